// The optimiser's worker thread on the small synthetic lawnmower (5 lines of 4 subframes, closures
// with seabed correspondences): it solves off the caller's thread and hands back the graph, the
// trajectory and the status; it updates at most once per period; it writes a checkpoint after
// every update and the products on request; finish() takes what is still queued; a restored graph
// goes out at start.
#include "pipeline/optimiser/optimiser_worker.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "tools/fixtures/synthetic_subframes.hpp"
#include "tests/optimiser/pose_graph_test_helpers.hpp"

namespace sss::optimiser {
namespace {

using test_helpers::graphOptions;
using test_helpers::missionOptions;

struct Scenario {
  synthetic::Mission mission;
  std::vector<sss::core::Subframe> subframes;
  std::vector<std::vector<sss::core::LoopClosure>> closures_of;  // by the newer subframe
};

Scenario makeScenario() {
  Scenario s;
  s.mission = synthetic::makeLawnmowerMission(missionOptions(3));
  synthetic::SubframeOptions subframe_options;
  subframe_options.correspondences_per_closure = 50;
  std::vector<std::vector<sss::core::Pose>> truth;
  s.subframes = synthetic::makeSubframes(s.mission, subframe_options, &truth);
  s.closures_of.resize(s.subframes.size());
  for (size_t c = 0; c < s.mission.closures.size(); ++c) {
    s.closures_of[s.mission.closures[c].newer_node].push_back(
        synthetic::makeMatcherClosure(s.mission, c, truth, subframe_options, 0));
  }
  return s;
}

OptimiserEngineOptions engineOptions() {
  OptimiserEngineOptions o;
  o.graph = graphOptions(8);
  return o;
}

std::string temporaryPath(const std::string& name) {
  return ::testing::TempDir() + "sss_worker_" + std::to_string(::getpid()) + "_" + name;
}

// The hooks record what the worker did and on which thread.
struct Recorder {
  std::mutex mutex;
  std::condition_variable changed;
  int results_ready = 0;
  int subframes_taken = 0;
  int products_written = 0;
  std::optional<sss::core::MissionOrigin> products_origin;
  bool hooks_on_caller_thread = false;
  const std::thread::id caller = std::this_thread::get_id();

  OptimiserWorker::Hooks hooks() {
    OptimiserWorker::Hooks h;
    h.subframe_taken = [this](const sss::core::Subframe&) {
      std::lock_guard<std::mutex> lock(mutex);
      ++subframes_taken;
      hooks_on_caller_thread = hooks_on_caller_thread || std::this_thread::get_id() == caller;
      changed.notify_all();
    };
    h.write_products = [this](const OptimiserEngine&, const std::optional<sss::core::MissionOrigin>& origin,
                              std::vector<std::string>& messages) {
      std::lock_guard<std::mutex> lock(mutex);
      ++products_written;
      products_origin = origin;
      messages.push_back("products written");
      changed.notify_all();
    };
    h.results_ready = [this] {
      std::lock_guard<std::mutex> lock(mutex);
      ++results_ready;
      changed.notify_all();
    };
    return h;
  }

