// The optimiser's worker thread. See optimiser_worker.hpp.
#include "pipeline/optimiser/optimiser_worker.hpp"

#include <algorithm>
#include <chrono>
#include <utility>

#include "pipeline/core/time.hpp"

namespace sss::optimiser {

void setStatusCounters(const OptimiserWorkerStatus& status, sss::core::HealthMonitor& health) {
  const PoseGraphCounters& graph = status.graph;
  const OptimiserEngineCounters& engine = status.engine;
  const FixCounters& fixes = status.fixes;
  const DrCalibration& calibration = status.calibration;
  health.setCounter("nodes", static_cast<double>(graph.nodes_added));
  health.setCounter("nodes_marginalised", static_cast<double>(graph.nodes_marginalised));
  health.setCounter("closures_received", static_cast<double>(graph.closures_received));
  health.setCounter("closures_accepted", static_cast<double>(graph.closures_accepted));
  health.setCounter("closures_rejected",
                    static_cast<double>(graph.closures_rejected_gate + graph.closures_rejected_inconsistent +
                                        graph.closures_rejected_no_support));
  health.setCounter("closures_refused", static_cast<double>(engine.closures_refused));
  health.setCounter("closures_waiting", static_cast<double>(engine.closures_waiting));
  health.setCounter("subframes_refused", static_cast<double>(engine.subframes_refused));
  health.setCounter("odometer_resets", static_cast<double>(engine.odometer_resets));
  // The odometry's drift per metre, per axis: the INS's reported one once it qualified (updates > 0).
  health.setCounter("odometry_drift_fraction", engine.odometry_drift_fraction);
  health.setCounter("odometry_drift_updates", static_cast<double>(engine.odometry_drift_updates));
  health.setCounter("fixes_received", static_cast<double>(fixes.received));
  health.setCounter("fixes_accepted", static_cast<double>(fixes.accepted));
  health.setCounter("fixes_rejected", static_cast<double>(fixes.rejected_gate + fixes.refused));
  health.setCounter("updates", static_cast<double>(graph.updates));
  // The DR calibration in use (re-estimated every calibration_period_s of mission time): 0 and NaN
  // sigmas before the first estimate; the scale's sigma NaN while no fix observes it.
  health.setCounter("full_smoothings", static_cast<double>(graph.full_smoothings));
  health.setCounter("calibration_estimated", calibration.estimated ? 1.0 : 0.0);
  health.setCounter("calibration_dvl_scale", calibration.dvl_scale);
  health.setCounter("calibration_dvl_scale_sigma", calibration.sigma(0));
  health.setCounter("calibration_heading_bias_rad", calibration.heading_bias_rad);
  health.setCounter("calibration_heading_cos_rad", calibration.heading_cos_rad);
  health.setCounter("calibration_heading_cos_sigma_rad", calibration.sigma(2));
  health.setCounter("calibration_heading_sin_rad", calibration.heading_sin_rad);
  health.setCounter("solver_failures", static_cast<double>(graph.solver_failures));
  health.setCounter("last_update_ms", 1e3 * graph.last_update_s);
  health.setCounter("memory_mb", static_cast<double>(status.memory_bytes) / 1e6);
  health.setCounter("last_checkpoint_ms", 1e3 * status.last_checkpoint_s);
}

OptimiserWorker::OptimiserWorker(OptimiserEngine& engine, OptimiserWorkerOptions options, Hooks hooks)
    : engine_(engine),
      options_(std::move(options)),
      hooks_(std::move(hooks)),
      snapshot_(std::make_shared<const SlidingWindowPoseGraph>(engine.graph())) {}

OptimiserWorker::~OptimiserWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    wake_.notify_one();
  }
  if (thread_.joinable()) thread_.join();
}

void OptimiserWorker::start() {
  if (engine_.graph().numNodes() > 0) {
    std::vector<std::string> none;
    publish(true, -1.0, none);
  }
  thread_ = std::thread([this] { run(); });
}

void OptimiserWorker::addSubframe(sss::core::Subframe subframe) {
  std::lock_guard<std::mutex> lock(mutex_);
  queued_.subframes.push_back(std::move(subframe));
  wake_.notify_one();
}

void OptimiserWorker::addLoopClosure(sss::core::LoopClosure closure) {
  std::lock_guard<std::mutex> lock(mutex_);
  queued_.closures.push_back(std::move(closure));
  wake_.notify_one();
}

void OptimiserWorker::addFix(AbsoluteFix fix) {
  std::lock_guard<std::mutex> lock(mutex_);
  queued_.fixes.push_back(std::move(fix));
  wake_.notify_one();
}

void OptimiserWorker::addNavAccuracy(const NavAccuracy& accuracy) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (last_nav_accuracy_us_ >= 0 && accuracy.utime_us < last_nav_accuracy_us_ + 1'000'000) return;
  last_nav_accuracy_us_ = accuracy.utime_us;
  queued_.nav_accuracy.push_back(accuracy);  // no wake: it waits for the next subframe or closure
}

void OptimiserWorker::requestProducts() {
  std::lock_guard<std::mutex> lock(mutex_);
  queued_.products = true;
  wake_.notify_one();
}

void OptimiserWorker::setOrigin(const sss::core::MissionOrigin& origin) {
  std::lock_guard<std::mutex> lock(mutex_);
  origin_ = origin;
}

