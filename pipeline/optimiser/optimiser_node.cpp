// sss-optimiser: SSS_SUBFRAME + SSS_LOOP (+ SSS_FIX: absolute fixes) -> pose graph -> SSS_TRAJECTORY (matcher); SSS_NAV ->
// SSS_POSE for every nav sample and the correction on DDS for the navigation computer.
// Translation only; the logic is in OptimiserEngine. The graph is solved on a worker thread; the
// process loop answers each nav sample from a snapshot of the newest solved graph, so a solve never
// delays a pose. The engine (graph, ping poses, correspondences) is checkpointed after every update
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
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/core/geodesy.hpp"
#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/state_file.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/messages/closure_messages.hpp"
#include "pipeline/optimiser/optimiser_engine.hpp"
#include "pipeline/optimiser/correction_slew.hpp"
#include "pipeline/optimiser/fix_message.hpp"
#include "products/footprints.hpp"
#include "products/live_products.hpp"
#include "products/mosaic_products.hpp"
#include "pipeline/optimiser/pose_message.hpp"
#include "pipeline/messages/subframe_messages.hpp"
#include "pipeline/messages/sensor_messages.hpp"
#include "pipeline/transport/dds.hpp"
#include "pipeline/transport/logging.hpp"
#include "pipeline/transport/process_loop.hpp"
#include "pipeline/transport/process_options.hpp"

namespace {

namespace fs = std::filesystem;
using sss::optimiser::OptimiserEngine;
using sss::optimiser::SlidingWindowPoseGraph;

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

// Inputs for the worker, and what it hands back to the process loop.
struct Shared {
  std::mutex mutex;
  std::condition_variable wake;
  std::deque<sss::core::Subframe> subframes;
  std::deque<sss::core::LoopClosure> closures;
  std::deque<sss::optimiser::AbsoluteFix> fixes;  // SSS_FIX, in the navigation's frame
  bool products_requested = false;
  bool stop = false;
  std::optional<sss::core::MissionOrigin> origin;  // of the navigation (SSS_NAV), for the products
  // Results.
  std::shared_ptr<const SlidingWindowPoseGraph> snapshot;  // newest solved graph (for corrections)
  std::optional<std::vector<sss::core::TrajectoryNode>> trajectory;  // to publish
  sss::optimiser::PoseGraphCounters graph_counters;
  sss::optimiser::OptimiserEngineCounters engine_counters;
  sss::optimiser::FixCounters fix_counters;
  sss::optimiser::DrCalibration calibration;
  double last_update_s = 0.0;
  double last_checkpoint_s = 0.0;
  size_t memory_bytes = 0;
  std::vector<std::string> messages;  // log lines from the worker (logged by the loop)
};

}  // namespace

