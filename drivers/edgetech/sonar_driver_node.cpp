// sss-sonar-driver: EdgeTech 2205 JSF from the sonar processor's TCP data port (or a .jsf or
// .xtf file for replay) -> SSS_PING on LCM. Translation only; the logic is in SonarDriver and
// XtfReader.
//   sss-sonar-driver [--config FILE] [--file FILE.jsf|FILE.xtf [--speed X]] [--lcm-url URL]
#include <strings.h>

#include <cstdio>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <string>

#include "drivers/edgetech/ping_message.hpp"
#include "drivers/edgetech/sonar_driver.hpp"
#include "drivers/xtf/xtf_reader.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/transport/logging.hpp"
#include "pipeline/transport/process_loop.hpp"
#include "pipeline/transport/replay_pacer.hpp"
#include "pipeline/transport/tcp_client.hpp"

namespace {

using sss::core::monotonicUtime;
using sss::core::nowUtime;

struct NodeOptions {
  sss::transport::ProcessOptions process;
  sss::edgetech::SonarDriverOptions driver;
  sss::transport::TcpClientOptions tcp;
  std::string ping_channel = "SSS_PING";
  std::string replay_file;      // non-empty: read this file instead of TCP
  double replay_speed = 1.0;    // 0: as fast as possible
  int xtf_pair_index = 0;       // XTF with several side-scan pairs: 0 = lowest frequency
};

// Replays a file through the same byte path as TCP, publishing each ping at its sonar time
// divided by the speed factor.
class FileReplay {
 public:
  FileReplay(const std::string& path, double speed) : file_(path, std::ios::binary), pacer_(speed) {}
  bool isOpen() const { return file_.is_open(); }
  bool done() const { return eof_ && queue_.empty(); }

  template <typename Publish>
  void step(sss::edgetech::SonarDriver& driver, Publish publish) {
    // Keep a small queue of decoded pings ahead of the pace.
    std::vector<char> chunk(1 << 16);
    while (!eof_ && queue_.size() < 64) {
      file_.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
      const size_t n = static_cast<size_t>(file_.gcount());
      std::vector<sss::edgetech::DriverPing> pings;
      if (n > 0) driver.onBytes(reinterpret_cast<const uint8_t*>(chunk.data()), n, nowUtime(), monotonicUtime(), pings);
      if (n < chunk.size()) {
        driver.finish(nowUtime(), monotonicUtime(), pings);
        eof_ = true;
      }
      for (auto& p : pings) queue_.push_back(std::move(p));
    }
    const int64_t now = monotonicUtime();
    int budget = 200;  // per step: keep the loop responsive to signals and status
    while (!queue_.empty() && budget-- > 0) {
      sss::edgetech::DriverPing& next = queue_.front();
      if (!pacer_.due(next.sonar_utime_us, now)) break;
      next.ping.last_arrival_us = now;
      publish(next);
      queue_.pop_front();
    }
  }

 private:
  std::ifstream file_;
  sss::transport::ReplayPacer pacer_;
  bool eof_ = false;
  std::deque<sss::edgetech::DriverPing> queue_;
};

// Replays an XTF file: its packets already join both sides, so they bypass the JSF assembler.
class XtfReplay {
 public:
  XtfReplay(const std::string& path, double speed, sss::xtf::XtfReaderOptions options)
      : reader_(path, options), pacer_(speed) {}
  bool isOpen() const { return reader_.isOpen(); }
  bool done() const { return eof_ && queue_.empty(); }
  sss::xtf::XtfReader& reader() { return reader_; }

  template <typename Publish>
  void step(Publish publish) {
    while (!eof_ && queue_.size() < 64) {
      sss::edgetech::DriverPing ping;
      if (!reader_.next(ping)) {
        eof_ = true;
        break;
      }
      queue_.push_back(std::move(ping));
    }
    const int64_t now = monotonicUtime();
    for (int budget = 200; budget > 0 && !queue_.empty(); --budget) {
      sss::edgetech::DriverPing& next = queue_.front();
      if (!pacer_.due(next.sonar_utime_us, now)) break;
      next.ping.last_arrival_us = now;
      publish(next);
      queue_.pop_front();
    }
  }

 private:
  sss::xtf::XtfReader reader_;
  sss::transport::ReplayPacer pacer_;
  bool eof_ = false;
  std::deque<sss::edgetech::DriverPing> queue_;
};

bool hasXtfExtension(const std::string& path) {
  return path.size() > 4 && strcasecmp(path.c_str() + path.size() - 4, ".xtf") == 0;
}

}  // namespace