std::optional<sss::core::MissionOrigin> OptimiserWorker::origin() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return origin_;
}

std::shared_ptr<const SlidingWindowPoseGraph> OptimiserWorker::snapshot() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return snapshot_;
}

OptimiserWorkerResults OptimiserWorker::takeResults() {
  std::lock_guard<std::mutex> lock(mutex_);
  OptimiserWorkerResults results;
  results.trajectory.swap(results_.trajectory);
  results.messages.swap(results_.messages);
  results.status = results_.status;
  return results;
}

void OptimiserWorker::take(const Batch& batch, std::vector<std::string>& messages) {
  for (const NavAccuracy& accuracy : batch.nav_accuracy) engine_.addNavAccuracy(accuracy);
  for (const sss::core::Subframe& subframe : batch.subframes) {
    const Status status = engine_.addSubframe(subframe);
    if (!status.ok) {
      messages.push_back("subframe " + std::to_string(subframe.id) + " refused: " + status.message);
    } else if (!status.message.empty()) {
      messages.push_back(status.message);  // an odometer reset
    }
    if (status.ok && hooks_.subframe_taken) hooks_.subframe_taken(subframe);
  }
  for (const sss::core::LoopClosure& closure : batch.closures) {
    const Status status = engine_.addLoopClosure(closure);
    if (!status.ok) {
      messages.push_back("closure " + std::to_string(closure.subframe_id_a) + "-" +
                         std::to_string(closure.subframe_id_b) + " refused: " + status.message);
    }
  }
  for (const AbsoluteFix& fix : batch.fixes) {
    const Status status = engine_.addFix(fix);
    if (!status.ok) messages.push_back("fix refused: " + status.message);
  }
}

double OptimiserWorker::saveCheckpoint(std::vector<std::string>& messages) {
  if (options_.checkpoint_path.empty()) return -1.0;
  const int64_t begin_us = sss::core::monotonicUtime();
  const Status saved = engine_.saveCheckpoint(options_.checkpoint_path);
  if (!saved.ok) messages.push_back("checkpoint: " + saved.message);
  return 1e-6 * static_cast<double>(sss::core::monotonicUtime() - begin_us);
}

void OptimiserWorker::publish(bool updated, double checkpoint_s, std::vector<std::string>& messages) {
  // Copied outside the lock: the loop must not wait for a copy of the graph.
  auto snapshot = updated ? std::make_shared<const SlidingWindowPoseGraph>(engine_.graph()) : nullptr;
  std::optional<std::vector<sss::core::TrajectoryNode>> trajectory;
  if (updated) trajectory = engine_.trajectory();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (snapshot) {
      snapshot_ = std::move(snapshot);
      results_.trajectory = std::move(trajectory);
    }
    OptimiserWorkerStatus& status = results_.status;
    status.graph = engine_.graph().counters();
    status.engine = engine_.counters();
    status.fixes = engine_.graph().fixCounters();
    status.calibration = engine_.graph().calibration();
    if (checkpoint_s >= 0.0) status.last_checkpoint_s = checkpoint_s;
    status.memory_bytes = engine_.memoryBytes();
    for (std::string& m : messages) results_.messages.push_back(std::move(m));
  }
  messages.clear();
  if (hooks_.results_ready) hooks_.results_ready();
}

void OptimiserWorker::run() {
  double last_update_monotonic_s = -1e9;
  for (;;) {
    Batch batch;
    std::optional<sss::core::MissionOrigin> origin;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      // Woken by input; the timeout lets a batch that came within the last period be solved.
      wake_.wait_for(lock, std::chrono::duration<double>(std::max(options_.update_period_s, 0.05)), [&] {
        return stop_ || !queued_.subframes.empty() || !queued_.closures.empty() || !queued_.fixes.empty() ||
               queued_.products;
      });
      if (stop_) return;
      std::swap(batch, queued_);
      origin = origin_;
    }
    std::vector<std::string> messages;
    take(batch, messages);
    const double now_s = 1e-6 * static_cast<double>(sss::core::monotonicUtime());
    bool updated = false;
    if (batch.products) {
      engine_.finish();
      if (hooks_.write_products) hooks_.write_products(engine_, origin, messages);
      updated = true;
    } else if (engine_.hasNewInput() && now_s - last_update_monotonic_s >= options_.update_period_s) {
      const UpdateReport report = engine_.update();
      if (!report.ok) messages.push_back("update failed: " + report.message);
      last_update_monotonic_s = now_s;
      updated = true;
    }
    const double checkpoint_s = updated ? saveCheckpoint(messages) : -1.0;
    if (updated || !messages.empty()) publish(updated, checkpoint_s, messages);
  }
}

std::vector<std::string> OptimiserWorker::finish() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    wake_.notify_one();
  }
  if (thread_.joinable()) thread_.join();
  Batch batch;
  std::optional<sss::core::MissionOrigin> origin;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    std::swap(batch, queued_);
    origin = origin_;
  }
  std::vector<std::string> messages;
  take(batch, messages);
  if (engine_.graph().numNodes() == 0) return messages;
  engine_.finish();
  if (hooks_.write_products) hooks_.write_products(engine_, origin, messages);
  saveCheckpoint(messages);
  return messages;
}

}  // namespace sss::optimiser
