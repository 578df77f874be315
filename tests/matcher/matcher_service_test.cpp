// sss-matcher's logic without middleware (MatcherService), on LCM messages as the process gets
// them, on the simulated three-line survey: the overlapping pairs are matched off the caller's
// thread and each accepted closure comes back as a message with the arrival time of the subframe
// that produced it, with a log line per pair; inputs that cannot be used are refused under their
// kind with the cause; a full queue is said once and counted; the state directory is restored at
// the next start and the restore is said.
#include "pipeline/matcher/matcher_service.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "pipeline/core/time.hpp"
#include "pipeline/messages/subframe_messages.hpp"
#include "tests/matcher/matcher_test_survey.hpp"

namespace sss::matcher {
namespace {

namespace fs = std::filesystem;
using sss::core::HealthMonitor;
using sss::core::ServiceLog;

// Subframe `id` of the survey with line k's DR off by k * (2 m north, 1.5 m east), as a message.
sss_msgs::subframe_t surveyMessage(int64_t id) { return sss::messages::toSubframeMessage(test::surveySubframe(id), 16, 16.0); }

// Takes the service's results as the loop would, until `subframes` have been taken in and the
// worker is idle (bounded: a broken worker fails instead of hanging).
std::vector<ClosureToPublish> takeUntilIdle(MatcherService& service, std::atomic<int>& results_ready,
                                            HealthMonitor& health, ServiceLog& log, double subframes) {
  std::vector<ClosureToPublish> closures;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline) {
    if (results_ready.exchange(0) > 0) {
      for (auto& c : service.takeResults(7'000'000, health, log)) closures.push_back(std::move(c));
    }
    service.reportHealth(health, "SSS_SUBFRAME");
    if (health.counter("subframes_in") >= subframes && health.counter("busy") == 0.0 && results_ready.load() == 0) {
      for (auto& c : service.takeResults(7'000'000, health, log)) closures.push_back(std::move(c));
      return closures;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ADD_FAILURE() << "the worker did not become idle within 120 s";
  return closures;
}

TEST(MatcherService, MatchesOffTheLoopAndHandsBackClosureMessagesWithTheirArrivalTimes) {
  std::atomic<int> results_ready{0};
  ServiceLog log;
  MatcherService service(MatcherServiceOptions{}, [&] { ++results_ready; }, log);
  ASSERT_EQ(log.warnings.size(), 1u);  // no state directory: what a restart loses
  EXPECT_NE(log.warnings[0].find("a restart loses the stored subframes"), std::string::npos) << log.warnings[0];
  log = {};
  HealthMonitor health(sss::core::monotonicUtime());
  service.start();
  for (int64_t id : {0, 1, 2, 3}) service.addSubframe(surveyMessage(id), 1000 + id, health, log);
  EXPECT_TRUE(log.empty());
  const std::vector<ClosureToPublish> closures = takeUntilIdle(service, results_ready, health, log, 4);

  // Lines 0 and 1 overlap (subframes 0, 1 and 2, 3); a pair is matched when its newer subframe
  // comes, and the closure carries that subframe's arrival.
  std::map<std::pair<int64_t, int64_t>, int64_t> arrival_of_pair;
  for (const ClosureToPublish& c : closures) {
    EXPECT_EQ(c.message.utime, 7'000'000);
    arrival_of_pair[{c.message.subframe_id_a, c.message.subframe_id_b}] = c.arrival_monotonic_us;
  }
  const std::map<std::pair<int64_t, int64_t>, int64_t> expected{{{0, 2}, 1002}, {{1, 2}, 1002}, {{0, 3}, 1003}};
  EXPECT_EQ(arrival_of_pair, expected);
  // A log line for each pair, accepted or not.
  ASSERT_EQ(log.info.size(), 3u);
  for (const std::string& line : log.info) EXPECT_EQ(line.rfind("loop closure ", 0), 0u) << line;
  EXPECT_TRUE(log.warnings.empty());
  EXPECT_EQ(health.counter("closures_accepted"), 3.0);
  EXPECT_EQ(health.counter("subframes_stored"), 4.0);
  service.stop();
}

TEST(MatcherService, RefusesMessagesItCannotUseAndSaysAFullQueueOnce) {
  MatcherServiceOptions options;
  options.max_queued_subframes = 1;
  ServiceLog log;
  MatcherService service(options, [] {}, log);  // not started: a stalled worker
  log = {};
  HealthMonitor health(sss::core::monotonicUtime());

  sss_msgs::subframe_t short_image = surveyMessage(0);
  short_image.image.resize(short_image.image.size() / 2);
  short_image.num_image_bytes = static_cast<int32_t>(short_image.image.size());
  service.addSubframe(short_image, 1, health, log);
  service.addSubframe(short_image, 2, health, log);
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_EQ(log.warnings[0].rfind("subframe 0 rejected: ", 0), 0u) << log.warnings[0];
  log = {};
  sss_msgs::trajectory_t trajectory{};
  trajectory.num_nodes = 1;  // and no node in its arrays
  service.setTrajectory(trajectory, health, log);
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_EQ(log.warnings[0].rfind("trajectory rejected: ", 0), 0u) << log.warnings[0];
  log = {};

  for (int64_t id : {0, 1, 2}) service.addSubframe(surveyMessage(id), 10 + id, health, log);
  ASSERT_EQ(log.warnings.size(), 1u);  // two dropped, said once
  EXPECT_EQ(log.warnings[0], "matcher queue full (1 subframes): dropping the oldest; further drops are counted");
  service.reportHealth(health, "SSS_SUBFRAME");
  EXPECT_EQ(health.counter("subframes_dropped_queue_full"), 2.0);
  EXPECT_EQ(health.counter("subframes_rejected"), 3.0);  // the two subframes and the trajectory
  EXPECT_EQ(health.snapshot(sss::core::monotonicUtime()).errors_total, 3);
}

TEST(MatcherService, TheNextStartRestoresTheStateDirectoryAndSaysSo) {
  const std::string dir = ::testing::TempDir() + "sss_matcher_service_" + std::to_string(::getpid());
  fs::remove_all(dir);
  MatcherServiceOptions options;
  options.state_directory = dir;
  HealthMonitor health(sss::core::monotonicUtime());
  {
    std::atomic<int> results_ready{0};
    ServiceLog log;
    MatcherService service(options, [&] { ++results_ready; }, log);
    EXPECT_TRUE(log.empty());
    service.start();
    for (int64_t id : {0, 1, 2, 3}) service.addSubframe(surveyMessage(id), id, health, log);
    EXPECT_EQ(takeUntilIdle(service, results_ready, health, log, 4).size(), 3u);
    ASSERT_FALSE(log.info.empty());
    EXPECT_EQ(log.info[0], "restored 0 subframes and 0 matched pairs from " + dir +
                               " (without matcher.state); 0 subframe(s) stored but not matched before the restart: "
                               "0 pair(s) matched now");
  }
  std::atomic<int> results_ready{0};
  ServiceLog log;
  MatcherService service(options, [&] { ++results_ready; }, log);
  service.start();
  EXPECT_TRUE(takeUntilIdle(service, results_ready, health, log, 0).empty());  // matched before the restart
  ASSERT_EQ(log.info.size(), 1u);
  EXPECT_EQ(log.info[0].rfind("restored 4 subframes and 3 matched pairs from " + dir + ";", 0), 0u) << log.info[0];
  EXPECT_TRUE(log.errors.empty());
  service.stop();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sss::matcher
