// sss-optimiser: SSS_SUBFRAME + SSS_LOOP (+ SSS_FIX: absolute fixes) -> pose graph -> SSS_TRAJECTORY (matcher); SSS_NAV ->
// SSS_POSE for every nav sample and the correction on DDS for the navigation computer.
// Wiring only: OptimiserService (optimiser_service.hpp) decodes the inputs, answers each nav sample
// from the newest solved graph and has the graph solved by OptimiserWorker on its own thread, so a
// solve never delays a pose; the DDS correction is paced by LatestSamplePacer. The engine (graph,
// ping poses, correspondences) is checkpointed after every update into the state directory and
// restored at start. On SIGTERM (end of mission) or SIGUSR1 (on request) it runs full smoothing and
// writes the products: optimised trajectory (TUM), corrected navigation (navigation.csv, .nmea), tie report
// (loop_closures.csv), tracks and footprints (GeoJSON), coverage, mosaics, bathymetry (PLY) and heightmap,
// the rasters also as GeoTIFF in the origin's UTM zone.
//   sss-optimiser [--config FILE [--check-config]] [--lcm-url URL]
#include <atomic>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/state_file.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/optimiser/optimiser_service.hpp"
#include "pipeline/optimiser/pose_message.hpp"
#include "pipeline/transport/dds.hpp"
#include "pipeline/transport/latest_sample_pacer.hpp"
#include "pipeline/transport/logging.hpp"
#include "pipeline/transport/process_loop.hpp"
#include "pipeline/transport/process_options.hpp"