  // Waits (bounded, so that a broken worker fails instead of hanging) until the predicate holds.
  template <typename Predicate>
  bool waitFor(Predicate predicate) {
    std::unique_lock<std::mutex> lock(mutex);
    return changed.wait_for(lock, std::chrono::seconds(30), predicate);
  }
};

// Polls the worker's results until the snapshot has `nodes` nodes (each results_ready may carry
// only part of the input). Returns the results taken on the way, merged.
OptimiserWorkerResults waitForNodes(OptimiserWorker& worker, Recorder& recorder, size_t nodes) {
  OptimiserWorkerResults merged;
  for (int seen = 0;;) {
    const bool woken = recorder.waitFor([&] { return recorder.results_ready > seen; });
    if (!woken) {
      ADD_FAILURE() << "no results within 30 s";
      return merged;
    }
    {
      std::lock_guard<std::mutex> lock(recorder.mutex);
      seen = recorder.results_ready;
    }
    OptimiserWorkerResults results = worker.takeResults();
    if (results.trajectory) merged.trajectory = std::move(results.trajectory);
    for (auto& m : results.messages) merged.messages.push_back(std::move(m));
    merged.status = results.status;
    if (worker.snapshot()->numNodes() >= nodes) return merged;
  }
}

TEST(OptimiserWorker, SolvesOffTheCallersThreadAndHandsBackGraphTrajectoryAndStatus) {
  const Scenario s = makeScenario();
  OptimiserEngine engine(engineOptions());
  Recorder recorder;
  OptimiserWorker worker(engine, {0.0, ""}, recorder.hooks());
  EXPECT_EQ(worker.snapshot()->numNodes(), 0u);  // never null, empty before the first update
  worker.start();
  for (size_t i = 0; i < s.subframes.size(); ++i) {
    worker.addSubframe(s.subframes[i]);
    for (const auto& closure : s.closures_of[i]) worker.addLoopClosure(closure);
  }
  const OptimiserWorkerResults results = waitForNodes(worker, recorder, s.subframes.size());
  ASSERT_TRUE(results.trajectory.has_value());
  EXPECT_EQ(results.trajectory->size(), s.subframes.size());
  EXPECT_EQ(results.status.graph.nodes_added, s.subframes.size());
  EXPECT_GE(results.status.graph.updates, 1u);
  EXPECT_GT(results.status.memory_bytes, 0u);
  {
    std::lock_guard<std::mutex> lock(recorder.mutex);
    EXPECT_EQ(recorder.subframes_taken, static_cast<int>(s.subframes.size()));
    EXPECT_FALSE(recorder.hooks_on_caller_thread);
  }
  // The closures reach the graph too (some may still be in the engine's queue until finish()).
  const std::vector<std::string> messages = worker.finish();
  EXPECT_GT(engine.graph().counters().closures_accepted, 0u);
  EXPECT_EQ(engine.graph().counters().full_smoothings, 1u);
  EXPECT_EQ(recorder.products_written, 1);
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0], "products written");
}

