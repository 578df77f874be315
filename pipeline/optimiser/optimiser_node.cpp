// sss-optimiser: SSS_SUBFRAME + SSS_LOOP (+ SSS_FIX: absolute fixes) -> pose graph -> SSS_TRAJECTORY (matcher); SSS_NAV ->
// SSS_POSE for every nav sample and the correction on DDS for the navigation computer.
// Wiring only: the graph is solved by OptimiserWorker (optimiser_worker.hpp) on its own thread; the
// process loop answers each nav sample with NavCorrector (nav_corrector.hpp) from a snapshot of the
// newest solved graph, so a solve never delays a pose; the DDS correction is paced by
// LatestSamplePacer. The engine (graph, ping poses, correspondences) is checkpointed after every update
// into the state directory and restored at start. On SIGTERM (end of mission) or SIGUSR1 (on request) it runs full smoothing and
// writes the products: optimised trajectory (TUM), corrected navigation (navigation.csv, .nmea), tie report
// (loop_closures.csv), tracks and footprints (GeoJSON), coverage, mosaics, bathymetry (PLY) and heightmap,
// the rasters also as GeoTIFF in the origin's UTM zone.
//   sss-optimiser [--config FILE [--check-config]] [--lcm-url URL]
#include <sys/eventfd.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <csignal>
#include <cstdio>
#include <memory>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/geodesy.hpp"
#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/state_file.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/messages/closure_messages.hpp"
#include "pipeline/optimiser/optimiser_engine.hpp"
#include "pipeline/optimiser/correction_slew.hpp"
#include "pipeline/optimiser/fix_message.hpp"
#include "pipeline/optimiser/nav_corrector.hpp"
#include "pipeline/optimiser/optimiser_worker.hpp"
#include "products/footprints.hpp"
#include "products/live_products.hpp"
#include "products/mosaic_products.hpp"
#include "pipeline/optimiser/pose_message.hpp"
#include "pipeline/messages/subframe_messages.hpp"
#include "pipeline/messages/sensor_messages.hpp"
#include "pipeline/transport/dds.hpp"
#include "pipeline/transport/latest_sample_pacer.hpp"
#include "pipeline/transport/logging.hpp"
#include "pipeline/transport/process_loop.hpp"
#include "pipeline/transport/process_options.hpp"

