// The optimiser's worker: solves the graph on its own thread, so that the process loop, which
// answers every nav sample (200 Hz, latency-bound), never waits for a solve.
//
// Inputs queue here from the loop's subscriptions. The worker takes them in batches; it updates
// the graph at most once per update_period_s and only when there is new input; it writes a
// checkpoint after every update; on request (SIGUSR1) it runs a full smoothing and writes the
// products. After each of these it hands back a snapshot of the solved graph (the loop answers
// nav samples from it), the trajectory for the matcher, its figures for SSS_STATUS and its log
// lines, and calls results_ready. finish() at the end of the mission stops the thread, then takes
// whatever is still queued, smooths, writes the products and a last checkpoint.
// No middleware: the node wires these to LCM, an eventfd and the status.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/core/closure_types.hpp"
#include "pipeline/core/health.hpp"
#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/subframe_types.hpp"
#include "pipeline/optimiser/optimiser_engine.hpp"
#include "pipeline/optimiser/pose_graph.hpp"

namespace sss::optimiser {

struct OptimiserWorkerOptions {
  double update_period_s = 1.0;  // at most one update per period, when there is new input
  std::string checkpoint_path;   // empty: no checkpoints
};

// The worker's figures as of its newest update (SSS_STATUS).
struct OptimiserWorkerStatus {
  PoseGraphCounters graph;
  OptimiserEngineCounters engine;
  FixCounters fixes;
  DrCalibration calibration;
  double last_checkpoint_s = 0.0;  // how long the newest checkpoint took
  size_t memory_bytes = 0;
};

// Writes the worker's status as SSS_STATUS counters (nodes, closures_*, fixes_*, calibration_*, ...).
void setStatusCounters(const OptimiserWorkerStatus& status, sss::core::HealthMonitor& health);

// What the worker hands back to the loop since the last takeResults().
struct OptimiserWorkerResults {
  std::optional<std::vector<sss::core::TrajectoryNode>> trajectory;  // the newest, if an update made one
  std::vector<std::string> messages;                                  // log lines
  OptimiserWorkerStatus status;
};

class OptimiserWorker {
 public:
  struct Hooks {
    // On the worker thread, for every subframe the engine took (the live products keep its image).
    std::function<void(const sss::core::Subframe&)> subframe_taken;
    // On the worker thread after a full smoothing (on request and at the end): the products.
    std::function<void(const OptimiserEngine&, const std::optional<sss::core::MissionOrigin>&,
                       std::vector<std::string>& messages)>
        write_products;
    // From the worker thread when results are ready (the loop wakes and calls takeResults()).
    std::function<void()> results_ready;
  };

  // The engine (possibly restored from a checkpoint) is the worker's from start() to finish().
  OptimiserWorker(OptimiserEngine& engine, OptimiserWorkerOptions options, Hooks hooks);
  ~OptimiserWorker();  // stops the thread without finishing (finish() is the end of a mission)
  OptimiserWorker(const OptimiserWorker&) = delete;
  OptimiserWorker& operator=(const OptimiserWorker&) = delete;

  // Starts the thread. A restored graph's trajectory and figures go out at once (the matcher
  // re-associates with them), not only after the next update.
  void start();

  void addSubframe(sss::core::Subframe subframe);
  void addLoopClosure(sss::core::LoopClosure closure);
  void addFix(AbsoluteFix fix);
  // The INS's reported accuracy (OptimiserEngine::addNavAccuracy); nav comes at up to 200 Hz, so at
  // most one per second is queued (the anchor, then the INS's drift rate).
  void addNavAccuracy(const NavAccuracy& accuracy);
  void requestProducts();
  // The navigation's origin (SSS_NAV), which geo-references the products.
  void setOrigin(const sss::core::MissionOrigin& origin);
  std::optional<sss::core::MissionOrigin> origin() const;

  // The newest solved graph (never null): corrections for the nav samples.
  std::shared_ptr<const SlidingWindowPoseGraph> snapshot() const;
  OptimiserWorkerResults takeResults();

  // End of mission: stops the thread, then adds what is still queued, runs the full smoothing,
  // writes the products and a last checkpoint. Returns their log lines. Call once, after start().
  std::vector<std::string> finish();

 private:
  struct Batch {
    std::deque<sss::core::Subframe> subframes;
    std::deque<sss::core::LoopClosure> closures;
    std::deque<AbsoluteFix> fixes;
    std::deque<NavAccuracy> nav_accuracy;
    bool products = false;
  };
  void run();
  // Gives the engine a batch; log lines into messages.
  void take(const Batch& batch, std::vector<std::string>& messages);
  // Saves the checkpoint (if any); how long it took, or -1 when there is none.
  double saveCheckpoint(std::vector<std::string>& messages);
  // Publishes the engine's state to the loop (under the lock) and calls results_ready.
  void publish(bool updated, double checkpoint_s, std::vector<std::string>& messages);

  OptimiserEngine& engine_;
  const OptimiserWorkerOptions options_;
  const Hooks hooks_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  Batch queued_;
  bool stop_ = false;
  std::optional<sss::core::MissionOrigin> origin_;
  int64_t last_nav_accuracy_us_ = -1;  // of the last one queued
  std::shared_ptr<const SlidingWindowPoseGraph> snapshot_;
  OptimiserWorkerResults results_;
  std::thread thread_;
};

}  // namespace sss::optimiser
