// EdgeTech driver logic, see sonar_driver.hpp.
#include "drivers/edgetech/sonar_driver.hpp"

#include "pipeline/core/state_file.hpp"

namespace sss::edgetech {

SonarDriver::SonarDriver(SonarDriverOptions options)
    : options_(options),
      parser_(options.parser),
      assembler_(options.assembler),
      clock_(options.clock),
      recorder_(options.recorder) {}

void SonarDriver::onBytes(const uint8_t* data, size_t size, int64_t host_utime_us, int64_t monotonic_us,
                          std::vector<DriverPing>& out) {
  recorder_.write(data, size, host_utime_us);
  messages_.clear();
  parser_.feed(data, size, messages_);
  assembled_.clear();
  handleMessages(host_utime_us, monotonic_us);
  convert(assembled_, out);
}

std::vector<JsfNavigationRecord> SonarDriver::takeNavigation() {
  std::vector<JsfNavigationRecord> records;
  records.swap(navigation_records_);
  return records;
}

void SonarDriver::handleMessages(int64_t host_utime_us, int64_t monotonic_us) {
  for (const JsfMessage& message : messages_) {
    if (isNavigationType(message.header.message_type)) {
      sss::core::Result<JsfNavigationRecord> nav =
          decodeNavigation(message.header, message.body.data(), message.body.size());
      if (nav) {
        ++navigation_messages_;
        if (keep_navigation_) {
          if (navigation_records_.size() >= kMaxKeptNavigation) {
            navigation_records_.erase(navigation_records_.begin(),
                                      navigation_records_.begin() + static_cast<std::ptrdiff_t>(kMaxKeptNavigation / 2));
          }
          navigation_records_.push_back(*nav);
        }
        latest_navigation_ = std::move(*nav);
      } else {
        ++sonar_decode_errors_;
        if (!decode_error_reported_) {
          decode_error_reported_ = true;
          new_faults_.push_back("JSF message at byte " + std::to_string(message.stream_offset) + ": " + nav.message() +
                                "; skipped");
        }
      }
      continue;
    }
    const bool old_side_scan = message.header.message_type == kJsfOldSideScanData;
    if (message.header.message_type != kJsfSonarData && !old_side_scan) {
      ++other_messages_;  // system info, bathymetry, ...: skipped by their byte count
      continue;
    }
    if (old_side_scan) ++old_side_scan_messages_;
    sss::core::Result<SonarChannelRecord> decoded =
        old_side_scan ? decodeOldSideScanData(message.header, message.body.data(), message.body.size())
                      : decodeSonarData(message.header, message.body.data(), message.body.size());
    if (!decoded) {
      ++sonar_decode_errors_;
      if (!decode_error_reported_) {
        decode_error_reported_ = true;
        new_faults_.push_back("JSF sonar message at byte " + std::to_string(message.stream_offset) + ": " +
                              decoded.message() + "; skipped");
      }
      continue;
    }
    if (decoded->layback_m > 0.0) {
      ++records_with_layback_;
      max_layback_m_ = std::max(max_layback_m_, decoded->layback_m);
      if (!options_.apply_layback) decoded->layback_m = 0.0;
    }
    const SonarChannelRecord& r = *decoded;
    // The clock sees every channel: the end of acquisition is the last sample's time.
    const int64_t acquisition_us = static_cast<int64_t>(static_cast<double>(r.start_depth_samples + r.samples.size()) *
                                                        r.sample_interval_s * 1e6);
    clock_.add(r.ping_time_us + acquisition_us, host_utime_us);
    assembler_.add(std::move(*decoded), monotonic_us, assembled_);
  }
}

void SonarDriver::onTimer(int64_t monotonic_us, std::vector<DriverPing>& out) {
  assembled_.clear();
  assembler_.expire(monotonic_us, assembled_);
  convert(assembled_, out);
}

void SonarDriver::onStreamEnd(int64_t host_utime_us, int64_t monotonic_us, std::vector<DriverPing>& out) {
  messages_.clear();
  parser_.finish(messages_);
  assembled_.clear();
  handleMessages(host_utime_us, monotonic_us);
  convert(assembled_, out);
}

void SonarDriver::finish(int64_t host_utime_us, int64_t monotonic_us, std::vector<DriverPing>& out) {
  onStreamEnd(host_utime_us, monotonic_us, out);
  assembled_.clear();
  assembler_.flush(assembled_);
  convert(assembled_, out);
}

void SonarDriver::convert(std::vector<AssembledPing>& pings, std::vector<DriverPing>& out) {
  for (AssembledPing& ping : pings) {
    DriverPing driver_ping;
    driver_ping.sonar_utime_us = ping.pingTimeUs();
    if (options_.time_source == TimeSource::kSonarClock) {
      driver_ping.utime_us = driver_ping.sonar_utime_us;
    } else {
      const auto offset = clock_.offsetUs();
      if (!offset) {
        // Not enough pings yet to know the sonar clock: publishing a guessed time would put the
        // ping at the wrong place. Counted; the estimate settles after a few pings.
        ++pings_without_offset_;
        continue;
      }
      driver_ping.utime_us = driver_ping.sonar_utime_us + *offset;
    }
    driver_ping.ping = std::move(ping);
    out.push_back(std::move(driver_ping));
  }
}

std::vector<std::string> SonarDriver::takeNewFaultMessages() {
  std::vector<std::string> faults = parser_.takeNewFaultMessages();
  for (std::string& fault : new_faults_) faults.push_back(std::move(fault));
  new_faults_.clear();
  const std::string recorder_error = recorder_.takeNewError();
  if (!recorder_error.empty()) faults.push_back(recorder_error);
  return faults;
}

std::string resolveRecordDirectory(const std::string& configured, const char* logs_directory_env) {
  return sss::core::resolveSystemdDirectory(configured, logs_directory_env);
}

void readSonarDriverOptions(sss::core::ConfigSection& section, SonarDriverOptions& options) {
  using namespace sss::core;
  int subsystem = options.assembler.subsystem;
  section.optional("subsystem", subsystem, {inRange(0, 255)});
  options.assembler.subsystem = static_cast<uint8_t>(subsystem);
  section.optional("adopt_other_side_scan_after", options.assembler.adopt_other_side_scan_after, {atLeast(0)});
  section.optional("missing_side_timeout_s", options.assembler.missing_side_timeout_s, {inRange(0.01, 60.0)});
  section.optional("max_pending_pings", options.assembler.max_pending_pings, {inRange(1, 1000)});
  section.optional("max_message_bytes", options.parser.max_body_bytes, {inRange(1024, 64 * 1024 * 1024)});
  section.optional("clock_window_s", options.clock.window_s, {inRange(1.0, 3600.0)});
  std::string time_source = options.time_source == TimeSource::kSonarClock ? "sonar" : "estimate";
  section.optional("time_source", time_source, {oneOf({"estimate", "sonar"})});
  options.time_source = time_source == "sonar" ? TimeSource::kSonarClock : TimeSource::kEstimateOffset;
  std::string layback = options.apply_layback ? "apply" : "ignore";
  section.optional("jsf_layback", layback, {oneOf({"ignore", "apply"})});
  options.apply_layback = layback == "apply";
  section.optional("record_directory", options.recorder.directory);
  double record_max_file_mb = static_cast<double>(options.recorder.max_file_bytes) / (1024.0 * 1024.0);
  section.optional("record_max_file_mb", record_max_file_mb, {inRange(1.0, 1e6)});
  options.recorder.max_file_bytes = static_cast<uint64_t>(record_max_file_mb * 1024.0 * 1024.0);
}

}  // namespace sss::edgetech
