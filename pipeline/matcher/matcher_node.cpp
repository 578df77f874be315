// sss-matcher: SSS_SUBFRAME + SSS_TRAJECTORY -> SSS_LOOP. Wiring only; the logic is in
// MatcherEngine, run by MatcherWorker (matcher_worker.hpp) on its own thread: matching a pair
// takes about a second, and the process loop stays free for LCM, SSS_STATUS and the watchdog. The stored subframes and
// the pair bookkeeping are kept in the state directory; the worker restores them first at start.
//   sss-matcher [--config FILE [--check-config]] [--lcm-url URL]
#include <sys/eventfd.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/core/state_file.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/messages/closure_messages.hpp"
#include "pipeline/matcher/matcher_engine.hpp"
#include "pipeline/matcher/matcher_worker.hpp"
#include "pipeline/messages/subframe_messages.hpp"
#include "pipeline/transport/logging.hpp"
#include "pipeline/transport/process_loop.hpp"
#include "pipeline/transport/process_options.hpp"

namespace {

struct NodeOptions {
  sss::transport::ProcessOptions process;
  sss::matcher::MatcherEngineOptions engine;
  std::string subframe_channel = "SSS_SUBFRAME";
  std::string trajectory_channel = "SSS_TRAJECTORY";
  std::string loop_channel = "SSS_LOOP";
  // Subframes waiting for the worker; beyond it the oldest waiting one is dropped and counted
  // (at 50 s per subframe and ~1 s per pair the queue stays empty; a long stall must not grow
  // memory without bound).
  int max_queued_subframes = 32;
  // Stored subframes and pair bookkeeping (MatcherStateStore). Empty: $STATE_DIRECTORY (systemd
  // StateDirectory=), else none: a restart then loses them.
  std::string state_directory;
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
    sss::matcher::readMatcherEngineOptions(section, options.engine);
    section.optional("subframe_channel", options.subframe_channel, {nonEmpty()});
    section.optional("trajectory_channel", options.trajectory_channel, {nonEmpty()});
    section.optional("loop_channel", options.loop_channel, {nonEmpty()});
    section.optional("max_queued_subframes", options.max_queued_subframes, {inRange(1, 10000)});
    section.optional("state_directory", options.state_directory,
                     {satisfies<std::string>([](const std::string& v) { return v.empty() || v.front() == '/'; },
                                             "\"\" or an absolute path")});
    section.rejectUnknownKeys();
    for (const std::string& problem : sss::matcher::validateMatcherEngineOptions(options.engine)) {
      section.addProblem("matcher", "", problem);
    }
    config_problems = config.problemReport();
  }
  if (const int code = sss::transport::configVerdict("sss-matcher", config_problems, config_path, arguments.check_config_only); code >= 0) {
    return code;
  }
  if (!arguments.lcm_url_override.empty()) options.process.lcm_url = arguments.lcm_url_override;
  options.state_directory = sss::core::resolveSystemdDirectory(options.state_directory, std::getenv("STATE_DIRECTORY"));

  sss::transport::initLogging(options.process.process_name, options.process.log_level);
  sss::transport::ProcessLoop loop(options.process);
  sss::core::HealthMonitor& health = loop.health();
  sss::matcher::MatcherEngine engine(options.engine);
  std::unique_ptr<sss::matcher::MatcherStateStore> store;
  if (!options.state_directory.empty()) {
    store = std::make_unique<sss::matcher::MatcherStateStore>(options.state_directory);
  } else {
    spdlog::warn("no state directory (config matcher.state_directory or $STATE_DIRECTORY): a restart loses the "
                 "stored subframes");
  }
  const int results_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (results_fd < 0) {
    spdlog::error("cannot create an eventfd for the matcher thread");
    return 1;
  }
  sss::matcher::MatcherWorker::Hooks hooks;
  hooks.results_ready = [results_fd] {
    const uint64_t one = 1;
    if (write(results_fd, &one, sizeof one) < 0) {
      // The counter saturates only after 2^64 - 1 writes; nothing to do.
    }
  };
  hooks.state_error = [&health](const std::string& error) {
    if (health.recordError("state_write", error, sss::core::nowUtime()))
      spdlog::warn("state directory: {}; further failures are counted in SSS_STATUS", error);
  };
  hooks.restored = [](const sss::matcher::RestoreReport& report) {
    for (const std::string& problem : report.problems) spdlog::error("state directory: {}", problem);
    spdlog::info("restored {} subframes and {} matched pairs from {}{}; {} subframe(s) stored but not matched "
                 "before the restart: {} pair(s) matched now",
                 report.subframes, report.pairs, report.directory,
                 report.state_file_found ? "" : " (without matcher.state)", report.subframes_without_state,
                 report.outcomes.size());
  };
  sss::matcher::MatcherWorker worker(engine, store.get(), {options.max_queued_subframes}, hooks);
  worker.start();

