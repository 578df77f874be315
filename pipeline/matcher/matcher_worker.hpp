// The matcher's worker: matching a pair takes about a second, so the engine runs on its own thread
// and the process loop stays free for LCM, SSS_STATUS and the systemd watchdog.
//
// Work comes in arrival order, except that a waiting trajectory goes first (the subframes after it
// are then matched with the newest poses) and only the newest trajectory is kept. Waiting
// subframes are bounded: beyond max_queued_subframes the oldest is dropped and counted (a long
// stall must not grow memory without bound). With a state store, the worker first restores the
// previous run (seconds for hundreds of subframes) while the loop queues what arrives. Each result
// keeps the monotonic arrival time of the input that produced it (latency figures). No middleware:
// the node wires these to LCM, an eventfd and the status.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "pipeline/core/subframe_types.hpp"
#include "pipeline/matcher/matcher_engine.hpp"

namespace sss::matcher {

struct MatcherWorkerOptions {
  // At 50 s per subframe and ~1 s per pair the queue stays empty; this bounds a long stall.
  int max_queued_subframes = 32;
};

struct TimedOutcome {
  PairOutcome outcome;
  int64_t arrival_monotonic_us = 0;  // of the subframe or trajectory that produced it
};

// The figures SSS_STATUS shows.
struct MatcherWorkerStatus {
  MatcherEngineCounters counters;
  size_t stored_subframes = 0;
  size_t memory_bytes = 0;
  bool busy = false;                 // matching (or restoring) now
  size_t queued_subframes = 0;
  uint64_t dropped_subframes = 0;    // queue full: the oldest waiting subframe dropped
};

class MatcherWorker {
 public:
  struct Hooks {
    // From the worker thread when outcomes are ready (the loop wakes and calls takeOutcomes()).
    std::function<void()> results_ready;
    // From the worker thread: a failed write in the state directory (the newest since the last).
    std::function<void(const std::string&)> state_error;
    // From the worker thread once the previous run is restored (its outcomes follow as results).
    std::function<void(const RestoreReport&)> restored;
  };

  // store: the state directory's store, or null (a restart then loses the stored subframes). The
  // engine and the store are the worker's from start() to stop().
  MatcherWorker(MatcherEngine& engine, MatcherStateStore* store, MatcherWorkerOptions options, Hooks hooks);
  ~MatcherWorker();  // stop()
  MatcherWorker(const MatcherWorker&) = delete;
  MatcherWorker& operator=(const MatcherWorker&) = delete;

  void start();
  // Queues a subframe; true when this dropped the oldest waiting one (the queue was full).
  bool addSubframe(sss::core::Subframe subframe, int64_t arrival_monotonic_us);
  // Replaces any waiting trajectory: only the newest matters.
  void setTrajectory(std::vector<TrajectoryNode> nodes);
  std::vector<TimedOutcome> takeOutcomes();
  MatcherWorkerStatus status() const;
  // Stops the thread after the pair it is matching; what waits is left.
  void stop();

 private:
  void run();
  void handOver(std::vector<PairOutcome> outcomes, int64_t arrival_monotonic_us);
  void setBusy(bool busy);

  MatcherEngine& engine_;
  MatcherStateStore* store_;
  const MatcherWorkerOptions options_;
  const Hooks hooks_;

  // Work, in arrival order; only the newest trajectory matters.
  mutable std::mutex work_mutex_;
  std::condition_variable wake_;
  std::deque<std::pair<sss::core::Subframe, int64_t>> subframes_;
  std::optional<std::vector<TrajectoryNode>> trajectory_;
  bool stop_ = false;
  uint64_t dropped_subframes_ = 0;

  // Results, for the loop.
  mutable std::mutex results_mutex_;
  std::vector<TimedOutcome> outcomes_;
  MatcherEngineCounters counters_;
  size_t stored_subframes_ = 0;
  size_t memory_bytes_ = 0;
  bool busy_ = false;

  std::thread thread_;
};

}  // namespace sss::matcher