namespace {

namespace fs = std::filesystem;
using sss::optimiser::OptimiserEngine;

struct NodeOptions {
  sss::transport::ProcessOptions process;
  sss::optimiser::OptimiserEngineOptions engine;
  // Only to check the configuration: poses are geo-referenced with the origin each SSS_NAV
  // sample carries (the frame its NED position is in; the INS bridge's choice).
  std::optional<sss::core::MissionOrigin> configured_origin;
  std::string subframe_channel = "SSS_SUBFRAME";
  std::string loop_channel = "SSS_LOOP";
  std::string fix_channel = "SSS_FIX";
  std::string nav_channel = "SSS_NAV";
  std::string pose_channel = "SSS_POSE";
  std::string trajectory_channel = "SSS_TRAJECTORY";
  // The published correction slews towards the graph's at a bounded rate (a fix can move it by metres).
  sss::optimiser::CorrectionSlewOptions slew;
  double update_period_s = 1.0;  // at most one solve per period, when there is new input
  // Checkpoint and products. Empty: $STATE_DIRECTORY (systemd StateDirectory=), else none.
  std::string state_directory;
  std::string products_directory;  // empty: <state_directory>/products
  // The mosaics among the products keep every subframe at mosaic resolution (~0.6 MB per 100 m of
  // line at 75 m range); beyond this bound the oldest go, and the mosaics show the newest part.
  double products_mosaic_max_mib = 256.0;
  bool dds_enabled = true;
  int dds_domain_id = 0;
  std::string dds_topic = "sss_navigation_correction";
  double dds_rate_hz = 10.0;
  int vehicle_id = 1;
  bool dds_loopback_only = false;  // tests and single-host chains
};

std::atomic<bool> g_products_requested{false};
void onSigusr1(int) { g_products_requested.store(true); }

// The node's options from the configuration file (none: the defaults). Empty when valid, else
// the problems, one per line.
std::string readNodeOptions(const std::string& config_path, NodeOptions& options) {
  options.process.process_name = "sss-optimiser";
  if (config_path.empty()) return {};  // the defaults
  using namespace sss::core;
  Config config = Config::fromFile(config_path);
  ConfigSection mission = config.section("mission");
  options.configured_origin = sss::core::readMissionOrigin(mission);
  ConfigSection section = config.section("optimiser");
  sss::transport::readProcessOptions(section, options.process);
  sss::optimiser::readOptimiserEngineOptions(section, options.engine);
  sss::optimiser::readCorrectionSlewOptions(section, options.slew);
  section.optional("subframe_channel", options.subframe_channel, {nonEmpty()});
  section.optional("loop_channel", options.loop_channel, {nonEmpty()});
  section.optional("fix_channel", options.fix_channel, {nonEmpty()});
  section.optional("nav_channel", options.nav_channel, {nonEmpty()});
  section.optional("pose_channel", options.pose_channel, {nonEmpty()});
  section.optional("trajectory_channel", options.trajectory_channel, {nonEmpty()});
  section.optional("update_period_s", options.update_period_s, {inRange(0.0, 3600.0)});
  section.optional("state_directory", options.state_directory);
  section.optional("products_directory", options.products_directory);
  section.optional("products_mosaic_max_mib", options.products_mosaic_max_mib, {inRange(0.0, 65536.0)});
  ConfigSection dds = section.section("dds");
  dds.optional("enabled", options.dds_enabled);
  dds.optional("domain_id", options.dds_domain_id, {inRange(0, 232)});
  dds.optional("topic", options.dds_topic, {nonEmpty()});
  dds.optional("rate_hz", options.dds_rate_hz, {inRange(0.01, 1000.0)});
  dds.optional("vehicle_id", options.vehicle_id, {inRange(0, 1000000)});
  dds.optional("loopback_only", options.dds_loopback_only);
  dds.rejectUnknownKeys();
  section.rejectUnknownKeys();
  for (const std::string& problem : sss::optimiser::validateOptimiserEngineOptions(options.engine)) {
    section.addProblem("optimiser", "", problem);
  }
  for (const std::string& problem : sss::optimiser::validateCorrectionSlewOptions(options.slew)) {
    section.addProblem("optimiser", "", problem);
  }
  return config.problemReport();
}

// The checkpoint's path in the state directory (empty: none), restored into the engine if it is there.
std::string restoreCheckpoint(const std::string& state_directory, OptimiserEngine& engine) {
  if (state_directory.empty()) {
    spdlog::warn("no state directory (config optimiser.state_directory or $STATE_DIRECTORY): no checkpoints, "
                 "a restart loses the graph");
    return {};
  }
  const std::string checkpoint_path = state_directory + "/optimiser.checkpoint";
  std::error_code ec;
  fs::create_directories(state_directory, ec);
  if (!fs::exists(checkpoint_path)) return checkpoint_path;
  const sss::optimiser::Status loaded = engine.loadCheckpoint(checkpoint_path);
  if (loaded.ok) {
    spdlog::info("resumed from {}: {} nodes, {} closures accepted, ping poses of {} subframes, {} odometer resets",
                 checkpoint_path, engine.graph().numNodes(), engine.graph().counters().closures_accepted,
                 engine.storedSubframes(), engine.counters().odometer_resets);
  } else {
    spdlog::error("checkpoint {} refused ({}); starting empty", checkpoint_path, loaded.message);
  }
  return checkpoint_path;
}

// The DDS participant, topic and writer of the correction, or why there are none.
class DdsCorrectionWriter {
 public:
  explicit DdsCorrectionWriter(const NodeOptions& options)
      : participant_(static_cast<uint32_t>(options.dds_domain_id),
                     options.dds_loopback_only ? sss::transport::dds::loopbackConfigXml() : std::string()) {
    if (!participant_.good()) return;
    topic_ = std::make_unique<sss::transport::dds::Topic<sss_dds_NavigationCorrection>>(
        participant_, &sss_dds_NavigationCorrection_desc, options.dds_topic);
    if (topic_->good()) writer_ = std::make_unique<sss::transport::dds::Writer<sss_dds_NavigationCorrection>>(participant_, *topic_);
  }
  bool good() const { return writer_ && writer_->good(); }
  std::string error() const { return participant_.good() ? "topic or writer" : participant_.error(); }
  bool write(const sss_dds_NavigationCorrection& sample) { return writer_->write(sample); }

