#include "pipeline/optimiser/optimiser_service.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <utility>

#include "pipeline/core/time.hpp"
#include "pipeline/messages/closure_messages.hpp"
#include "pipeline/messages/sensor_messages.hpp"
#include "pipeline/messages/subframe_messages.hpp"
#include "pipeline/optimiser/fix_message.hpp"
#include "pipeline/optimiser/pose_message.hpp"
#include "products/live_products.hpp"

namespace sss::optimiser {
namespace {

namespace fs = std::filesystem;

std::string formatOrigin(const sss::core::MissionOrigin& origin) {
  char text[64];
  std::snprintf(text, sizeof text, "%.7f %.7f", origin.latitude_deg, origin.longitude_deg);
  return text;
}

// The checkpoint's path in the state directory (empty: none), restored into the engine if it is there.
std::string restoreCheckpoint(const std::string& state_directory, OptimiserEngine& engine, sss::core::ServiceLog& log) {
  if (state_directory.empty()) {
    log.warnings.push_back("no state directory (config optimiser.state_directory or $STATE_DIRECTORY): no "
                           "checkpoints, a restart loses the graph");
    return {};
  }
  const std::string checkpoint_path = state_directory + "/optimiser.checkpoint";
  std::error_code ec;
  fs::create_directories(state_directory, ec);
  if (!fs::exists(checkpoint_path)) return checkpoint_path;
  const Status loaded = engine.loadCheckpoint(checkpoint_path);
  if (loaded.ok) {
    log.info.push_back("resumed from " + checkpoint_path + ": " + std::to_string(engine.graph().numNodes()) +
                       " nodes, " + std::to_string(engine.graph().counters().closures_accepted) +
                       " closures accepted, ping poses of " + std::to_string(engine.storedSubframes()) +
                       " subframes, " + std::to_string(engine.counters().odometer_resets) + " odometer resets");
  } else {
    log.errors.push_back("checkpoint " + checkpoint_path + " refused (" + loaded.message + "); starting empty");
  }
  return checkpoint_path;
}

// Counts a rejected input under its kind; the first of a kind is logged with its cause.
void reject(const std::string& kind, const std::string& what, const std::string& error,
            sss::core::HealthMonitor& health, sss::core::ServiceLog& log) {
  if (health.recordError(kind, error, sss::core::nowUtime()))
    log.warnings.push_back(what + " rejected: " + error + "; further ones are counted in SSS_STATUS");
}

}  // namespace

OptimiserService::OptimiserService(const OptimiserServiceOptions& options, std::function<void()> results_ready,
                                   sss::core::ServiceLog& log)
    : options_(options),
      engine_(options.engine),
      mosaics_(sss::subframe::PictureOptions{}, static_cast<size_t>(options.products_mosaic_max_mib * 1024.0 * 1024.0)),
      checkpoint_path_(restoreCheckpoint(options.state_directory, engine_, log)),
      corrector_(options.slew),
      worker_(engine_, {options.update_period_s, checkpoint_path_},
              OptimiserWorker::Hooks{
                  [this](const sss::core::Subframe& subframe) {  // on the worker's thread
                    mosaics_.add(subframe);                      // decimated: ~1/5 of the image
                    footprints_.push_back(sss::products::footprintOf(subframe));
                  },
                  [this](const OptimiserEngine& engine, const std::optional<sss::core::MissionOrigin>& origin,
                         std::vector<std::string>& messages) {
                    if (!options_.products_directory.empty())
                      sss::products::writeLiveProducts(engine, mosaics_, footprints_, options_.products_directory,
                                                       origin, messages);
                  },
                  std::move(results_ready)}) {}

void OptimiserService::start() { worker_.start(); }

std::optional<CorrectedPose> OptimiserService::addNav(const sss_msgs::nav_t& message, sss::core::HealthMonitor& health,
                                                      sss::core::ServiceLog& log) {
  const sss::core::NavSample nav = sss::messages::fromNavMessage(message);
  const NavCorrection answer = corrector_.correct(nav, *worker_.snapshot());
  if (nav.position_valid) worker_.addNavAccuracy(navAccuracyOf(nav));
  if (answer.verdict == NavVerdict::kBadSample) {
    if (health.recordError("bad_nav", "nav sample with non-finite pose or no time", sss::core::nowUtime()))
      log.warnings.push_back("nav sample rejected (non-finite pose or no time); further ones are counted in SSS_STATUS");
    return std::nullopt;
  }
  if (answer.verdict == NavVerdict::kNoPosition) {
    // Before the INS's first fix: no position, no frame, nothing to correct yet.
    if (health.recordError("nav_without_position", "nav sample without a position or origin", sss::core::nowUtime()))
      log.warnings.push_back("nav sample without a position (before the INS's first fix?) not corrected; further "
                             "ones are counted in SSS_STATUS");
    return std::nullopt;
  }
  if (answer.origin_changed) {
    const sss::core::MissionOrigin& origin = *nav.origin;
    if (answer.previous_origin) {
      log.errors.push_back("the navigation's origin moved from " + formatOrigin(*answer.previous_origin) + " to " +
                           formatOrigin(origin) + " (INS bridge restarted without its state directory?): "
                           "corrected poses are geo-referenced with the new one");
    } else {
      log.info.push_back("mission origin (from SSS_NAV): " + formatOrigin(origin));
    }
    const std::optional<sss::core::MissionOrigin>& configured = options_.configured_origin;
    if (configured && (configured->latitude_deg != origin.latitude_deg || configured->longitude_deg != origin.longitude_deg)) {
      log.warnings.push_back("the navigation's origin differs from mission.origin_* in the configuration (does the "
                             "INS bridge read the same file?); the navigation's is used");
    }
    worker_.setOrigin(origin);
  }
  if (answer.jump_m) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "the correction of the present pose jumped %.2f m (a fix or closures accepted); the published "
                  "pose follows at %.2f m/s, its covariance widened by what is left",
                  *answer.jump_m, options_.slew.max_rate_m_s);
    log.info.push_back(text);
  }
  return CorrectedPose{toPoseMessage(nav.utime_us, answer.dr, answer.correction, *corrector_.plane()),
                       answer.correction.accepted_closures};
}

