// The EdgeTech 2205 driver's logic, free of sockets and LCM: raw bytes in (from TCP or a file),
// joined pings out with their measurement time in the vehicle's time base; the raw stream is
// recorded as received; every fault is counted.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "drivers/edgetech/clock_offset.hpp"
#include "drivers/edgetech/jsf_navigation.hpp"
#include "drivers/edgetech/jsf_stream_parser.hpp"
#include "drivers/edgetech/ping_assembler.hpp"
#include "drivers/edgetech/raw_recorder.hpp"
#include "pipeline/core/config.hpp"

namespace sss::edgetech {

enum class TimeSource {
  kEstimateOffset,  // live: host time = sonar time + estimated offset
  kSonarClock,      // replay or a sonar synchronised by PTP/NTP: trust its clock
};

struct SonarDriverOptions {
  JsfParserOptions parser;
  PingAssemblerOptions assembler;
  ClockOffsetOptions clock;
  RawRecorderOptions recorder;
  TimeSource time_source = TimeSource::kEstimateOffset;
  // A towfish's layback in the type 80 headers (bytes 228-231). JSF does not say whether the
  // header's position is the ship's GPS or the fish's: false (default) uses the positions as
  // recorded and only counts the pings that carry one; true hands the layback on to be applied
  // along the heading (SonarChannelRecord::layback_m), for files whose positions are the ship's.
  bool apply_layback = false;
};

using sss::sonar::DriverPing;  // drivers/sonar/sonar_ping.hpp: what the driver hands out

// Where raw JSF from the sonar is recorded: the configured directory; when that is empty,
// systemd's LogsDirectory= as passed in $LOGS_DIRECTORY (its first entry: systemd joins several
// with ':'); when both are empty, nowhere (recording off). logs_directory_env may be null.
std::string resolveRecordDirectory(const std::string& configured, const char* logs_directory_env);

class SonarDriver {
 public:
  explicit SonarDriver(SonarDriverOptions options);

  // Bytes as received; host_utime_us: wall clock, monotonic_us: for timeouts and latency.
  void onBytes(const uint8_t* data, size_t size, int64_t host_utime_us, int64_t monotonic_us,
               std::vector<DriverPing>& out);
  // Periodic: pings whose other side never came.
  void onTimer(int64_t monotonic_us, std::vector<DriverPing>& out);
  // The byte stream ended (connection lost): whatever it completes is decided now; a
  // reconnection starts a new stream. Pings waiting for their other side keep waiting.
  void onStreamEnd(int64_t host_utime_us, int64_t monotonic_us, std::vector<DriverPing>& out);
  // End of input (file): everything pending, including lone sides.
  void finish(int64_t host_utime_us, int64_t monotonic_us, std::vector<DriverPing>& out);

  // Faults since the last call, one text per kind the first time it happens (log these).
  std::vector<std::string> takeNewFaultMessages();

  const JsfParserCounters& parserCounters() const { return parser_.counters(); }
  const PingAssemblerCounters& assemblerCounters() const { return assembler_.counters(); }
  const RawRecorder& recorder() const { return recorder_; }
  uint64_t sonarDecodeErrors() const { return sonar_decode_errors_; }
  uint64_t navigationMessages() const { return navigation_messages_; }
  uint64_t otherMessages() const { return other_messages_; }
  // Side-scan messages of the older type 82 (decoded like type 80; they carry no position).
  uint64_t oldSideScanMessages() const { return old_side_scan_messages_; }
  // Side-scan records carrying a layback (applied or not, see apply_layback) and the largest.
  uint64_t recordsWithLayback() const { return records_with_layback_; }
  double maxLaybackM() const { return max_layback_m_; }
  // The newest navigation message of the sonar's own sensors (2020/2080/2090/2091/2002).
  const std::optional<JsfNavigationRecord>& latestNavigation() const { return latest_navigation_; }
  // With keepNavigation(true), every navigation message decoded since the last call, in stream
  // order (the offline runner uses them as the navigation when the pings carry no position).
  // Off by default (the live driver has the INS); bounded to the newest kMaxKeptNavigation.
  void keepNavigation(bool keep) { keep_navigation_ = keep; }
  std::vector<JsfNavigationRecord> takeNavigation();
  static constexpr size_t kMaxKeptNavigation = 100000;
  uint64_t pingsWithoutOffset() const { return pings_without_offset_; }
  // host = sonar + offset; empty before enough pings.
  std::optional<int64_t> clockOffsetUs() const { return clock_.offsetUs(); }
  uint64_t clockResets() const { return clock_.resets(); }

 private:
  void handleMessages(int64_t host_utime_us, int64_t monotonic_us);
  void convert(std::vector<AssembledPing>& pings, std::vector<DriverPing>& out);

  SonarDriverOptions options_;
  JsfStreamParser parser_;
  PingAssembler assembler_;
  ClockOffsetEstimator clock_;
  RawRecorder recorder_;
  std::vector<JsfMessage> messages_;      // reused between calls
  std::vector<AssembledPing> assembled_;  // reused between calls
  uint64_t sonar_decode_errors_ = 0;
  uint64_t navigation_messages_ = 0;
  uint64_t other_messages_ = 0;
  uint64_t old_side_scan_messages_ = 0;
  uint64_t records_with_layback_ = 0;
  double max_layback_m_ = 0.0;
  std::optional<JsfNavigationRecord> latest_navigation_;
  std::vector<JsfNavigationRecord> navigation_records_;
  bool keep_navigation_ = false;
  uint64_t pings_without_offset_ = 0;
  std::vector<std::string> new_faults_;
  bool decode_error_reported_ = false;
};

// Reads the sonar_driver section's library keys (see config/sss-slam.yaml).
void readSonarDriverOptions(sss::core::ConfigSection& section, SonarDriverOptions& options);

}  // namespace sss::edgetech
