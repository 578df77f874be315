// What sss-matcher does around its engine and worker, without middleware and without logging
// (what happened comes back as log lines for the process to write):
//   start:    the state directory's store (stored subframes, pair bookkeeping), which the worker
//             restores first; without one a warning says what a restart loses;
//   inputs:   SSS_SUBFRAME and SSS_TRAJECTORY messages are decoded and queued for the worker, which
//             matches on its own thread (a pair takes about a second). A message that cannot be
//             used is counted in SSS_STATUS under its kind (bad_subframe, bad_trajectory) and the
//             first of each kind logged with its cause; a full queue drops the oldest subframe,
//             said once and counted;
//   results:  the accepted closures to publish, each with the arrival time of the input that
//             produced it, and a log line per pair; what the worker's thread had to say (the
//             restored state, failed writes in the state directory) comes with them;
//   status:   the engine's and the worker's counters for SSS_STATUS.
// The process wires these to LCM, a wake-up of its loop and its timers.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "pipeline/core/health.hpp"
#include "pipeline/core/service_log.hpp"
#include "pipeline/matcher/matcher_engine.hpp"
#include "pipeline/matcher/matcher_state.hpp"
#include "pipeline/matcher/matcher_worker.hpp"
#include "sss_msgs/loop_closure_t.hpp"
#include "sss_msgs/subframe_t.hpp"
#include "sss_msgs/trajectory_t.hpp"

namespace sss::matcher {

struct MatcherServiceOptions {
  MatcherEngineOptions engine;
  // Subframes waiting for the worker; beyond it the oldest waiting one is dropped and counted
  // (at 50 s per subframe and ~1 s per pair the queue stays empty; a long stall must not grow
  // memory without bound).
  int max_queued_subframes = 32;
  // Stored subframes and pair bookkeeping (MatcherStateStore). Empty: none, a restart loses them.
  std::string state_directory;
};

struct ClosureToPublish {
  sss_msgs::loop_closure_t message;
  int64_t arrival_monotonic_us = 0;  // of the subframe or trajectory that produced it
};

class MatcherService {
 public:
  // results_ready is called from the worker's thread when takeResults() has something.
  MatcherService(const MatcherServiceOptions& options, std::function<void()> results_ready, sss::core::ServiceLog& log);
  ~MatcherService();  // stop()
  MatcherService(const MatcherService&) = delete;
  MatcherService& operator=(const MatcherService&) = delete;

  // Starts the worker's thread, which restores the state directory first.
  void start();
  void addSubframe(const sss_msgs::subframe_t& message, int64_t arrival_monotonic_us, sss::core::HealthMonitor& health,
                   sss::core::ServiceLog& log);
  void setTrajectory(const sss_msgs::trajectory_t& message, sss::core::HealthMonitor& health, sss::core::ServiceLog& log);
  // The closures accepted since the last call, stamped now_utime_us; a log line for every pair;
  // failed writes in the state directory counted under state_write (the first one logged).
  std::vector<ClosureToPublish> takeResults(int64_t now_utime_us, sss::core::HealthMonitor& health,
                                            sss::core::ServiceLog& log);
  // The counters into SSS_STATUS, and the queue's depth on the subframe channel.
  void reportHealth(sss::core::HealthMonitor& health, const std::string& subframe_channel) const;
  // Stops the worker after the pair it is matching; what waits is left (stored in the state directory).
  void stop();

 private:

  const MatcherServiceOptions options_;
  const std::function<void()> results_ready_;
  MatcherEngine engine_;
  std::unique_ptr<MatcherStateStore> store_;
  // What the worker's thread said (the restored state, failed writes), kept for the loop's next
  // takeResults().
  std::mutex from_worker_mutex_;
  sss::core::ServiceLog worker_log_;
  std::vector<std::string> state_errors_;
  uint64_t rejected_messages_ = 0;
  bool queue_full_said_ = false;
  std::unique_ptr<MatcherWorker> worker_;  // last: its thread uses the members above
};

}  // namespace sss::matcher
