// sss-matcher: SSS_SUBFRAME + SSS_TRAJECTORY -> SSS_LOOP. Translation only; the logic is in
// MatcherEngine. Matching a pair takes about a second, so it runs on a worker thread and the
// process loop stays free for LCM, SSS_STATUS and the systemd watchdog. The stored subframes and
// the pair bookkeeping are kept in the state directory; the worker restores them first at start.
//   sss-matcher [--config FILE [--check-config]] [--lcm-url URL]
#include <sys/eventfd.h>
#include <unistd.h>

#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/core/state_file.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/messages/closure_messages.hpp"
#include "pipeline/matcher/matcher_engine.hpp"
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

// Work for the matcher thread, in arrival order; only the newest trajectory matters.
struct WorkQueue {
  std::mutex mutex;
  std::condition_variable wake;
  std::deque<std::pair<sss::core::Subframe, int64_t>> subframes;  // with arrival monotonic time
  std::optional<std::vector<sss::matcher::TrajectoryNode>> trajectory;
  bool stop = false;
  uint64_t dropped_subframes = 0;
};

// Results for the process loop to publish.
struct Results {
  std::mutex mutex;
  std::vector<std::pair<sss::matcher::PairOutcome, int64_t>> outcomes;  // with the input's arrival time
  sss::matcher::MatcherEngineCounters counters;
  size_t stored = 0;
  size_t memory_bytes = 0;
  bool busy = false;
};

}  // namespace

int main(int argc, char** argv) {
  sss::transport::NodeArguments arguments;
  if (const int exit_code = sss::transport::parseNodeArguments(argc, argv, arguments); exit_code >= 0) return exit_code;
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
  WorkQueue work;
  Results results;
  const int results_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (results_fd < 0) {
    spdlog::error("cannot create an eventfd for the matcher thread");
    return 1;
  }

  // Hands the engine's results to the process loop (worker thread).
  auto handOver = [&](std::vector<sss::matcher::PairOutcome> outcomes, int64_t arrival) {
    const std::string state_error = engine.takeStateError();
    if (!state_error.empty() && health.recordError("state_write", state_error, sss::core::nowUtime()))
      spdlog::warn("state directory: {}; further failures are counted in SSS_STATUS", state_error);
    {
      std::lock_guard<std::mutex> lock(results.mutex);
      for (auto& outcome : outcomes) results.outcomes.emplace_back(std::move(outcome), arrival);
      results.counters = engine.counters();
      results.stored = engine.storedSubframes();
      results.memory_bytes = engine.memoryBytes();
      results.busy = false;
    }
    const uint64_t one = 1;
    if (write(results_fd, &one, sizeof one) < 0) {
      // The counter saturates only after 2^64 - 1 writes; nothing to do.
    }
  };

  std::thread worker([&] {
    // First the state of the previous run (seconds for hundreds of subframes): the loop meanwhile
    // answers the watchdog and queues what arrives.
    if (store) {
      {
        std::lock_guard<std::mutex> lock(results.mutex);
        results.busy = true;
      }
      sss::matcher::RestoreReport report = engine.restore(*store);
      for (const std::string& problem : report.problems) spdlog::error("state directory: {}", problem);
      spdlog::info("restored {} subframes and {} matched pairs from {}{}; {} subframe(s) stored but not matched "
                   "before the restart: {} pair(s) matched now",
                   report.subframes, report.pairs, report.directory,
                   report.state_file_found ? "" : " (without matcher.state)", report.subframes_without_state,
                   report.outcomes.size());
      handOver(std::move(report.outcomes), sss::core::monotonicUtime());
    }
    for (;;) {
      std::optional<std::pair<sss::core::Subframe, int64_t>> subframe;
      std::optional<std::vector<sss::matcher::TrajectoryNode>> trajectory;
      {
        std::unique_lock<std::mutex> lock(work.mutex);
        work.wake.wait(lock, [&] { return work.stop || !work.subframes.empty() || work.trajectory.has_value(); });
        if (work.stop) return;
        // In arrival order, except that a waiting trajectory goes first: the subframes after it
        // are then matched with the newest poses.
        if (work.trajectory) {
          trajectory = std::move(work.trajectory);
          work.trajectory.reset();
        } else {
          subframe = std::move(work.subframes.front());
          work.subframes.pop_front();
        }
      }
      {
        std::lock_guard<std::mutex> lock(results.mutex);
        results.busy = true;
      }
      const int64_t arrival = subframe ? subframe->second : sss::core::monotonicUtime();
      handOver(subframe ? engine.addSubframe(std::move(subframe->first)) : engine.updateTrajectory(*trajectory),
               arrival);
    }
  });

  uint64_t rejected_messages = 0;
  loop.bus().subscribe<sss_msgs::subframe_t>(options.subframe_channel, [&](const sss_msgs::subframe_t& message) {
    sss::core::Subframe subframe;
    std::string error;
    if (!sss::messages::fromSubframeMessage(message, subframe, error)) {
      ++rejected_messages;
      if (health.recordError("bad_subframe", error, sss::core::nowUtime()))
        spdlog::warn("subframe {} rejected: {}; further ones are counted in SSS_STATUS", message.subframe_id, error);
      return;
    }
    std::lock_guard<std::mutex> lock(work.mutex);
    work.subframes.emplace_back(std::move(subframe), sss::core::monotonicUtime());
    while (static_cast<int>(work.subframes.size()) > options.max_queued_subframes) {
      work.subframes.pop_front();
      if (work.dropped_subframes++ == 0)
        spdlog::warn("matcher queue full ({} subframes): dropping the oldest; further drops are counted",
                     options.max_queued_subframes);
    }
    work.wake.notify_one();
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
    std::lock_guard<std::mutex> lock(work.mutex);
    work.trajectory = std::move(nodes);
    work.wake.notify_one();
  });

  loop.addFileDescriptor(results_fd, [&] {
    uint64_t count = 0;
    if (read(results_fd, &count, sizeof count) < 0) return;
    std::vector<std::pair<sss::matcher::PairOutcome, int64_t>> outcomes;
    {
      std::lock_guard<std::mutex> lock(results.mutex);
      outcomes.swap(results.outcomes);
    }
    for (const auto& [outcome, arrival] : outcomes) {
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
    sss::matcher::MatcherEngineCounters c;
    size_t stored = 0, memory = 0, queued = 0;
    uint64_t dropped = 0;
    bool busy = false;
    {
      std::lock_guard<std::mutex> lock(results.mutex);
      c = results.counters;
      stored = results.stored;
      memory = results.memory_bytes;
      busy = results.busy;
    }
    {
      std::lock_guard<std::mutex> lock(work.mutex);
      queued = work.subframes.size();
      dropped = work.dropped_subframes;
    }
    const auto set = [&](const char* name, double value) { health.setCounter(name, value); };
    set("subframes_in", static_cast<double>(c.subframes_in));
    set("subframes_rejected", static_cast<double>(c.subframes_rejected + rejected_messages));
    set("subframes_dropped_queue_full", static_cast<double>(dropped));
    set("subframes_evicted", static_cast<double>(c.subframes_evicted));
    set("subframes_stored", static_cast<double>(stored));
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
    set("memory_bytes", static_cast<double>(memory));
    set("busy", busy ? 1.0 : 0.0);
    health.setQueueDepth(options.subframe_channel, false, static_cast<int>(queued));
  });

  const int code = loop.run();
  {
    std::lock_guard<std::mutex> lock(work.mutex);
    work.stop = true;
    work.wake.notify_all();
  }
  worker.join();
  close(results_fd);
  return code;
}
