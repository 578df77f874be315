// What sss-optimiser does around its engine and worker, without middleware and without logging
// (what happened comes back as log lines for the process to write):
//   start:    the engine is restored from the state directory's checkpoint, if there is one;
//   inputs:   SSS_SUBFRAME, SSS_LOOP and SSS_FIX messages are decoded and queued for the worker,
//             which solves the graph on its own thread (optimiser_worker.hpp). A message that
//             cannot be used is counted in SSS_STATUS under its kind (bad_subframe,
//             bad_loop_closure, bad_fix) and the first of each kind logged with its cause;
//   nav:      every SSS_NAV sample is answered at once with the corrected pose (SSS_POSE) from the
//             newest solved graph (nav_corrector.hpp), never waiting for a solve;
//   results:  what the worker solved since the last call: the trajectory for the matcher, the
//             status counters, its log lines;
//   products: the subframes at mosaic resolution and their footprints are kept for the live
//             products, written after a full smoothing (on request and at the end of the mission).
// The process wires these to LCM, DDS, an eventfd and its timers.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "sss_msgs/fix_t.hpp"
#include "sss_msgs/loop_closure_t.hpp"
#include "sss_msgs/nav_t.hpp"
#include "sss_msgs/pose_t.hpp"
#include "sss_msgs/subframe_t.hpp"
#include "sss_msgs/trajectory_t.hpp"
#include "pipeline/core/health.hpp"
#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/service_log.hpp"
#include "pipeline/optimiser/correction_slew.hpp"
#include "pipeline/optimiser/nav_corrector.hpp"
#include "pipeline/optimiser/optimiser_engine.hpp"
#include "pipeline/optimiser/optimiser_worker.hpp"
#include "products/footprints.hpp"
#include "products/mosaic_products.hpp"

namespace sss::optimiser {

struct OptimiserServiceOptions {
  OptimiserEngineOptions engine;
  CorrectionSlewOptions slew;
  double update_period_s = 1.0;  // at most one solve per period, when there is new input
  // The checkpoint (optimiser.checkpoint) lives here. Empty: none, and a warning at start says
  // what a restart then loses.
  std::string state_directory;
  std::string products_directory;  // empty: no products
  // The mosaics among the products keep every subframe at mosaic resolution (~0.6 MB per 100 m of
  // line at 75 m range); beyond this bound the oldest go, and the mosaics show the newest part.
  double products_mosaic_max_mib = 256.0;
  // The configuration's mission origin, only to warn when the navigation's differs (poses are
  // geo-referenced with the origin each SSS_NAV sample carries).
  std::optional<sss::core::MissionOrigin> configured_origin;
};

// The answer to one nav sample.
struct CorrectedPose {
  sss_msgs::pose_t pose;
  int accepted_closures = 0;  // in the graph the correction comes from (for the DDS sample)
};

class OptimiserService {
 public:
  // results_ready is called from the worker's thread when takeResults() has something.
  OptimiserService(const OptimiserServiceOptions& options, std::function<void()> results_ready,
                   sss::core::ServiceLog& log);
  OptimiserService(const OptimiserService&) = delete;
  OptimiserService& operator=(const OptimiserService&) = delete;

  // Starts the worker's thread; a restored graph's trajectory goes out at once.
  void start();

  // The corrected pose, or nothing for a sample that cannot be answered (counted, logged once).
  std::optional<CorrectedPose> addNav(const sss_msgs::nav_t& message, sss::core::HealthMonitor& health,
                                      sss::core::ServiceLog& log);
  void addSubframe(const sss_msgs::subframe_t& message, sss::core::HealthMonitor& health, sss::core::ServiceLog& log);
  void addLoopClosure(const sss_msgs::loop_closure_t& message, sss::core::HealthMonitor& health,
                      sss::core::ServiceLog& log);
  // Fixes placed in the mission frame by the INS bridge: used only in the navigation's frame.
  void addFix(const sss_msgs::fix_t& message, sss::core::HealthMonitor& health, sss::core::ServiceLog& log);

  // The worker's news: the trajectory to publish (if an update made one), its counters into health.
  std::optional<sss_msgs::trajectory_t> takeResults(sss::core::HealthMonitor& health, int64_t now_utime_us,
                                                    sss::core::ServiceLog& log);
  // The published correction's slew figures (off the nav path: once a second is enough).
  void reportSlew(sss::core::HealthMonitor& health) const;
  // A full smoothing and the products (SIGUSR1).
  void requestProducts(sss::core::ServiceLog& log);
  // End of mission: what is still queued, full smoothing, products, a last checkpoint.
  void finish(sss::core::ServiceLog& log);

  const std::string& checkpointPath() const { return checkpoint_path_; }

 private:
  const OptimiserServiceOptions options_;
  OptimiserEngine engine_;
  // The subframes at mosaic resolution for the products' mosaics, only since this start (a restart
  // restores the graph from its checkpoint, not the images); their footprints (~1 kB each) all mission.
  sss::products::MosaicStore mosaics_;
  std::vector<sss::products::SubframeFootprint> footprints_;
  std::string checkpoint_path_;
  NavCorrector corrector_;
  OptimiserWorker worker_;
};

}  // namespace sss::optimiser