void OptimiserService::addSubframe(const sss_msgs::subframe_t& message, sss::core::HealthMonitor& health,
                                   sss::core::ServiceLog& log) {
  sss::core::Result<sss::core::Subframe> subframe = sss::messages::fromSubframeMessage(message);
  if (!subframe) {
    reject("bad_subframe", "subframe " + std::to_string(message.subframe_id), subframe.message(), health, log);
    return;
  }
  // The image travels to the worker, which keeps it for the products at mosaic resolution (off the
  // loop, which answers every nav sample); the graph keeps poses only.
  worker_.addSubframe(std::move(subframe).value());
}

void OptimiserService::addLoopClosure(const sss_msgs::loop_closure_t& message, sss::core::HealthMonitor& health,
                                      sss::core::ServiceLog& log) {
  sss::core::Result<sss::core::LoopClosure> closure = sss::messages::fromLoopClosureMessage(message);
  if (!closure) {
    reject("bad_loop_closure", "loop closure", closure.message(), health, log);
    return;
  }
  worker_.addLoopClosure(std::move(closure).value());
}

void OptimiserService::addFix(const sss_msgs::fix_t& message, sss::core::HealthMonitor& health,
                              sss::core::ServiceLog& log) {
  sss::core::Result<AbsoluteFix> fix = fromFixMessage(message);
  const sss::core::MissionOrigin origin = fixMessageOrigin(message);
  const std::optional<sss::core::MissionOrigin> nav_origin = worker_.origin();
  if (fix && nav_origin && (std::abs(origin.latitude_deg - nav_origin->latitude_deg) > 1e-9 ||
                            std::abs(origin.longitude_deg - nav_origin->longitude_deg) > 1e-9)) {
    fix = sss::core::Status::error("the fix's mission origin differs from the navigation's (another INS bridge?)");
  }
  if (!fix) {
    reject("bad_fix", "fix", fix.message(), health, log);
    return;
  }
  worker_.addFix(*fix);
}

std::optional<sss_msgs::trajectory_t> OptimiserService::takeResults(sss::core::HealthMonitor& health,
                                                                    int64_t now_utime_us, sss::core::ServiceLog& log) {
  OptimiserWorkerResults results = worker_.takeResults();
  log.info.insert(log.info.end(), results.messages.begin(), results.messages.end());
  setStatusCounters(results.status, health);
  if (!results.trajectory || results.trajectory->empty()) return std::nullopt;
  return sss::messages::toTrajectoryMessage(*results.trajectory, now_utime_us);
}

void OptimiserService::reportSlew(sss::core::HealthMonitor& health) const {
  health.setCounter("correction_lag_m", corrector_.slew().lagM());
  health.setCounter("correction_last_jump_m", corrector_.slew().lastJumpM());
  health.setCounter("correction_jumps", static_cast<double>(corrector_.slew().jumps()));
}

void OptimiserService::requestProducts(sss::core::ServiceLog& log) {
  log.info.push_back("products requested (SIGUSR1): full smoothing");
  worker_.requestProducts();
}

void OptimiserService::finish(sss::core::ServiceLog& log) {
  const std::vector<std::string> messages = worker_.finish();
  log.info.insert(log.info.end(), messages.begin(), messages.end());
}

}  // namespace sss::optimiser
