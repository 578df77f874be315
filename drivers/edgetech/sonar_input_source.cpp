// sss-sonar-driver's inputs. See sonar_input_source.hpp.
#include "drivers/edgetech/sonar_input_source.hpp"

#include <strings.h>

#include <utility>

#include "pipeline/core/time.hpp"

namespace sss::edgetech {
namespace {

using sss::core::monotonicUtime;
using sss::core::nowUtime;

// A file carries the sonar's own clock; there is no arrival time to compare it with.
SonarDriverOptions driverOptionsFor(const SonarInputOptions& options) {
  SonarDriverOptions driver = options.driver;
  if (!options.replay_file.empty()) driver.time_source = TimeSource::kSonarClock;
  return driver;
}

}  // namespace

bool isXtfPath(const std::string& path) {
  return path.size() > 4 && strcasecmp(path.c_str() + path.size() - 4, ".xtf") == 0;
}

SonarInputSource::SonarInputSource(SonarInputOptions options, sss::core::HealthMonitor& health,
                                   SonarInputHooks hooks)
    : options_(std::move(options)),
      health_(health),
      hooks_(std::move(hooks)),
      driver_(driverOptionsFor(options_)),
      pacer_(options_.replay_speed) {
  if (options_.replay_file.empty()) {
    kind_ = Kind::kTcp;
  } else if (isXtfPath(options_.replay_file)) {
    kind_ = Kind::kXtfFile;
  } else {
    kind_ = Kind::kJsfFile;
  }
}

sss::core::Status SonarInputSource::open() {
  switch (kind_) {
    case Kind::kTcp:
      tcp_ = std::make_unique<sss::transport::TcpClient>(
          options_.tcp,
          [this](const uint8_t* data, size_t size) {
            pings_.clear();
            driver_.onBytes(data, size, nowUtime(), monotonicUtime(), pings_);
            deliverAll(pings_);
          },
          [this](sss::transport::LinkState state, const std::string& reason) { onLinkState(state, reason); });
      return sss::core::Status::success();
    case Kind::kJsfFile:
      jsf_file_.open(options_.replay_file, std::ios::binary);
      if (!jsf_file_.is_open()) return sss::core::Status::error("cannot open sonar file '" + options_.replay_file + "'");
      jsf_chunk_.resize(1 << 16);
      return sss::core::Status::success();
    case Kind::kXtfFile: {
      sss::xtf::XtfReaderOptions xtf_options;
      xtf_options.pair_index = options_.xtf_pair_index;
      xtf_options.nav_units = options_.xtf_nav_units;
      xtf_reader_ = std::make_unique<sss::xtf::XtfReader>(options_.replay_file, xtf_options);
      if (!xtf_reader_->isOpen()) return sss::core::Status::error(xtf_reader_->error());
      say(hooks_.info, xtf_reader_->summary());
      return sss::core::Status::success();
    }
  }
  return sss::core::Status::success();
}

int SonarInputSource::fd() const { return tcp_ ? tcp_->fd() : -1; }

double SonarInputSource::stepPeriodS() const {
  return kind_ == Kind::kTcp ? options_.link_step_period_s : options_.replay_step_period_s;
}

void SonarInputSource::step() {
  switch (kind_) {
    case Kind::kTcp: return stepLink();
    case Kind::kJsfFile: return stepJsf();
    case Kind::kXtfFile: return stepXtf();
  }
}

void SonarInputSource::onReadable() {
  if (tcp_) tcp_->onReadable(monotonicUtime());
}

bool SonarInputSource::done() const { return kind_ != Kind::kTcp && end_of_file_ && queue_.empty(); }

void SonarInputSource::stepJsf() {
  if (!jsf_file_.is_open()) return;
  // The file goes through the same byte path as TCP, in a buffer allocated once (this runs every
  // replay_step_period_s).
  while (!end_of_file_ && queue_.size() < options_.replay_read_ahead_pings) {
    jsf_file_.read(jsf_chunk_.data(), static_cast<std::streamsize>(jsf_chunk_.size()));
    const size_t n = static_cast<size_t>(jsf_file_.gcount());
    pings_.clear();
    if (n > 0) {
      driver_.onBytes(reinterpret_cast<const uint8_t*>(jsf_chunk_.data()), n, nowUtime(), monotonicUtime(), pings_);
    }
    if (n < jsf_chunk_.size()) {
      driver_.finish(nowUtime(), monotonicUtime(), pings_);
      end_of_file_ = true;
    }
    for (DriverPing& ping : pings_) queue_.push_back(std::move(ping));
  }
  publishDue();
  if (done() && !end_reported_) {
    end_reported_ = true;
    updateStatus();  // the final status carries every ping of the file
    const PingAssemblerCounters& assembled = driver_.assemblerCounters();
    say(hooks_.info, "replay of '" + options_.replay_file + "' finished: " +
                         std::to_string(assembled.complete_pings + assembled.incomplete_pings) + " pings");
  }
}

void SonarInputSource::stepXtf() {
  if (!xtf_reader_ || !xtf_reader_->isOpen()) return;
  // XTF packets already join both sides: they bypass the JSF assembler.
  while (!end_of_file_ && queue_.size() < options_.replay_read_ahead_pings) {
    DriverPing ping;
    if (!xtf_reader_->next(ping)) {
      end_of_file_ = true;
      break;
    }
    queue_.push_back(std::move(ping));
  }
  xtf_pings_published_ += publishDue();
  reportFaults(xtf_reader_->takeNewFaultMessages());
  const sss::xtf::XtfReaderCounters& counters = xtf_reader_->counters();
  health_.setCounter("xtf_pings", static_cast<double>(counters.pings));
  health_.setCounter("xtf_packets_skipped", static_cast<double>(counters.packets_skipped));
  health_.setCounter("xtf_corrupt_records", static_cast<double>(counters.corruptRecords()));
  health_.setCounter("xtf_bytes_skipped", static_cast<double>(counters.bytes_skipped));
  health_.setCounter("xtf_truncated_packets", static_cast<double>(counters.truncated_packets));
  if (done() && !end_reported_) {
    end_reported_ = true;
    say(hooks_.info, xtf_reader_->summary());
    say(hooks_.info, "replay of '" + options_.replay_file + "' finished: " + std::to_string(xtf_pings_published_) +
                         " pings");
  }
}

size_t SonarInputSource::publishDue() {
  const int64_t now_us = monotonicUtime();
  size_t published = 0;
  for (int budget = options_.replay_pings_per_step; budget > 0 && !queue_.empty(); --budget) {
    DriverPing& next = queue_.front();
    if (!pacer_.due(next.sonar_utime_us, now_us)) break;
    next.ping.last_arrival_us = now_us;
    if (hooks_.ping) hooks_.ping(next);
    queue_.pop_front();
    ++published;
  }
  return published;
}

void SonarInputSource::stepLink() {
  if (!tcp_) return;
  const int64_t now_us = monotonicUtime();
  tcp_->service(now_us);
  health_.setCounter("link_connects", static_cast<double>(tcp_->connects()));
  health_.setCounter("link_disconnects", static_cast<double>(tcp_->disconnects()));
  pings_.clear();
  driver_.onTimer(now_us, pings_);  // pings whose other side never came
  deliverAll(pings_);
}

void SonarInputSource::onLinkState(sss::transport::LinkState state, const std::string& reason) {
  const bool connected = state == sss::transport::LinkState::kConnected;
  health_.setState(connected ? sss::core::HealthState::kOk : sss::core::HealthState::kWarning,
                   "sonar link: " + reason);
  if (connected) {
    say(hooks_.info, "sonar link: " + reason);
  } else if (state == sss::transport::LinkState::kDisconnected) {
    say(hooks_.warning, "sonar link: " + reason);
    // A message cut by the drop is not joined to the next connection's bytes.
    pings_.clear();
    driver_.onStreamEnd(nowUtime(), monotonicUtime(), pings_);
    deliverAll(pings_);
  }
}

void SonarInputSource::updateStatus() {
  const JsfParserCounters& parser = driver_.parserCounters();
  const PingAssemblerCounters& assembler = driver_.assemblerCounters();
  health_.setCounter("jsf_messages", static_cast<double>(parser.messages));
  health_.setCounter("jsf_bytes_skipped", static_cast<double>(parser.bytes_skipped));
  health_.setCounter("jsf_bad_headers", static_cast<double>(parser.bad_headers));
  health_.setCounter("jsf_truncated_messages", static_cast<double>(parser.truncated_messages));
  health_.setCounter("jsf_sonar_decode_errors", static_cast<double>(driver_.sonarDecodeErrors()));
  health_.setCounter("jsf_navigation_messages", static_cast<double>(driver_.navigationMessages()));
  health_.setCounter("jsf_other_messages", static_cast<double>(driver_.otherMessages()));
  health_.setCounter("pings_complete", static_cast<double>(assembler.complete_pings));
  health_.setCounter("pings_one_side_missing", static_cast<double>(assembler.incomplete_pings));
  health_.setCounter("pings_before_clock_estimate", static_cast<double>(driver_.pingsWithoutOffset()));
  if (const auto offset_us = driver_.clockOffsetUs()) health_.setCounter("clock_offset_s", *offset_us * 1e-6);
  health_.setCounter("clock_resets", static_cast<double>(driver_.clockResets()));
  if (driver_.recorder().enabled()) {
    health_.setCounter("recorded_bytes", static_cast<double>(driver_.recorder().bytesWritten()));
    health_.setCounter("record_errors", static_cast<double>(driver_.recorder().writeErrors()));
  }
  reportFaults(driver_.takeNewFaultMessages());
}

void SonarInputSource::deliverAll(const std::vector<DriverPing>& pings) {
  if (!hooks_.ping) return;
  for (const DriverPing& ping : pings) hooks_.ping(ping);
}

void SonarInputSource::say(const std::function<void(const std::string&)>& hook, const std::string& line) const {
  if (hook) hook(line);
}

void SonarInputSource::reportFaults(const std::vector<std::string>& faults) const {
  if (!faults.empty() && hooks_.faults) hooks_.faults(faults);
}

}  // namespace sss::edgetech
