#include "pipeline/matcher/matcher_service.hpp"

#include <cstdio>
#include <utility>

#include "pipeline/core/time.hpp"
#include "pipeline/messages/closure_messages.hpp"
#include "pipeline/messages/subframe_messages.hpp"

namespace sss::matcher {
namespace {

std::string restoredLine(const RestoreReport& report) {
  return "restored " + std::to_string(report.subframes) + " subframes and " + std::to_string(report.pairs) +
         " matched pairs from " + report.directory + (report.state_file_found ? "" : " (without matcher.state)") +
         "; " + std::to_string(report.subframes_without_state) +
         " subframe(s) stored but not matched before the restart: " + std::to_string(report.outcomes.size()) +
         " pair(s) matched now";
}

std::string outcomeLine(const PairOutcome& outcome) {
  char text[400];
  if (outcome.accepted) {
    const Eigen::Vector3d& t = outcome.closure.T_a_b.translation;
    std::snprintf(text, sizeof text,
                  "loop closure %lld-%lld (round %d): %d inliers of %d matches, t = [%.2f %.2f %.2f] m, %.2f s",
                  static_cast<long long>(outcome.subframe_id_a), static_cast<long long>(outcome.subframe_id_b),
                  outcome.association_round, outcome.closure.num_inliers, outcome.closure.num_matches, t.x(), t.y(),
                  t.z(), outcome.seconds);
    return text;
  }
  std::snprintf(text, sizeof text, "pair %lld-%lld (round %d) rejected: ", static_cast<long long>(outcome.subframe_id_a),
                static_cast<long long>(outcome.subframe_id_b), outcome.association_round);
  return text + outcome.reason;
}

}  // namespace

MatcherService::MatcherService(const MatcherServiceOptions& options, std::function<void()> results_ready,
                               sss::core::ServiceLog& log)
    : options_(options), results_ready_(std::move(results_ready)), engine_(options.engine) {
  if (!options_.state_directory.empty()) {
    store_ = std::make_unique<MatcherStateStore>(options_.state_directory);
  } else {
    log.warnings.push_back("no state directory (config matcher.state_directory or $STATE_DIRECTORY): a restart "
                           "loses the stored subframes");
  }
  // The worker's thread only queues what it has to say and wakes the loop, which says it.
  MatcherWorker::Hooks hooks;
  hooks.results_ready = results_ready_;
  hooks.state_error = [this](const std::string& error) {
    {
      std::lock_guard<std::mutex> lock(from_worker_mutex_);
      state_errors_.push_back(error);
    }
    if (results_ready_) results_ready_();
  };
  hooks.restored = [this](const RestoreReport& report) {
    {
      std::lock_guard<std::mutex> lock(from_worker_mutex_);
      for (const std::string& problem : report.problems) worker_log_.errors.push_back("state directory: " + problem);
      worker_log_.info.push_back(restoredLine(report));
    }
    if (results_ready_) results_ready_();
  };
  worker_ = std::make_unique<MatcherWorker>(engine_, store_.get(), MatcherWorkerOptions{options_.max_queued_subframes},
                                            hooks);
}

MatcherService::~MatcherService() { stop(); }

void MatcherService::start() { worker_->start(); }

void MatcherService::stop() { worker_->stop(); }

void MatcherService::addSubframe(const sss_msgs::subframe_t& message, int64_t arrival_monotonic_us,
                                 sss::core::HealthMonitor& health, sss::core::ServiceLog& log) {
  sss::core::Result<sss::core::Subframe> subframe = sss::messages::fromSubframeMessage(message);
  if (!subframe) {
    ++rejected_messages_;
    if (health.recordError("bad_subframe", subframe.message(), sss::core::nowUtime()))
      log.warnings.push_back("subframe " + std::to_string(message.subframe_id) + " rejected: " + subframe.message() +
                             "; further ones are counted in SSS_STATUS");
    return;
  }
  if (worker_->addSubframe(std::move(subframe).value(), arrival_monotonic_us) && !queue_full_said_) {
    queue_full_said_ = true;
    log.warnings.push_back("matcher queue full (" + std::to_string(options_.max_queued_subframes) +
                           " subframes): dropping the oldest; further drops are counted");
  }
}

void MatcherService::setTrajectory(const sss_msgs::trajectory_t& message, sss::core::HealthMonitor& health,
                                   sss::core::ServiceLog& log) {
  sss::core::Result<std::vector<TrajectoryNode>> nodes = sss::messages::fromTrajectoryMessage(message);
  if (!nodes) {
    ++rejected_messages_;
    if (health.recordError("bad_trajectory", nodes.message(), sss::core::nowUtime()))
      log.warnings.push_back("trajectory rejected: " + nodes.message() + "; further ones are counted in SSS_STATUS");
    return;
  }
  worker_->setTrajectory(std::move(nodes).value());
}

std::vector<ClosureToPublish> MatcherService::takeResults(int64_t now_utime_us, sss::core::HealthMonitor& health,
                                                          sss::core::ServiceLog& log) {
  std::vector<std::string> state_errors;
  {
    std::lock_guard<std::mutex> lock(from_worker_mutex_);
    log.errors.insert(log.errors.end(), worker_log_.errors.begin(), worker_log_.errors.end());
    log.info.insert(log.info.end(), worker_log_.info.begin(), worker_log_.info.end());
    worker_log_ = {};
    state_errors.swap(state_errors_);
  }
  for (const std::string& error : state_errors) {
    if (health.recordError("state_write", error, now_utime_us))
      log.warnings.push_back("state directory: " + error + "; further failures are counted in SSS_STATUS");
  }
  std::vector<ClosureToPublish> closures;
  for (const auto& [outcome, arrival] : worker_->takeOutcomes()) {
    if (outcome.accepted) closures.push_back({sss::messages::toLoopClosureMessage(outcome.closure, now_utime_us), arrival});
    log.info.push_back(outcomeLine(outcome));
  }
  return closures;
}

void MatcherService::reportHealth(sss::core::HealthMonitor& health, const std::string& subframe_channel) const {
  const MatcherWorkerStatus status = worker_->status();
  const MatcherEngineCounters& c = status.counters;
  const auto set = [&](const char* name, double value) { health.setCounter(name, value); };
  set("subframes_in", static_cast<double>(c.subframes_in));
  set("subframes_rejected", static_cast<double>(c.subframes_rejected + rejected_messages_));
  set("subframes_dropped_queue_full", static_cast<double>(status.dropped_subframes));
  set("subframes_evicted", static_cast<double>(c.subframes_evicted));
  set("subframes_stored", static_cast<double>(status.stored_subframes));
  set("trajectory_updates", static_cast<double>(c.trajectory_updates));
  set("pairs_attempted", static_cast<double>(c.pairs_attempted));
  set("closures_accepted", static_cast<double>(c.closures_accepted));
  set("pairs_rejected", static_cast<double>(c.pairs_rejected));
  set("rematches", static_cast<double>(c.rematches));
  set("closures_without_opposed_relief", static_cast<double>(c.closures_without_opposed_relief));
  set("closures_widened_by_passes", static_cast<double>(c.closures_widened_by_passes));
  set("subframes_restored", static_cast<double>(c.subframes_restored));
  set("pairs_restored", static_cast<double>(c.pairs_restored));
  set("state_files_corrupt", static_cast<double>(c.state_files_corrupt));
  set("state_write_errors", static_cast<double>(c.state_write_errors));
  set("mean_pair_s", c.pairs_attempted ? c.pair_seconds_total / static_cast<double>(c.pairs_attempted) : 0.0);
  set("memory_bytes", static_cast<double>(status.memory_bytes));
  set("busy", status.busy ? 1.0 : 0.0);
  health.setQueueDepth(subframe_channel, false, static_cast<int>(status.queued_subframes));
}

}  // namespace sss::matcher
