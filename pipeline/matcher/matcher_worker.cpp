// The matcher's worker thread. See matcher_worker.hpp.
#include "pipeline/matcher/matcher_worker.hpp"

#include "pipeline/core/time.hpp"

namespace sss::matcher {

MatcherWorker::MatcherWorker(MatcherEngine& engine, MatcherStateStore* store, MatcherWorkerOptions options, Hooks hooks)
    : engine_(engine), store_(store), options_(options), hooks_(std::move(hooks)) {}

MatcherWorker::~MatcherWorker() { stop(); }

void MatcherWorker::start() {
  if (store_) setBusy(true);  // restoring: busy before the thread runs, so the status never says idle
  thread_ = std::thread([this] { run(); });
}

void MatcherWorker::stop() {
  {
    std::lock_guard<std::mutex> lock(work_mutex_);
    stop_ = true;
    wake_.notify_all();
  }
  if (thread_.joinable()) thread_.join();
}

bool MatcherWorker::addSubframe(sss::core::Subframe subframe, int64_t arrival_monotonic_us) {
  std::lock_guard<std::mutex> lock(work_mutex_);
  subframes_.emplace_back(std::move(subframe), arrival_monotonic_us);
  bool dropped = false;
  while (static_cast<int>(subframes_.size()) > options_.max_queued_subframes) {
    subframes_.pop_front();
    ++dropped_subframes_;
    dropped = true;
  }
  wake_.notify_one();
  return dropped;
}

void MatcherWorker::setTrajectory(std::vector<TrajectoryNode> nodes) {
  std::lock_guard<std::mutex> lock(work_mutex_);
  trajectory_ = std::move(nodes);
  wake_.notify_one();
}

std::vector<TimedOutcome> MatcherWorker::takeOutcomes() {
  std::lock_guard<std::mutex> lock(results_mutex_);
  std::vector<TimedOutcome> outcomes;
  outcomes.swap(outcomes_);
  return outcomes;
}

MatcherWorkerStatus MatcherWorker::status() const {
  MatcherWorkerStatus status;
  {
    std::lock_guard<std::mutex> lock(results_mutex_);
    status.counters = counters_;
    status.stored_subframes = stored_subframes_;
    status.memory_bytes = memory_bytes_;
    status.busy = busy_;
  }
  std::lock_guard<std::mutex> lock(work_mutex_);
  status.queued_subframes = subframes_.size();
  status.dropped_subframes = dropped_subframes_;
  return status;
}

void MatcherWorker::setBusy(bool busy) {
  std::lock_guard<std::mutex> lock(results_mutex_);
  busy_ = busy;
}

void MatcherWorker::handOver(std::vector<PairOutcome> outcomes, int64_t arrival_monotonic_us) {
  const std::string state_error = engine_.takeStateError();
  if (!state_error.empty() && hooks_.state_error) hooks_.state_error(state_error);
  {
    std::lock_guard<std::mutex> lock(results_mutex_);
    for (PairOutcome& outcome : outcomes) outcomes_.push_back({std::move(outcome), arrival_monotonic_us});
    counters_ = engine_.counters();
    stored_subframes_ = engine_.storedSubframes();
    memory_bytes_ = engine_.memoryBytes();
    busy_ = false;
  }
  if (hooks_.results_ready) hooks_.results_ready();
}

void MatcherWorker::run() {
  if (store_) {
    RestoreReport report = engine_.restore(*store_);
    if (hooks_.restored) hooks_.restored(report);
    handOver(std::move(report.outcomes), sss::core::monotonicUtime());
  }
  for (;;) {
    std::optional<std::pair<sss::core::Subframe, int64_t>> subframe;
    std::optional<std::vector<TrajectoryNode>> trajectory;
    {
      std::unique_lock<std::mutex> lock(work_mutex_);
      wake_.wait(lock, [&] { return stop_ || !subframes_.empty() || trajectory_.has_value(); });
      if (stop_) return;
      // In arrival order, except that a waiting trajectory goes first.
      if (trajectory_) {
        trajectory = std::move(trajectory_);
        trajectory_.reset();
      } else {
        subframe = std::move(subframes_.front());
        subframes_.pop_front();
      }
    }
    setBusy(true);
    const int64_t arrival = subframe ? subframe->second : sss::core::monotonicUtime();
    handOver(subframe ? engine_.addSubframe(std::move(subframe->first)) : engine_.updateTrajectory(*trajectory), arrival);
  }
}

}  // namespace sss::matcher