int main(int argc, char** argv) {
  sss::transport::NodeArguments arguments;
  if (const int exit_code = sss::transport::parseNodeArguments(argc, argv, arguments); exit_code >= 0) return exit_code;
  const std::string& config_path = arguments.config_path;
  NodeOptions options;
  options.process.process_name = "sss-optimiser";
  std::string config_problems;  // empty: valid (or no file: the defaults)
  if (!config_path.empty()) {
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
    config_problems = config.problemReport();
  }
  if (const int code = sss::transport::configVerdict("sss-optimiser", config_problems, config_path, arguments.check_config_only); code >= 0) {
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
  // The tangent plane of the origin in the navigation (rebuilt if the INS bridge's origin changes).
  std::optional<sss::core::LocalTangentPlane> plane;
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
  const std::string checkpoint_path =
      options.state_directory.empty() ? std::string() : options.state_directory + "/optimiser.checkpoint";
  if (!checkpoint_path.empty()) {
    std::error_code ec;
    fs::create_directories(options.state_directory, ec);
    if (fs::exists(checkpoint_path)) {
      const sss::optimiser::Status loaded = engine.loadCheckpoint(checkpoint_path);
      if (loaded.ok) {
        spdlog::info("resumed from {}: {} nodes, {} closures accepted, ping poses of {} subframes, {} odometer resets",
                     checkpoint_path, engine.graph().numNodes(), engine.graph().counters().closures_accepted,
                     engine.storedSubframes(), engine.counters().odometer_resets);
      } else {
        spdlog::error("checkpoint {} refused ({}); starting empty", checkpoint_path, loaded.message);
      }
    }
  } else {
    spdlog::warn("no state directory (config optimiser.state_directory or $STATE_DIRECTORY): no checkpoints, "
                 "a restart loses the graph");
  }

  Shared shared;
  shared.snapshot = std::make_shared<const SlidingWindowPoseGraph>(engine.graph());
  const int results_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (results_fd < 0) {
    spdlog::error("cannot create an eventfd for the optimiser thread");
    return 1;
  }
  auto notifyLoop = [&] {
    const uint64_t one = 1;
    if (write(results_fd, &one, sizeof one) < 0) {
      // Saturated counter: the loop is already due to read.
    }
  };

  std::thread worker([&] {
    double last_update_monotonic_s = -1e9;
    for (;;) {
      std::deque<sss::core::Subframe> subframes;
      std::deque<sss::core::LoopClosure> closures;
      std::deque<sss::optimiser::AbsoluteFix> fixes;
      bool products = false;
      std::optional<sss::core::MissionOrigin> origin;
      {
        std::unique_lock<std::mutex> lock(shared.mutex);
        shared.wake.wait_for(lock, std::chrono::duration<double>(std::max(options.update_period_s, 0.05)), [&] {
          return shared.stop || !shared.subframes.empty() || !shared.closures.empty() || !shared.fixes.empty() ||
                 shared.products_requested;
        });
        if (shared.stop) return;
        subframes.swap(shared.subframes);
        closures.swap(shared.closures);
        fixes.swap(shared.fixes);
        products = shared.products_requested;
        shared.products_requested = false;
        origin = shared.origin;
      }
      std::vector<std::string> messages;
      for (const auto& subframe : subframes) {
        const auto status = engine.addSubframe(subframe);
        if (!status.ok) messages.push_back("subframe " + std::to_string(subframe.id) + " refused: " + status.message);
        else if (!status.message.empty()) messages.push_back(status.message);  // an odometer reset
        if (status.ok) keepForProducts(subframe);
      }
      for (const auto& closure : closures) {
        const auto status = engine.addLoopClosure(closure);
        if (!status.ok) {
          messages.push_back("closure " + std::to_string(closure.subframe_id_a) + "-" +
                             std::to_string(closure.subframe_id_b) + " refused: " + status.message);
        }
      }
      for (const auto& fix : fixes) {
        const auto status = engine.addFix(fix);
        if (!status.ok) messages.push_back("fix refused: " + status.message);
      }
      const double now_s = 1e-6 * static_cast<double>(sss::core::monotonicUtime());
      bool updated = false;
      if (products) {
        engine.finish();
        if (!options.products_directory.empty()) sss::products::writeLiveProducts(engine, mosaics, footprints, options.products_directory, origin, messages);
        updated = true;
      } else if (engine.hasNewInput() && now_s - last_update_monotonic_s >= options.update_period_s) {
        const auto report = engine.update();
        if (!report.ok) messages.push_back("update failed: " + report.message);
        last_update_monotonic_s = now_s;
        updated = true;
      }
      double checkpoint_s = -1.0;
      if (updated && !checkpoint_path.empty()) {
        const int64_t begin_us = sss::core::monotonicUtime();
        const auto saved = engine.saveCheckpoint(checkpoint_path);
        checkpoint_s = 1e-6 * static_cast<double>(sss::core::monotonicUtime() - begin_us);
        if (!saved.ok) messages.push_back("checkpoint: " + saved.message);
      }
      if (!updated && messages.empty()) continue;
      auto snapshot = updated ? std::make_shared<const SlidingWindowPoseGraph>(engine.graph()) : nullptr;
      {
        std::lock_guard<std::mutex> lock(shared.mutex);
        if (snapshot) {
          shared.snapshot = std::move(snapshot);
          shared.trajectory = engine.trajectory();
        }
        shared.graph_counters = engine.graph().counters();
        shared.engine_counters = engine.counters();
        shared.fix_counters = engine.graph().fixCounters();
        shared.calibration = engine.graph().calibration();
        shared.last_update_s = engine.graph().counters().last_update_s;
        if (checkpoint_s >= 0.0) shared.last_checkpoint_s = checkpoint_s;
        shared.memory_bytes = engine.memoryBytes();
        for (auto& m : messages) shared.messages.push_back(std::move(m));
      }
      notifyLoop();
    }
  });

  auto snapshot = [&] {
    std::lock_guard<std::mutex> lock(shared.mutex);
    return shared.snapshot;
  };

  // ---- DDS: the newest correction, reliable, keep-last 1, transient-local ----------------------
  std::unique_ptr<sss::transport::dds::Participant> participant;
  std::unique_ptr<sss::transport::dds::Topic<sss_dds_NavigationCorrection>> topic;
  std::unique_ptr<sss::transport::dds::Writer<sss_dds_NavigationCorrection>> writer;
  if (options.dds_enabled) {
    participant = std::make_unique<sss::transport::dds::Participant>(
        static_cast<uint32_t>(options.dds_domain_id),
        options.dds_loopback_only ? sss::transport::dds::loopbackConfigXml() : std::string());
    if (participant->good()) {
      topic = std::make_unique<sss::transport::dds::Topic<sss_dds_NavigationCorrection>>(
          *participant, &sss_dds_NavigationCorrection_desc, options.dds_topic);
      if (topic->good()) writer = std::make_unique<sss::transport::dds::Writer<sss_dds_NavigationCorrection>>(*participant, *topic);
    }
    if (!writer || !writer->good()) {
      spdlog::error("DDS writer for topic '{}' on domain {} could not be created ({}); corrections go on LCM only",
                    options.dds_topic, options.dds_domain_id,
                    participant && !participant->good() ? participant->error() : "topic or writer");
      writer.reset();
      health.recordError("dds", "DDS writer unavailable", sss::core::nowUtime());
    }
  }
  // Written from the nav callback, so the navigation computer gets a correction as soon as its
  // nav sample is answered (not up to a timer period later), at most dds.rate_hz. A sample held
  // back by the rate goes out from the timer only when the nav has gone quiet for half a period
  // (otherwise the next nav sample, a few ms later, is written fresh instead).
  std::optional<sss_dds_NavigationCorrection> pending_dds;
  uint64_t dds_written = 0;
  const auto dds_period_us = static_cast<int64_t>(1e6 / options.dds_rate_hz);
  int64_t last_dds_write_us = std::numeric_limits<int64_t>::min() / 2;
  int64_t last_nav_us = 0;
  auto writeDds = [&](const sss_dds_NavigationCorrection& sample, int64_t now_us) {
    last_dds_write_us = now_us;
    pending_dds.reset();
    if (writer->write(sample)) {
      ++dds_written;
      health.setCounter("dds_corrections", static_cast<double>(dds_written));
    } else if (health.recordError("dds_write", "DDS write failed", sss::core::nowUtime())) {
      spdlog::warn("DDS write failed; further failures are counted in SSS_STATUS");
    }
  };

  sss::optimiser::CorrectionSlew slew(options.slew);
  // Off the nav path (200 Hz, latency-bound): the slew's figures go to SSS_STATUS once a second.
  loop.addTimer(1.0, [&] {
    health.setCounter("correction_lag_m", slew.lagM());
    health.setCounter("correction_last_jump_m", slew.lastJumpM());
    health.setCounter("correction_jumps", static_cast<double>(slew.jumps()));
  });
  // ---- subscriptions ------------------------------------------------------------------------------
  loop.bus().subscribe<sss_msgs::nav_t>(options.nav_channel, [&](const sss_msgs::nav_t& message) {
    const int64_t arrival = sss::core::monotonicUtime();
    const sss::core::NavSample nav = sss::messages::fromNavMessage(message);
    if (!nav.position_ned_m.allFinite() || !std::isfinite(nav.heading_rad) || !std::isfinite(nav.roll_rad) ||
        !std::isfinite(nav.pitch_rad) || nav.utime_us <= 0) {
      if (health.recordError("bad_nav", "nav sample with non-finite pose or no time", sss::core::nowUtime()))
        spdlog::warn("nav sample rejected (non-finite pose or no time); further ones are counted in SSS_STATUS");
      return;
    }
    if (!nav.position_valid || !nav.origin) {
      // Before the INS's first fix: no position, no frame, nothing to correct yet.
      if (health.recordError("nav_without_position", "nav sample without a position or origin", sss::core::nowUtime()))
        spdlog::warn("nav sample without a position (before the INS's first fix?) not corrected; further ones are "
                     "counted in SSS_STATUS");
      return;
    }
    if (!plane || plane->originLatitudeDeg() != nav.origin->latitude_deg ||
        plane->originLongitudeDeg() != nav.origin->longitude_deg) {
      if (plane) {
        spdlog::error("the navigation's origin moved from {:.7f} {:.7f} to {:.7f} {:.7f} (INS bridge restarted "
                      "without its state directory?): corrected poses are geo-referenced with the new one",
                      plane->originLatitudeDeg(), plane->originLongitudeDeg(), nav.origin->latitude_deg,
                      nav.origin->longitude_deg);
      } else {
        spdlog::info("mission origin (from SSS_NAV): {:.7f} {:.7f}", nav.origin->latitude_deg, nav.origin->longitude_deg);
      }
      if (options.configured_origin && (options.configured_origin->latitude_deg != nav.origin->latitude_deg ||
                                        options.configured_origin->longitude_deg != nav.origin->longitude_deg)) {
        spdlog::warn("the navigation's origin differs from mission.origin_* in the configuration (does the INS "
                     "bridge read the same file?); the navigation's is used");
      }
      plane.emplace(nav.origin->latitude_deg, nav.origin->longitude_deg);
      std::lock_guard<std::mutex> lock(shared.mutex);
      shared.origin = nav.origin;
    }
    const auto graph = snapshot();
    const sss::optimiser::Correction correction = slew.apply(graph->correctionAt(nav.utime_us), nav.utime_us);
    if (const auto jump = slew.takeNewJump()) {
      spdlog::info("the correction of the present pose jumped {:.2f} m (a fix or closures accepted); the published "
                   "pose follows at {:.2f} m/s, its covariance widened by what is left", *jump, options.slew.max_rate_m_s);
    }
    const auto dr = sss::core::poseOf(nav);
    const sss_msgs::pose_t pose = sss::optimiser::toPoseMessage(nav.utime_us, dr, correction, *plane);
    loop.bus().publish(options.pose_channel, pose, arrival);
    if (writer) {
      const sss_dds_NavigationCorrection sample =
          sss::optimiser::toDdsCorrection(pose, static_cast<uint32_t>(options.vehicle_id), correction.accepted_closures);
      const int64_t now_us = sss::core::monotonicUtime();
      last_nav_us = now_us;
      if (now_us - last_dds_write_us >= dds_period_us) {
        writeDds(sample, now_us);
      } else {
        pending_dds = sample;
      }
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
    std::lock_guard<std::mutex> lock(shared.mutex);
    shared.subframes.push_back(std::move(subframe));
    shared.wake.notify_one();
  });
  loop.bus().subscribe<sss_msgs::loop_closure_t>(options.loop_channel, [&](const sss_msgs::loop_closure_t& message) {
    sss::core::LoopClosure closure;
    std::string error;
    if (!sss::messages::fromLoopClosureMessage(message, closure, error)) {
      if (health.recordError("bad_loop_closure", error, sss::core::nowUtime()))
        spdlog::warn("loop closure rejected: {}; further ones are counted in SSS_STATUS", error);
      return;
    }
    std::lock_guard<std::mutex> lock(shared.mutex);
    shared.closures.push_back(std::move(closure));
    shared.wake.notify_one();
  });

  // Absolute fixes placed in the mission frame by the INS bridge: used only in the navigation's frame.
  loop.bus().subscribe<sss_msgs::fix_t>(options.fix_channel, [&](const sss_msgs::fix_t& message) {
    std::string error;
    std::optional<sss::optimiser::AbsoluteFix> fix = sss::optimiser::fromFixMessage(message, error);
    std::lock_guard<std::mutex> lock(shared.mutex);
    const sss::core::MissionOrigin origin = sss::optimiser::fixMessageOrigin(message);
    if (fix && shared.origin && (std::abs(origin.latitude_deg - shared.origin->latitude_deg) > 1e-9 ||
                                 std::abs(origin.longitude_deg - shared.origin->longitude_deg) > 1e-9)) {
      error = "the fix's mission origin differs from the navigation's (another INS bridge?)";
      fix.reset();
    }
    if (!fix) {
      if (health.recordError("bad_fix", error, sss::core::nowUtime()))
        spdlog::warn("fix rejected: {}; further ones are counted in SSS_STATUS", error);
      return;
    }
    shared.fixes.push_back(*fix);
    shared.wake.notify_one();
  });

  loop.addFileDescriptor(results_fd, [&] {
    uint64_t count = 0;
    if (read(results_fd, &count, sizeof count) < 0) return;
    std::optional<std::vector<sss::core::TrajectoryNode>> trajectory;
    std::vector<std::string> messages;
    sss::optimiser::PoseGraphCounters graph_counters;
    sss::optimiser::OptimiserEngineCounters engine_counters;
    sss::optimiser::FixCounters fix_counters;
    sss::optimiser::DrCalibration calibration;
    size_t memory_bytes = 0;
    double last_checkpoint_s = 0.0;
    {
      std::lock_guard<std::mutex> lock(shared.mutex);
      trajectory.swap(shared.trajectory);
      messages.swap(shared.messages);
      graph_counters = shared.graph_counters;
      engine_counters = shared.engine_counters;
      fix_counters = shared.fix_counters;
      calibration = shared.calibration;
      memory_bytes = shared.memory_bytes;
      last_checkpoint_s = shared.last_checkpoint_s;
    }
    for (const auto& m : messages) spdlog::info("{}", m);
    if (trajectory && !trajectory->empty()) {
      loop.bus().publish(options.trajectory_channel, sss::messages::toTrajectoryMessage(*trajectory, sss::core::nowUtime()));
    }
    health.setCounter("nodes", static_cast<double>(graph_counters.nodes_added));
    health.setCounter("nodes_marginalised", static_cast<double>(graph_counters.nodes_marginalised));
    health.setCounter("closures_received", static_cast<double>(graph_counters.closures_received));
    health.setCounter("closures_accepted", static_cast<double>(graph_counters.closures_accepted));
    health.setCounter("closures_rejected",
                      static_cast<double>(graph_counters.closures_rejected_gate +
                                          graph_counters.closures_rejected_inconsistent +
                                          graph_counters.closures_rejected_no_support));
    health.setCounter("closures_refused", static_cast<double>(engine_counters.closures_refused));
    health.setCounter("closures_waiting", static_cast<double>(engine_counters.closures_waiting));
    health.setCounter("subframes_refused", static_cast<double>(engine_counters.subframes_refused));
    health.setCounter("odometer_resets", static_cast<double>(engine_counters.odometer_resets));
    health.setCounter("fixes_received", static_cast<double>(fix_counters.received));
    health.setCounter("fixes_accepted", static_cast<double>(fix_counters.accepted));
    health.setCounter("fixes_rejected", static_cast<double>(fix_counters.rejected_gate + fix_counters.refused));
    health.setCounter("updates", static_cast<double>(graph_counters.updates));
    // The DR calibration in use (re-estimated every calibration_period_s of mission time): 0 and
    // NaN sigmas before the first estimate; the scale's sigma NaN while no fix observes it.
    health.setCounter("full_smoothings", static_cast<double>(graph_counters.full_smoothings));
    health.setCounter("calibration_estimated", calibration.estimated ? 1.0 : 0.0);
    health.setCounter("calibration_dvl_scale", calibration.dvl_scale);
    health.setCounter("calibration_dvl_scale_sigma", calibration.sigma(0));
    health.setCounter("calibration_heading_bias_rad", calibration.heading_bias_rad);
    health.setCounter("calibration_heading_cos_rad", calibration.heading_cos_rad);
    health.setCounter("calibration_heading_cos_sigma_rad", calibration.sigma(2));
    health.setCounter("calibration_heading_sin_rad", calibration.heading_sin_rad);
    health.setCounter("solver_failures", static_cast<double>(graph_counters.solver_failures));
    health.setCounter("last_update_ms", 1e3 * graph_counters.last_update_s);
    health.setCounter("memory_mb", static_cast<double>(memory_bytes) / 1e6);
    health.setCounter("last_checkpoint_ms", 1e3 * last_checkpoint_s);
  });

  if (writer) {
    loop.addTimer(0.25 / options.dds_rate_hz, [&] {
      const int64_t now_us = sss::core::monotonicUtime();
      if (pending_dds && now_us - last_dds_write_us >= dds_period_us && now_us - last_nav_us >= dds_period_us / 2) {
        writeDds(*pending_dds, now_us);
      }
    });
  }
  std::signal(SIGUSR1, onSigusr1);
  loop.addTimer(0.5, [&] {
    if (!g_products_requested.exchange(false)) return;
    spdlog::info("products requested (SIGUSR1): full smoothing");
    std::lock_guard<std::mutex> lock(shared.mutex);
    shared.products_requested = true;
    shared.wake.notify_one();
  });

  // A restored graph: its trajectory and counters go out at once (the matcher re-associates with
  // them), not only after the next update.
  if (engine.graph().numNodes() > 0) {
    std::lock_guard<std::mutex> lock(shared.mutex);
    shared.trajectory = engine.trajectory();
    shared.graph_counters = engine.graph().counters();
    shared.engine_counters = engine.counters();
    shared.memory_bytes = engine.memoryBytes();
    notifyLoop();
  }
  const int exit_code = loop.run();
  {
    std::lock_guard<std::mutex> lock(shared.mutex);
    shared.stop = true;
    shared.wake.notify_one();
  }
  worker.join();
  close(results_fd);
  // End of mission: whatever arrived last, full smoothing, products and a final checkpoint.
  for (const auto& subframe : shared.subframes) {
    const auto status = engine.addSubframe(subframe);
    if (!status.message.empty()) spdlog::info("subframe {}: {}", subframe.id, status.message);
    if (status.ok) keepForProducts(subframe);
  }
  for (const auto& closure : shared.closures) engine.addLoopClosure(closure);
  for (const auto& fix : shared.fixes) engine.addFix(fix);
  if (engine.graph().numNodes() > 0) {
    engine.finish();
    std::vector<std::string> messages;
    if (!options.products_directory.empty()) sss::products::writeLiveProducts(engine, mosaics, footprints, options.products_directory, shared.origin, messages);
    if (!checkpoint_path.empty()) {
      const auto saved = engine.saveCheckpoint(checkpoint_path);
      if (!saved.ok) messages.push_back("checkpoint: " + saved.message);
    }
    for (const auto& m : messages) spdlog::info("{}", m);
  }
  return exit_code;
}