TEST(OptimiserWorker, UpdatesAtMostOncePerPeriodAndFinishTakesWhatIsQueued) {
  const Scenario s = makeScenario();
  OptimiserEngine engine(engineOptions());
  Recorder recorder;
  OptimiserWorker worker(engine, {3600.0, ""}, recorder.hooks());
  worker.start();
  worker.addSubframe(s.subframes[0]);
  waitForNodes(worker, recorder, 1);  // the first update comes at once
  for (size_t i = 1; i < 4; ++i) worker.addSubframe(s.subframes[i]);
  // The worker takes them into the engine but solves again only an hour after the first update.
  ASSERT_TRUE(recorder.waitFor([&] { return recorder.subframes_taken == 4; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(worker.snapshot()->numNodes(), 1u);
  EXPECT_EQ(worker.takeResults().status.graph.updates, 1u);
  // Queued and never taken by the thread: finish() takes it.
  worker.setOrigin({58.25, 11.45});
  worker.finish();
  worker.addSubframe(s.subframes[4]);  // after finish(): nobody takes it, and nothing breaks
  EXPECT_EQ(engine.graph().numNodes(), 4u);
  ASSERT_TRUE(recorder.products_origin.has_value());
  EXPECT_DOUBLE_EQ(recorder.products_origin->latitude_deg, 58.25);
}

// Nav's accuracy reports (200 Hz on the vehicle) reach the engine with the next batch, at most
// one per second, and the first node's anchor takes the one nearest its centre.
TEST(OptimiserWorker, PassesTheInsAccuracyOnForTheFirstNodesAnchor) {
  const Scenario s = makeScenario();
  OptimiserEngine engine(engineOptions());
  Recorder recorder;
  OptimiserWorker worker(engine, {0.0, ""}, recorder.hooks());
  worker.start();
  const int64_t centre_us = s.subframes[0].pings[s.subframes[0].centre_ping_index].utime_us;
  for (int64_t t_us = centre_us - 10'000'000; t_us <= centre_us + 10'000'000; t_us += 5'000) {
    // 200 Hz; the accuracy worsens by 1 cm a second, 1.23 m at the centre.
    const double std_m = 1.23 + 0.01 * 1e-6 * static_cast<double>(t_us - centre_us);
    worker.addNavAccuracy({t_us, std_m, 0.5 * std_m});
  }
  worker.addSubframe(s.subframes[0]);
  waitForNodes(worker, recorder, 1);
  worker.finish();
  EXPECT_TRUE(engine.anchorDecided());
  EXPECT_NEAR(engine.graph().firstNodeInsSigma().x(), 1.23, 1e-9);
  EXPECT_NEAR(engine.graph().firstNodeInsSigma().y(), 0.615, 1e-9);
}

TEST(OptimiserWorker, WritesACheckpointAfterEveryUpdateAndTheProductsOnRequest) {
  const Scenario s = makeScenario();
  const std::string checkpoint = temporaryPath("checkpoint");
  std::filesystem::remove(checkpoint);
  OptimiserEngine engine(engineOptions());
  Recorder recorder;
  OptimiserWorker worker(engine, {0.0, checkpoint}, recorder.hooks());
  worker.start();
  for (size_t i = 0; i < 8; ++i) worker.addSubframe(s.subframes[i]);
  const OptimiserWorkerResults results = waitForNodes(worker, recorder, 8);
  EXPECT_TRUE(std::filesystem::exists(checkpoint));
  EXPECT_GT(results.status.last_checkpoint_s, 0.0);
  worker.requestProducts();
  ASSERT_TRUE(recorder.waitFor([&] { return recorder.products_written == 1; }));
  EXPECT_EQ(engine.graph().counters().full_smoothings, 1u);
  // A second engine restores the checkpoint: a restarted process goes on from the same graph.
  worker.finish();
  OptimiserEngine restored(engineOptions());
  ASSERT_TRUE(restored.loadCheckpoint(checkpoint).ok);
  EXPECT_EQ(restored.graph().numNodes(), 8u);
  std::filesystem::remove(checkpoint);
  std::filesystem::remove(checkpoint + ".journal");
}

TEST(OptimiserWorker, ARestoredGraphGoesOutAtStartAndRefusedInputIsReported) {
  const Scenario s = makeScenario();
  OptimiserEngine engine(engineOptions());
  for (size_t i = 0; i < 4; ++i) ASSERT_TRUE(engine.addSubframe(s.subframes[i]).ok);
  ASSERT_TRUE(engine.update().ok);
  Recorder recorder;
  OptimiserWorker worker(engine, {0.0, ""}, recorder.hooks());
  worker.start();
  ASSERT_TRUE(recorder.waitFor([&] { return recorder.results_ready >= 1; }));
  OptimiserWorkerResults results = worker.takeResults();
  ASSERT_TRUE(results.trajectory.has_value());  // before any new input
  EXPECT_EQ(results.trajectory->size(), 4u);
  EXPECT_EQ(results.status.graph.nodes_added, 4u);
  // A subframe older than the newest is refused by the engine: the worker says so in its log lines.
  worker.addSubframe(s.subframes[1]);
  ASSERT_TRUE(recorder.waitFor([&] { return recorder.results_ready >= 2; }));
  results = worker.takeResults();
  ASSERT_EQ(results.messages.size(), 1u);
  EXPECT_NE(results.messages[0].find("subframe " + std::to_string(s.subframes[1].id) + " refused"), std::string::npos)
      << results.messages[0];
  EXPECT_EQ(results.status.engine.subframes_refused, 1u);
  worker.finish();
}

}  // namespace
}  // namespace sss::optimiser