namespace {

struct NodeOptions {
  sss::transport::ProcessOptions process;
  // The engine, the slew of the published correction, the update period, the state and products
  // directories (empty state directory: $STATE_DIRECTORY, systemd StateDirectory=, else none; empty
  // products directory: <state directory>/products).
  sss::optimiser::OptimiserServiceOptions service;
  std::string subframe_channel = "SSS_SUBFRAME";
  std::string loop_channel = "SSS_LOOP";
  std::string fix_channel = "SSS_FIX";
  std::string nav_channel = "SSS_NAV";
  std::string pose_channel = "SSS_POSE";
  std::string trajectory_channel = "SSS_TRAJECTORY";
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
  options.service.configured_origin = sss::core::readMissionOrigin(mission);
  ConfigSection section = config.section("optimiser");
  sss::transport::readProcessOptions(section, options.process);
  sss::optimiser::readOptimiserEngineOptions(section, options.service.engine);
  sss::optimiser::readCorrectionSlewOptions(section, options.service.slew);
  section.optional("subframe_channel", options.subframe_channel, {nonEmpty()});
  section.optional("loop_channel", options.loop_channel, {nonEmpty()});
  section.optional("fix_channel", options.fix_channel, {nonEmpty()});
  section.optional("nav_channel", options.nav_channel, {nonEmpty()});
  section.optional("pose_channel", options.pose_channel, {nonEmpty()});
  section.optional("trajectory_channel", options.trajectory_channel, {nonEmpty()});
  section.optional("update_period_s", options.service.update_period_s, {inRange(0.0, 3600.0)});
  section.optional("state_directory", options.service.state_directory);
  section.optional("products_directory", options.service.products_directory);
  section.optional("products_mosaic_max_mib", options.service.products_mosaic_max_mib, {inRange(0.0, 65536.0)});
  ConfigSection dds = section.section("dds");
  dds.optional("enabled", options.dds_enabled);
  dds.optional("domain_id", options.dds_domain_id, {inRange(0, 232)});
  dds.optional("topic", options.dds_topic, {nonEmpty()});
  dds.optional("rate_hz", options.dds_rate_hz, {inRange(0.01, 1000.0)});
  dds.optional("vehicle_id", options.vehicle_id, {inRange(0, 1000000)});
  dds.optional("loopback_only", options.dds_loopback_only);
  dds.rejectUnknownKeys();
  section.rejectUnknownKeys();
  for (const std::string& problem : sss::optimiser::validateOptimiserEngineOptions(options.service.engine)) {
    section.addProblem("optimiser", "", problem);
  }
  for (const std::string& problem : sss::optimiser::validateCorrectionSlewOptions(options.service.slew)) {
    section.addProblem("optimiser", "", problem);
  }
  return config.problemReport();
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

}  // namespace

int main(int argc, char** argv) {
  sss::transport::NodeArguments arguments;
  const int usage_exit_code = sss::transport::parseNodeArguments(
      "sss-optimiser", "sliding-window pose graph: SSS_SUBFRAME + SSS_LOOP + SSS_NAV (+ SSS_FIX) -> SSS_POSE, SSS_TRAJECTORY, DDS",
      argc, argv, arguments);
  if (usage_exit_code >= 0) return usage_exit_code;
  NodeOptions options;
  const std::string config_problems = readNodeOptions(arguments.config_path, options);
  if (const int code = sss::transport::finishConfiguration(config_problems, arguments, options.process); code >= 0) {
    return code;
  }
  options.service.state_directory = sss::core::resolveSystemdDirectory(options.service.state_directory, std::getenv("STATE_DIRECTORY"));
  if (options.service.products_directory.empty() && !options.service.state_directory.empty()) {
    options.service.products_directory = options.service.state_directory + "/products";
  }

  sss::transport::ProcessLoop loop(options.process);
  sss::core::HealthMonitor& health = loop.health();
  // The worker wakes the loop when it has results: the trajectory for the matcher, the status.
  std::function<void()> on_results;  // set once the service exists
  const std::function<void()> results_ready = loop.addWakeup([&] { on_results(); });
  if (!results_ready) {
    spdlog::error("cannot create an eventfd for the optimiser thread");
    return 1;
  }
  sss::core::ServiceLog log;
  sss::optimiser::OptimiserService service(options.service, results_ready, log);
  sss::transport::writeServiceLog(log);

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

  loop.addTimer(1.0, [&] { service.reportSlew(health); });
  // ---- subscriptions ------------------------------------------------------------------------------
  loop.bus().subscribe<sss_msgs::nav_t>(options.nav_channel, [&](const sss_msgs::nav_t& message) {
    const int64_t arrival = sss::core::monotonicUtime();
    const std::optional<sss::optimiser::CorrectedPose> answer = service.addNav(message, health, log);
    sss::transport::writeServiceLog(log);
    if (!answer) return;
    loop.bus().publish(options.pose_channel, answer->pose, arrival);
    if (dds_writer) {
      const sss_dds_NavigationCorrection sample = sss::optimiser::toDdsCorrection(
          answer->pose, static_cast<uint32_t>(options.vehicle_id), answer->accepted_closures);
      if (const auto due = dds_pacer.offer(sample, sss::core::monotonicUtime())) writeDds(*due);
    }
  });
  loop.bus().subscribe<sss_msgs::subframe_t>(options.subframe_channel, [&](const sss_msgs::subframe_t& message) {
    service.addSubframe(message, health, log);
    sss::transport::writeServiceLog(log);
  });
  loop.bus().subscribe<sss_msgs::loop_closure_t>(options.loop_channel, [&](const sss_msgs::loop_closure_t& message) {
    service.addLoopClosure(message, health, log);
    sss::transport::writeServiceLog(log);
  });
  loop.bus().subscribe<sss_msgs::fix_t>(options.fix_channel, [&](const sss_msgs::fix_t& message) {
    service.addFix(message, health, log);
    sss::transport::writeServiceLog(log);
  });
  on_results = [&] {
    const std::optional<sss_msgs::trajectory_t> trajectory = service.takeResults(health, sss::core::nowUtime(), log);
    sss::transport::writeServiceLog(log);
    if (trajectory) loop.bus().publish(options.trajectory_channel, *trajectory);
  };

  if (dds_writer) {
    loop.addTimer(0.25 / options.dds_rate_hz, [&] {
      if (const auto due = dds_pacer.poll(sss::core::monotonicUtime())) writeDds(*due);
    });
  }
  std::signal(SIGUSR1, onSigusr1);
  loop.addTimer(0.5, [&] {
    if (!g_products_requested.exchange(false)) return;
    service.requestProducts(log);
    sss::transport::writeServiceLog(log);
  });

  service.start();
  const int exit_code = loop.run();
  // End of mission: whatever arrived last, full smoothing, products and a final checkpoint.
  service.finish(log);
  sss::transport::writeServiceLog(log);
  return exit_code;
}