 private:
  sss::transport::dds::Participant participant_;
  std::unique_ptr<sss::transport::dds::Topic<sss_dds_NavigationCorrection>> topic_;
  std::unique_ptr<sss::transport::dds::Writer<sss_dds_NavigationCorrection>> writer_;
};

void logOriginChange(const std::optional<sss::core::MissionOrigin>& previous, const sss::core::MissionOrigin& origin,
                     const std::optional<sss::core::MissionOrigin>& configured) {
  if (previous) {
    spdlog::error("the navigation's origin moved from {:.7f} {:.7f} to {:.7f} {:.7f} (INS bridge restarted "
                  "without its state directory?): corrected poses are geo-referenced with the new one",
                  previous->latitude_deg, previous->longitude_deg, origin.latitude_deg, origin.longitude_deg);
  } else {
    spdlog::info("mission origin (from SSS_NAV): {:.7f} {:.7f}", origin.latitude_deg, origin.longitude_deg);
  }
  if (configured && (configured->latitude_deg != origin.latitude_deg || configured->longitude_deg != origin.longitude_deg)) {
    spdlog::warn("the navigation's origin differs from mission.origin_* in the configuration (does the INS "
                 "bridge read the same file?); the navigation's is used");
  }
}

}  // namespace

int main(int argc, char** argv) {
  sss::transport::NodeArguments arguments;
  const int usage_exit_code = sss::transport::parseNodeArguments(
      "sss-optimiser", "sliding-window pose graph: SSS_SUBFRAME + SSS_LOOP + SSS_NAV (+ SSS_FIX) -> SSS_POSE, SSS_TRAJECTORY, DDS",
      argc, argv, arguments);
  if (usage_exit_code >= 0) return usage_exit_code;
  NodeOptions options;
  const std::string config_problems = readNodeOptions(arguments.config_path, options);
  if (const int code = sss::transport::configVerdict("sss-optimiser", config_problems, arguments.config_path, arguments.check_config_only); code >= 0) {
    return code;
  }
  if (!arguments.lcm_url_override.empty()) options.process.lcm_url = arguments.lcm_url_override;
  options.state_directory = sss::core::resolveSystemdDirectory(options.state_directory, std::getenv("STATE_DIRECTORY"));
  if (options.products_directory.empty() && !options.state_directory.empty()) {
    options.products_directory = options.state_directory + "/products";
  }

  sss::transport::initLogging(options.process.process_name, options.process.log_level);
  sss::transport::ProcessLoop loop(options.process);
  sss::core::HealthMonitor& health = loop.health();
  // Determinism and bounded latency come from the iteration bound; the time limit is the config's.
  OptimiserEngine engine(options.engine);
  // The subframes at mosaic resolution for the products' mosaics: only since this start (a restart
  // restores the graph from its checkpoint, not the images).
  sss::products::MosaicStore mosaics(sss::subframe::PictureOptions{},
                                     static_cast<size_t>(options.products_mosaic_max_mib * 1024.0 * 1024.0));
  std::vector<sss::products::SubframeFootprint> footprints;  // ~1 kB per subframe, kept all mission
  auto keepForProducts = [&](const sss::core::Subframe& subframe) {
    mosaics.add(subframe);  // decimated: ~1/5 of the image
    footprints.push_back(sss::products::footprintOf(subframe));
  };
  const std::string checkpoint_path = restoreCheckpoint(options.state_directory, engine);

  sss::optimiser::OptimiserWorker::Hooks hooks;
  hooks.subframe_taken = keepForProducts;
  hooks.write_products = [&](const OptimiserEngine& e, const std::optional<sss::core::MissionOrigin>& origin,
                             std::vector<std::string>& messages) {
    if (!options.products_directory.empty())
      sss::products::writeLiveProducts(e, mosaics, footprints, options.products_directory, origin, messages);
  };
  const int results_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (results_fd < 0) {
    spdlog::error("cannot create an eventfd for the optimiser thread");
    return 1;
  }
  hooks.results_ready = [results_fd] {
    const uint64_t one = 1;
    if (write(results_fd, &one, sizeof one) < 0) {
      // Saturated counter: the loop is already due to read.
    }
  };
  sss::optimiser::OptimiserWorker worker(engine, {options.update_period_s, checkpoint_path}, hooks);

  // ---- DDS: the newest correction, reliable, keep-last 1, transient-local ----------------------
  std::unique_ptr<DdsCorrectionWriter> dds_writer;
  if (options.dds_enabled) {
    dds_writer = std::make_unique<DdsCorrectionWriter>(options);
    if (!dds_writer->good()) {
      spdlog::error("DDS writer for topic '{}' on domain {} could not be created ({}); corrections go on LCM only",
                    options.dds_topic, options.dds_domain_id, dds_writer->error());
      dds_writer.reset();
      health.recordError("dds", "DDS writer unavailable", sss::core::nowUtime());
    }
  }
  // Written from the nav callback, so the navigation computer gets a correction as soon as its nav
  // sample is answered (not up to a timer period later), at most dds.rate_hz (latest_sample_pacer.hpp).
  sss::transport::LatestSamplePacer<sss_dds_NavigationCorrection> dds_pacer(static_cast<int64_t>(1e6 / options.dds_rate_hz));
  uint64_t dds_written = 0;
  auto writeDds = [&](const sss_dds_NavigationCorrection& sample) {
    if (dds_writer->write(sample)) {
      ++dds_written;
      health.setCounter("dds_corrections", static_cast<double>(dds_written));
    } else if (health.recordError("dds_write", "DDS write failed", sss::core::nowUtime())) {
      spdlog::warn("DDS write failed; further failures are counted in SSS_STATUS");
    }
  };

  sss::optimiser::NavCorrector corrector(options.slew);
  // Off the nav path (200 Hz, latency-bound): the slew's figures go to SSS_STATUS once a second.
  loop.addTimer(1.0, [&] {
    health.setCounter("correction_lag_m", corrector.slew().lagM());
    health.setCounter("correction_last_jump_m", corrector.slew().lastJumpM());
    health.setCounter("correction_jumps", static_cast<double>(corrector.slew().jumps()));
  });
  // ---- subscriptions ------------------------------------------------------------------------------
  loop.bus().subscribe<sss_msgs::nav_t>(options.nav_channel, [&](const sss_msgs::nav_t& message) {
    const int64_t arrival = sss::core::monotonicUtime();
    const sss::core::NavSample nav = sss::messages::fromNavMessage(message);
    const sss::optimiser::NavCorrection answer = corrector.correct(nav, *worker.snapshot());
    if (nav.position_valid) worker.addNavAccuracy({nav.utime_us, nav.position_std_north_m, nav.position_std_east_m});
    if (answer.verdict == sss::optimiser::NavVerdict::kBadSample) {
      if (health.recordError("bad_nav", "nav sample with non-finite pose or no time", sss::core::nowUtime()))
        spdlog::warn("nav sample rejected (non-finite pose or no time); further ones are counted in SSS_STATUS");
      return;
    }
    if (answer.verdict == sss::optimiser::NavVerdict::kNoPosition) {
      // Before the INS's first fix: no position, no frame, nothing to correct yet.
      if (health.recordError("nav_without_position", "nav sample without a position or origin", sss::core::nowUtime()))
        spdlog::warn("nav sample without a position (before the INS's first fix?) not corrected; further ones are "
                     "counted in SSS_STATUS");
      return;
    }
    if (answer.origin_changed) {
      logOriginChange(answer.previous_origin, *nav.origin, options.configured_origin);
      worker.setOrigin(*nav.origin);
    }
    if (answer.jump_m) {
      spdlog::info("the correction of the present pose jumped {:.2f} m (a fix or closures accepted); the published "
                   "pose follows at {:.2f} m/s, its covariance widened by what is left", *answer.jump_m, options.slew.max_rate_m_s);
    }
    const sss_msgs::pose_t pose = sss::optimiser::toPoseMessage(nav.utime_us, answer.dr, answer.correction, *corrector.plane());
    loop.bus().publish(options.pose_channel, pose, arrival);
    if (dds_writer) {
      const sss_dds_NavigationCorrection sample =
          sss::optimiser::toDdsCorrection(pose, static_cast<uint32_t>(options.vehicle_id), answer.correction.accepted_closures);
      if (const auto due = dds_pacer.offer(sample, sss::core::monotonicUtime())) writeDds(*due);
    }
  });
  loop.bus().subscribe<sss_msgs::subframe_t>(options.subframe_channel, [&](const sss_msgs::subframe_t& message) {
    sss::core::Subframe subframe;
    std::string error;
    if (!sss::messages::fromSubframeMessage(message, subframe, error)) {
      if (health.recordError("bad_subframe", error, sss::core::nowUtime()))
        spdlog::warn("subframe {} rejected: {}; further ones are counted in SSS_STATUS", message.subframe_id, error);
      return;
    }
    // The image travels to the worker, which keeps it for the products at mosaic resolution (off this
    // loop, which answers every nav sample); the graph keeps poses only.
    worker.addSubframe(std::move(subframe));
  });
  loop.bus().subscribe<sss_msgs::loop_closure_t>(options.loop_channel, [&](const sss_msgs::loop_closure_t& message) {
    sss::core::LoopClosure closure;
    std::string error;
    if (!sss::messages::fromLoopClosureMessage(message, closure, error)) {
      if (health.recordError("bad_loop_closure", error, sss::core::nowUtime()))
        spdlog::warn("loop closure rejected: {}; further ones are counted in SSS_STATUS", error);
      return;
    }
    worker.addLoopClosure(std::move(closure));
  });

  // Absolute fixes placed in the mission frame by the INS bridge: used only in the navigation's frame.
  loop.bus().subscribe<sss_msgs::fix_t>(options.fix_channel, [&](const sss_msgs::fix_t& message) {
    std::string error;
    std::optional<sss::optimiser::AbsoluteFix> fix = sss::optimiser::fromFixMessage(message, error);
    const sss::core::MissionOrigin origin = sss::optimiser::fixMessageOrigin(message);
    const std::optional<sss::core::MissionOrigin> nav_origin = worker.origin();
    if (fix && nav_origin && (std::abs(origin.latitude_deg - nav_origin->latitude_deg) > 1e-9 ||
                              std::abs(origin.longitude_deg - nav_origin->longitude_deg) > 1e-9)) {
      error = "the fix's mission origin differs from the navigation's (another INS bridge?)";
      fix.reset();
    }
    if (!fix) {
      if (health.recordError("bad_fix", error, sss::core::nowUtime()))
        spdlog::warn("fix rejected: {}; further ones are counted in SSS_STATUS", error);
      return;
    }
    worker.addFix(*fix);
  });

  loop.addFileDescriptor(results_fd, [&] {
    uint64_t count = 0;
    if (read(results_fd, &count, sizeof count) < 0) return;
    sss::optimiser::OptimiserWorkerResults results = worker.takeResults();
    for (const auto& m : results.messages) spdlog::info("{}", m);
    if (results.trajectory && !results.trajectory->empty()) {
      loop.bus().publish(options.trajectory_channel, sss::messages::toTrajectoryMessage(*results.trajectory, sss::core::nowUtime()));
    }
    sss::optimiser::setStatusCounters(results.status, health);
  });

  if (dds_writer) {
    loop.addTimer(0.25 / options.dds_rate_hz, [&] {
      if (const auto due = dds_pacer.poll(sss::core::monotonicUtime())) writeDds(*due);
    });
  }
  std::signal(SIGUSR1, onSigusr1);
  loop.addTimer(0.5, [&] {
    if (!g_products_requested.exchange(false)) return;
    spdlog::info("products requested (SIGUSR1): full smoothing");
    worker.requestProducts();
  });

  worker.start();
  const int exit_code = loop.run();
  // End of mission: whatever arrived last, full smoothing, products and a final checkpoint.
  for (const auto& m : worker.finish()) spdlog::info("{}", m);
  close(results_fd);
  return exit_code;
}
