// The matcher's worker thread on the simulated three-line survey: it matches off the caller's
// thread and hands back each outcome with the arrival time of the subframe that produced it; the
// waiting subframes are bounded (the oldest dropped and counted); only the newest trajectory is
// kept; with a state directory a new worker restores the previous run first.
#include "pipeline/matcher/matcher_worker.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "pipeline/matcher/matcher_state.hpp"
#include "tests/matcher/matcher_test_survey.hpp"

namespace sss::matcher {
namespace {

namespace fs = std::filesystem;

using test::surveySubframe;  // line k's DR off by k * (2 m north, 1.5 m east)

struct Recorder {
  std::mutex mutex;
  std::condition_variable changed;
  int results_ready = 0;
  bool on_caller_thread = false;
  std::vector<RestoreReport> restored;
  const std::thread::id caller = std::this_thread::get_id();

  MatcherWorker::Hooks hooks() {
    MatcherWorker::Hooks h;
    h.results_ready = [this] {
      std::lock_guard<std::mutex> lock(mutex);
      ++results_ready;
      on_caller_thread = on_caller_thread || std::this_thread::get_id() == caller;
      changed.notify_all();
    };
    h.restored = [this](const RestoreReport& report) {
      std::lock_guard<std::mutex> lock(mutex);
      restored.push_back(report);
    };
    return h;
  }
};

// Waits (bounded: a broken worker fails instead of hanging) until the worker has taken every
// queued input and is idle.
bool waitIdle(const MatcherWorker& worker, uint64_t subframes_in) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline) {
    const MatcherWorkerStatus s = worker.status();
    if (s.counters.subframes_in >= subframes_in && !s.busy && s.queued_subframes == 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

TEST(MatcherWorker, MatchesOffTheCallersThreadAndKeepsEachOutcomesArrivalTime) {
  MatcherEngine engine{MatcherEngineOptions{}};
  Recorder recorder;
  MatcherWorker worker(engine, nullptr, {32}, recorder.hooks());
  worker.start();
  for (int64_t id : {0, 1, 2, 3}) worker.addSubframe(surveySubframe(id), 1000 + id);
  ASSERT_TRUE(waitIdle(worker, 4));
  std::map<std::pair<int64_t, int64_t>, int64_t> arrival_of_pair;
  for (const TimedOutcome& t : worker.takeOutcomes())
    arrival_of_pair[{t.outcome.subframe_id_a, t.outcome.subframe_id_b}] = t.arrival_monotonic_us;
  // Lines 0 and 1 overlap (subframes 0, 1 and 2, 3); a pair is matched when its newer subframe comes.
  const std::map<std::pair<int64_t, int64_t>, int64_t> expected{{{0, 2}, 1002}, {{1, 2}, 1002}, {{0, 3}, 1003}};
  EXPECT_EQ(arrival_of_pair, expected);
  EXPECT_TRUE(worker.takeOutcomes().empty());  // taken once
  const MatcherWorkerStatus status = worker.status();
  EXPECT_EQ(status.stored_subframes, 4u);
  EXPECT_GT(status.memory_bytes, 0u);
  EXPECT_EQ(status.dropped_subframes, 0u);
  std::lock_guard<std::mutex> lock(recorder.mutex);
  EXPECT_EQ(recorder.results_ready, 4);  // one per subframe
  EXPECT_FALSE(recorder.on_caller_thread);
}

TEST(MatcherWorker, TheOldestWaitingSubframeIsDroppedAndOnlyTheNewestTrajectoryIsKept) {
  MatcherEngine engine{MatcherEngineOptions{}};
  Recorder recorder;
  MatcherWorker worker(engine, nullptr, {2}, recorder.hooks());
  // Queued before the thread runs: a stalled worker.
  EXPECT_FALSE(worker.addSubframe(surveySubframe(0), 1));
  EXPECT_FALSE(worker.addSubframe(surveySubframe(1), 2));
  EXPECT_TRUE(worker.addSubframe(surveySubframe(2), 3));
  EXPECT_TRUE(worker.addSubframe(surveySubframe(3), 4));
  const std::vector<TrajectoryNode> first{{0, 1, sss::core::Pose()}};
  worker.setTrajectory(first);
  worker.setTrajectory(first);  // replaces the waiting one
  MatcherWorkerStatus status = worker.status();
  EXPECT_EQ(status.queued_subframes, 2u);
  EXPECT_EQ(status.dropped_subframes, 2u);
  worker.start();
  ASSERT_TRUE(waitIdle(worker, 2));
  status = worker.status();
  EXPECT_EQ(status.counters.subframes_in, 2u);  // 2 and 3: both of line 1, no pair
  EXPECT_EQ(status.counters.trajectory_updates, 1u);
  EXPECT_TRUE(worker.takeOutcomes().empty());
}

TEST(MatcherWorker, WithAStateDirectoryANewWorkerRestoresThePreviousRunFirst) {
  const std::string dir = (fs::temp_directory_path() / ("sss_matcher_worker_" + std::to_string(getpid()))).string();
  fs::remove_all(dir);
  {
    MatcherStateStore store(dir);
    MatcherEngine engine{MatcherEngineOptions{}};
    Recorder recorder;
    MatcherWorker worker(engine, &store, {32}, recorder.hooks());
    worker.start();
    for (int64_t id : {0, 1, 2, 3}) worker.addSubframe(surveySubframe(id), id);
    ASSERT_TRUE(waitIdle(worker, 4));
    std::lock_guard<std::mutex> lock(recorder.mutex);
    ASSERT_EQ(recorder.restored.size(), 1u);  // an empty directory: nothing restored
    EXPECT_EQ(recorder.restored[0].subframes, 0u);
  }
  MatcherStateStore store(dir);
  MatcherEngine engine{MatcherEngineOptions{}};
  Recorder recorder;
  MatcherWorker worker(engine, &store, {32}, recorder.hooks());
  worker.start();
  ASSERT_TRUE(waitIdle(worker, 0));
  {
    std::lock_guard<std::mutex> lock(recorder.mutex);
    ASSERT_EQ(recorder.restored.size(), 1u);
    EXPECT_EQ(recorder.restored[0].subframes, 4u);
    EXPECT_EQ(recorder.restored[0].pairs, 3u);
    EXPECT_GE(recorder.results_ready, 1);
  }
  EXPECT_EQ(worker.status().stored_subframes, 4u);
  worker.stop();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sss::matcher
