// What sss-subframe-buffer does around its SubframeBuffer, without middleware and without logging
// (what happened comes back as log lines for the process to write):
//   numbering: the next subframe and line ids survive restarts in the state directory (saved
//              before the subframes that use them leave, so a kill in between skips ids and never
//              reuses one; a restarted buffer numbering from 0 would see its subframes refused by
//              the optimiser as duplicates);
//   idle flush: when the sonar stops (end of the mission, a pause between surveys) nothing else
//              ends the open line; after idle_flush_s without pings its tail becomes a subframe;
//   status:    the buffer's counters for SSS_STATUS, each kind of lost ping logged once.
// The process publishes what each call returns, in order.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/core/health.hpp"
#include "pipeline/core/service_log.hpp"
#include "pipeline/subframe/subframe_buffer.hpp"

namespace sss::subframe {

struct SubframeBufferServiceOptions {
  SubframeBufferOptions buffer;
  double idle_flush_s = 5.0;  // no ping for this long (host monotonic time): close the open line
  // Where the numbering is kept (the state directory's "numbering" file). Empty: not kept, and a
  // warning at start says what a restart then does.
  std::string numbering_path;
};

using ServiceLog = sss::core::ServiceLog;

class SubframeBufferService {
 public:
  static constexpr const char* kNumberingFormat = "sss-subframe-buffer numbering 1";

  // Resumes the numbering an earlier run saved at options.numbering_path (a file that cannot be
  // read is reported and the numbering starts from 0).
  SubframeBufferService(const SubframeBufferServiceOptions& options, ServiceLog& log);

  // Each returns the subframes completed by the call, the numbering already saved for them.
  std::vector<Subframe> addNav(const sss::core::NavSample& nav, ServiceLog& log);
  std::vector<Subframe> addPing(sss::core::PingSample ping, int64_t now_monotonic_us, ServiceLog& log);
  // On a timer: closes the open line once idle_flush_s passed without a ping (once per pause).
  std::vector<Subframe> flushIfIdle(int64_t now_monotonic_us, ServiceLog& log);
  // At exit: the open line's tail.
  std::vector<Subframe> finish(ServiceLog& log);

  // Every second: the counters into SSS_STATUS's health; the first ping lost for a cause is an
  // error of its kind and one log line naming the cause and what to check.
  void reportHealth(sss::core::HealthMonitor& health, int64_t now_utime_us, ServiceLog& log);

  const SubframeBuffer& buffer() const { return buffer_; }
  uint64_t numberingWriteFailures() const { return numbering_write_failures_; }

 private:
  std::vector<Subframe> takeCompleted(ServiceLog& log);

  SubframeBufferServiceOptions options_;
  SubframeBuffer buffer_;
  std::vector<Subframe> completed_;
  int64_t last_ping_monotonic_us_ = 0;
  bool flushed_since_last_ping_ = true;
  uint64_t numbering_write_failures_ = 0;
  uint64_t reported_no_nav_ = 0, reported_out_of_order_ = 0, reported_no_altitude_ = 0;
};

}  // namespace sss::subframe