int main(int argc, char** argv) {
  sss::transport::NodeArguments arguments;
  NodeOptions options;
  sss::cli::CommandLine command_line("sss-sonar-driver",
                                     "EdgeTech 2205 JSF from the sonar processor's TCP data port, or a .jsf/.xtf file "
                                     "replayed -> SSS_PING");
  sss::transport::addNodeFlags(command_line, arguments);
  sss::transport::ReplayFlags replay_flags;
  sss::transport::addReplayFlags(command_line, "replay this .jsf or .xtf file instead of TCP", replay_flags);
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  const std::string& config_path = arguments.config_path;
  const std::string& lcm_url_override = arguments.lcm_url_override;
  const bool check_config_only = arguments.check_config_only;

  options.process.process_name = "sss-sonar-driver";
  std::string config_problems;  // empty: valid (or no file: the defaults)
  if (!config_path.empty()) {
    sss::core::Config config = sss::core::Config::fromFile(config_path);
    sss::core::ConfigSection section = config.section("sonar_driver");
    sss::transport::readProcessOptions(section, options.process);
    sss::edgetech::readSonarDriverOptions(section, options.driver);
    section.optional("host", options.tcp.host, {sss::core::nonEmpty()});
    section.optional("port", options.tcp.port, {sss::core::inRange(1, 65535)});
    section.optional("reconnect_min_s", options.tcp.reconnect_min_s, {sss::core::inRange(0.01, 60.0)});
    section.optional("reconnect_max_s", options.tcp.reconnect_max_s, {sss::core::inRange(0.1, 600.0)});
    section.optional("silence_timeout_s", options.tcp.silence_timeout_s, {sss::core::inRange(0.0, 3600.0)});
    section.optional("ping_channel", options.ping_channel, {sss::core::nonEmpty()});
    section.optional("replay_file", options.replay_file);
    section.optional("replay_speed", options.replay_speed, {sss::core::inRange(0.0, 1000.0)});
    section.optional("xtf_pair_index", options.xtf_pair_index, {sss::core::inRange(0, 7)});
    section.rejectUnknownKeys();
    config_problems = config.problemReport();
  }
  options.replay_file = replay_flags.file.value_or(options.replay_file);
  options.replay_speed = replay_flags.speed.value_or(options.replay_speed);
  if (const int code = sss::transport::configVerdict("sss-sonar-driver", config_problems, config_path, check_config_only); code >= 0) {
    return code;
  }
  if (!lcm_url_override.empty()) options.process.lcm_url = lcm_url_override;
  // A file carries the sonar's own clock; there is no arrival time to compare it with.
  if (!options.replay_file.empty()) options.driver.time_source = sss::edgetech::TimeSource::kSonarClock;
  // Under systemd the sonar's raw bytes go to the unit's LogsDirectory= unless the config says
  // where; a file being replayed is already on disk.
  if (options.replay_file.empty()) {
    options.driver.recorder.directory =
        sss::edgetech::resolveRecordDirectory(options.driver.recorder.directory, std::getenv("LOGS_DIRECTORY"));
  }

  sss::transport::initLogging(options.process.process_name, options.process.log_level);
  sss::transport::ProcessLoop loop(options.process);
  sss::core::HealthMonitor& health = loop.health();
  sss::edgetech::SonarDriver driver(options.driver);
  if (driver.recorder().enabled()) spdlog::info("recording the raw JSF stream to {}", options.driver.recorder.directory);

  auto publish = [&](const sss::edgetech::DriverPing& ping) {
    loop.bus().publish(options.ping_channel, sss::edgetech::toPingMessage(ping), ping.ping.last_arrival_us);
  };
  auto updateCounters = [&] {
    const auto& parser = driver.parserCounters();
    const auto& assembler = driver.assemblerCounters();
    health.setCounter("jsf_messages", static_cast<double>(parser.messages));
    health.setCounter("jsf_bytes_skipped", static_cast<double>(parser.bytes_skipped));
    health.setCounter("jsf_bad_headers", static_cast<double>(parser.bad_headers));
    health.setCounter("jsf_truncated_messages", static_cast<double>(parser.truncated_messages));
    health.setCounter("jsf_sonar_decode_errors", static_cast<double>(driver.sonarDecodeErrors()));
    health.setCounter("jsf_navigation_messages", static_cast<double>(driver.navigationMessages()));
    health.setCounter("jsf_other_messages", static_cast<double>(driver.otherMessages()));
    health.setCounter("pings_complete", static_cast<double>(assembler.complete_pings));
    health.setCounter("pings_one_side_missing", static_cast<double>(assembler.incomplete_pings));
    health.setCounter("pings_before_clock_estimate", static_cast<double>(driver.pingsWithoutOffset()));
    if (const auto offset = driver.clockOffsetUs()) health.setCounter("clock_offset_s", *offset * 1e-6);
    health.setCounter("clock_resets", static_cast<double>(driver.clockResets()));
    if (driver.recorder().enabled()) {
      health.setCounter("recorded_bytes", static_cast<double>(driver.recorder().bytesWritten()));
      health.setCounter("record_errors", static_cast<double>(driver.recorder().writeErrors()));
    }
    loop.reportFaults("sonar_input", driver.takeNewFaultMessages());
  };
  loop.addTimer(1.0, updateCounters);

  std::unique_ptr<FileReplay> replay;
  std::unique_ptr<XtfReplay> xtf_replay;
  std::unique_ptr<sss::transport::TcpClient> tcp;
  int registered_fd = -1;
  std::vector<sss::edgetech::DriverPing> pings;  // reused by the TCP callbacks below
  if (!options.replay_file.empty() && hasXtfExtension(options.replay_file)) {
    sss::xtf::XtfReaderOptions xtf_options;
    xtf_options.pair_index = options.xtf_pair_index;
    xtf_replay = std::make_unique<XtfReplay>(options.replay_file, options.replay_speed, xtf_options);
    if (!xtf_replay->isOpen()) {
      spdlog::critical("{}", xtf_replay->reader().error());
      return 1;
    }
    spdlog::info("{}", xtf_replay->reader().summary());
    uint64_t xtf_pings_published = 0;
    loop.addTimer(0.002, [&] {
      xtf_replay->step([&](const sss::edgetech::DriverPing& ping) {
        publish(ping);
        ++xtf_pings_published;
      });
      sss::xtf::XtfReader& reader = xtf_replay->reader();
      loop.reportFaults("sonar_input", reader.takeNewFaultMessages());
      health.setCounter("xtf_pings", static_cast<double>(reader.counters().pings));
      health.setCounter("xtf_packets_skipped", static_cast<double>(reader.counters().packets_skipped));
      health.setCounter("xtf_corrupt_records", static_cast<double>(reader.counters().corruptRecords()));
      health.setCounter("xtf_bytes_skipped", static_cast<double>(reader.counters().bytes_skipped));
      health.setCounter("xtf_truncated_packets", static_cast<double>(reader.counters().truncated_packets));
      if (xtf_replay->done()) {
        spdlog::info("{}", reader.summary());
        spdlog::info("replay of '{}' finished: {} pings", options.replay_file, xtf_pings_published);
        loop.stop();
      }
    });
  } else if (!options.replay_file.empty()) {
    replay = std::make_unique<FileReplay>(options.replay_file, options.replay_speed);
    if (!replay->isOpen()) {
      spdlog::critical("cannot open sonar file '{}'", options.replay_file);
      return 1;
    }
    loop.addTimer(0.002, [&] {
      replay->step(driver, publish);
      if (replay->done()) {
        updateCounters();
        spdlog::info("replay of '{}' finished: {} pings", options.replay_file,
                     driver.assemblerCounters().complete_pings + driver.assemblerCounters().incomplete_pings);
        loop.stop();
      }
    });
  } else {
    tcp = std::make_unique<sss::transport::TcpClient>(
        options.tcp,
        [&](const uint8_t* data, size_t size) {
          pings.clear();
          driver.onBytes(data, size, nowUtime(), monotonicUtime(), pings);
          for (const auto& ping : pings) publish(ping);
        },
        [&](sss::transport::LinkState state, const std::string& reason) {
          health.setState(state == sss::transport::LinkState::kConnected ? sss::core::HealthState::kOk
                                                                         : sss::core::HealthState::kWarning,
                          "sonar link: " + reason);
          if (state == sss::transport::LinkState::kConnected) {
            spdlog::info("sonar link: {}", reason);
          } else if (state == sss::transport::LinkState::kDisconnected) {
            spdlog::warn("sonar link: {}", reason);
            pings.clear();
            driver.onStreamEnd(nowUtime(), monotonicUtime(), pings);
            for (const auto& ping : pings) publish(ping);
          }
        });
    // Service the link and expire lone sides; (re)register the socket with the loop.
    loop.addTimer(0.05, [&] {
      const int64_t now = monotonicUtime();
      tcp->service(now);
      if (tcp->fd() != registered_fd) {
        if (registered_fd >= 0) loop.removeFileDescriptor(registered_fd);
        registered_fd = tcp->fd();
        if (registered_fd >= 0) loop.addFileDescriptor(registered_fd, [&] { tcp->onReadable(monotonicUtime()); });
      }
      health.setCounter("link_connects", static_cast<double>(tcp->connects()));
      health.setCounter("link_disconnects", static_cast<double>(tcp->disconnects()));
      pings.clear();
      driver.onTimer(now, pings);
      for (const auto& ping : pings) publish(ping);
    });
  }
  return loop.run();
}