  uint64_t rejected_messages = 0;
  bool queue_full_said = false;
  loop.bus().subscribe<sss_msgs::subframe_t>(options.subframe_channel, [&](const sss_msgs::subframe_t& message) {
    sss::core::Subframe subframe;
    std::string error;
    if (!sss::messages::fromSubframeMessage(message, subframe, error)) {
      ++rejected_messages;
      if (health.recordError("bad_subframe", error, sss::core::nowUtime()))
        spdlog::warn("subframe {} rejected: {}; further ones are counted in SSS_STATUS", message.subframe_id, error);
      return;
    }
    if (worker.addSubframe(std::move(subframe), sss::core::monotonicUtime()) && !queue_full_said) {
      queue_full_said = true;
      spdlog::warn("matcher queue full ({} subframes): dropping the oldest; further drops are counted",
                   options.max_queued_subframes);
    }
  });
  loop.bus().subscribe<sss_msgs::trajectory_t>(options.trajectory_channel, [&](const sss_msgs::trajectory_t& message) {
    std::vector<sss::matcher::TrajectoryNode> nodes;
    std::string error;
    if (!sss::messages::fromTrajectoryMessage(message, nodes, error)) {
      ++rejected_messages;
      if (health.recordError("bad_trajectory", error, sss::core::nowUtime()))
        spdlog::warn("trajectory rejected: {}; further ones are counted in SSS_STATUS", error);
      return;
    }
    worker.setTrajectory(std::move(nodes));
  });

  loop.addFileDescriptor(results_fd, [&] {
    uint64_t count = 0;
    if (read(results_fd, &count, sizeof count) < 0) return;
    for (const auto& [outcome, arrival] : worker.takeOutcomes()) {
      if (outcome.accepted) {
        loop.bus().publish(options.loop_channel,
                           sss::messages::toLoopClosureMessage(outcome.closure, sss::core::nowUtime()), arrival);
        spdlog::info("loop closure {}-{} (round {}): {} inliers of {} matches, t = [{:.2f} {:.2f} {:.2f}] m, {:.2f} s",
                     outcome.subframe_id_a, outcome.subframe_id_b, outcome.association_round,
                     outcome.closure.num_inliers, outcome.closure.num_matches, outcome.closure.T_a_b.translation.x(),
                     outcome.closure.T_a_b.translation.y(), outcome.closure.T_a_b.translation.z(), outcome.seconds);
      } else {
        spdlog::info("pair {}-{} (round {}) rejected: {}", outcome.subframe_id_a, outcome.subframe_id_b,
                     outcome.association_round, outcome.reason);
      }
    }
  });

  loop.addTimer(1.0, [&] {
    const sss::matcher::MatcherWorkerStatus status = worker.status();
    const sss::matcher::MatcherEngineCounters& c = status.counters;
    const auto set = [&](const char* name, double value) { health.setCounter(name, value); };
    set("subframes_in", static_cast<double>(c.subframes_in));
    set("subframes_rejected", static_cast<double>(c.subframes_rejected + rejected_messages));
    set("subframes_dropped_queue_full", static_cast<double>(status.dropped_subframes));
    set("subframes_evicted", static_cast<double>(c.subframes_evicted));
    set("subframes_stored", static_cast<double>(status.stored_subframes));
    set("trajectory_updates", static_cast<double>(c.trajectory_updates));
    set("pairs_attempted", static_cast<double>(c.pairs_attempted));
    set("closures_accepted", static_cast<double>(c.closures_accepted));
    set("pairs_rejected", static_cast<double>(c.pairs_rejected));
    set("rematches", static_cast<double>(c.rematches));
    set("subframes_restored", static_cast<double>(c.subframes_restored));
    set("pairs_restored", static_cast<double>(c.pairs_restored));
    set("state_files_corrupt", static_cast<double>(c.state_files_corrupt));
    set("state_write_errors", static_cast<double>(c.state_write_errors));
    set("mean_pair_s", c.pairs_attempted ? c.pair_seconds_total / static_cast<double>(c.pairs_attempted) : 0.0);
    set("memory_bytes", static_cast<double>(status.memory_bytes));
    set("busy", status.busy ? 1.0 : 0.0);
    health.setQueueDepth(options.subframe_channel, false, static_cast<int>(status.queued_subframes));
  });

  const int code = loop.run();
  worker.stop();
  close(results_fd);
  return code;
}
