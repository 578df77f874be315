// sss-matcher: SSS_SUBFRAME + SSS_TRAJECTORY -> SSS_LOOP. Wiring only; the logic is in
// MatcherService (matcher_service.hpp): MatcherEngine run by MatcherWorker on its own thread
// (matching a pair takes about a second, and the process loop stays free for LCM, SSS_STATUS and
// the watchdog). The stored subframes and the pair bookkeeping are kept in the state directory;
// the worker restores them first at start.
//   sss-matcher [--config FILE [--check-config]] [--lcm-url URL]
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "pipeline/core/state_file.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/matcher/matcher_service.hpp"
#include "pipeline/transport/logging.hpp"
#include "pipeline/transport/process_loop.hpp"
#include "pipeline/transport/process_options.hpp"

namespace {

struct NodeOptions {
  sss::transport::ProcessOptions process;
  // The engine, the worker's queue bound and the state directory (empty: $STATE_DIRECTORY, systemd
  // StateDirectory=, else none: a restart then loses the stored subframes).
  sss::matcher::MatcherServiceOptions service;
  std::string subframe_channel = "SSS_SUBFRAME";
  std::string trajectory_channel = "SSS_TRAJECTORY";
  std::string loop_channel = "SSS_LOOP";
};

}  // namespace

int main(int argc, char** argv) {
  sss::transport::NodeArguments arguments;
  const int usage_exit_code = sss::transport::parseNodeArguments(
      "sss-matcher", "dense side-scan matching of overlapping subframes: SSS_SUBFRAME + SSS_TRAJECTORY -> SSS_LOOP",
      argc, argv, arguments);
  if (usage_exit_code >= 0) return usage_exit_code;
  const std::string& config_path = arguments.config_path;
  NodeOptions options;
  options.process.process_name = "sss-matcher";
  std::string config_problems;  // empty: valid (or no file: the defaults)
  if (!config_path.empty()) {
    using namespace sss::core;
    Config config = Config::fromFile(config_path);
    ConfigSection section = config.section("matcher");
    sss::transport::readProcessOptions(section, options.process);
    sss::matcher::readMatcherEngineOptions(section, options.service.engine);
    section.optional("subframe_channel", options.subframe_channel, {nonEmpty()});
    section.optional("trajectory_channel", options.trajectory_channel, {nonEmpty()});
    section.optional("loop_channel", options.loop_channel, {nonEmpty()});
    section.optional("max_queued_subframes", options.service.max_queued_subframes, {inRange(1, 10000)});
    section.optional("state_directory", options.service.state_directory,
                     {satisfies<std::string>([](const std::string& v) { return v.empty() || v.front() == '/'; },
                                             "\"\" or an absolute path")});
    section.rejectUnknownKeys();
    for (const std::string& problem : sss::matcher::validateMatcherEngineOptions(options.service.engine)) {
      section.addProblem("matcher", "", problem);
    }
    config_problems = config.problemReport();
  }
  if (const int code = sss::transport::finishConfiguration(config_problems, arguments, options.process); code >= 0) {
    return code;
  }
  options.service.state_directory = sss::core::resolveSystemdDirectory(options.service.state_directory, std::getenv("STATE_DIRECTORY"));

  sss::transport::ProcessLoop loop(options.process);
  sss::core::HealthMonitor& health = loop.health();
  // The worker wakes the loop when it has outcomes (or something to say).
  std::function<void()> on_results;  // set once the service exists
  const std::function<void()> results_ready = loop.addWakeup([&] { on_results(); });
  if (!results_ready) {
    spdlog::error("cannot create an eventfd for the matcher thread");
    return 1;
  }
  sss::core::ServiceLog log;
  sss::matcher::MatcherService service(options.service, results_ready, log);
  sss::transport::writeServiceLog(log);
  on_results = [&] {
    const std::vector<sss::matcher::ClosureToPublish> closures = service.takeResults(sss::core::nowUtime(), health, log);
    sss::transport::writeServiceLog(log);
    for (const sss::matcher::ClosureToPublish& closure : closures) {
      loop.bus().publish(options.loop_channel, closure.message, closure.arrival_monotonic_us);
    }
  };
  service.start();

  loop.bus().subscribe<sss_msgs::subframe_t>(options.subframe_channel, [&](const sss_msgs::subframe_t& message) {
    service.addSubframe(message, sss::core::monotonicUtime(), health, log);
    sss::transport::writeServiceLog(log);
  });
  loop.bus().subscribe<sss_msgs::trajectory_t>(options.trajectory_channel, [&](const sss_msgs::trajectory_t& message) {
    service.setTrajectory(message, health, log);
    sss::transport::writeServiceLog(log);
  });
  loop.addTimer(1.0, [&] { service.reportHealth(health, options.subframe_channel); });

  const int code = loop.run();
  service.stop();
  return code;
}
