// sss-matcher as a process over LCM udpm: the subframes of a simulated survey go in as
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // lcm-gen decode() false positive at -O3
// SSS_SUBFRAME, loop closures between the overlapping lines come out on SSS_LOOP and decode; a
// malformed subframe and a malformed trajectory are counted, not fatal; SIGTERM stops it cleanly.
// Killed with SIGKILL and started again, it restores its subframes from the state directory and
// matches new lines against the old ones, without sending the old closures again.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <thread>

#include "pipeline/core/time.hpp"
#include "pipeline/messages/closure_messages.hpp"
#include "pipeline/messages/subframe_messages.hpp"
#include "pipeline/transport/lcm_bus.hpp"
#include "tools/fixtures/spawn_process.hpp"
#include "sss_msgs/status_t.hpp"
#include "tests/matcher/matcher_test_survey.hpp"

namespace sss::matcher {
namespace {

using sss::messages::fromLoopClosureMessage;
using sss::messages::toTrajectoryMessage;
using sss::core::LoopClosure;
using sss::core::TrajectoryNode;

TEST(MatcherNode, SubframesInLoopClosuresOutBadMessagesCounted) {
  const auto& survey = test::threeLineSurvey();
  const std::string dir = ::testing::TempDir() + "/matcher_node_" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  const std::string lcm_url =
      "udpm://239.255.76.67:" + std::to_string(27000 + getpid() % 2000) + "?ttl=0&recv_buf_size=16777216";
  const std::string config = dir + "/matcher.yaml";
  {
    std::ofstream file(config);
    file << "matcher:\n  lcm_url: \"" << lcm_url << "\"\n  log_level: warn\n";
  }
  sss::core::HealthMonitor health(sss::core::monotonicUtime());
  sss::transport::LcmBus bus(lcm_url, health);
  ASSERT_TRUE(bus.good());
  std::vector<LoopClosure> closures;
  int decode_failures = 0;
  bus.subscribe<sss_msgs::loop_closure_t>("SSS_LOOP", [&](const sss_msgs::loop_closure_t& message) {
    const sss::core::Result<LoopClosure> closure = fromLoopClosureMessage(message);
    closure ? closures.push_back(*closure) : void(++decode_failures);
  });
  double rejected_in_status = -1.0;
  bus.subscribe<sss_msgs::status_t>("SSS_STATUS", [&](const sss_msgs::status_t& message) {
    if (message.process != "sss-matcher") return;
    for (int i = 0; i < message.num_counters; ++i) {
      if (message.counter_name[i] == "subframes_rejected") rejected_in_status = message.counter_value[i];
    }
  });

  const pid_t matcher = sss::test::spawnProcess({SSS_MATCHER_PATH, "--config", config});
  ASSERT_GT(matcher, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  // A subframe whose image is shorter than its size says, and a trajectory with a zero quaternion.
  sss_msgs::subframe_t broken = sss::messages::toSubframeMessage(survey.subframes.front(), 16, 16.0);
  broken.num_image_bytes -= 2;
  broken.image.resize(broken.num_image_bytes);
  bus.publish("SSS_SUBFRAME", broken);
  auto bad_trajectory = toTrajectoryMessage({TrajectoryNode{}}, 1);
  bad_trajectory.orientation_wxyz[0] = {0.0, 0.0, 0.0, 0.0};
  bus.publish("SSS_TRAJECTORY", bad_trajectory);
  for (const auto& subframe : survey.subframes) {
    bus.publish("SSS_SUBFRAME", sss::messages::toSubframeMessage(subframe, 16, 16.0, 0.0087f, 0.87f));
    bus.handleTimeout(100);
  }
  // Three lines overlap pairwise: at least one closure per line pair, ~0.3 s per pair.
  const int64_t deadline = sss::core::monotonicUtime() + 60'000'000;
  std::set<std::pair<int64_t, int64_t>> pairs;
  while (sss::core::monotonicUtime() < deadline && (closures.size() < 6 || rejected_in_status < 1.0)) {
    bus.handleTimeout(100);
  }
  ::kill(matcher, SIGTERM);
  int status = 0;
  ::waitpid(matcher, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  std::filesystem::remove_all(dir);

  EXPECT_EQ(decode_failures, 0);
  EXPECT_GE(closures.size(), 6u);
  EXPECT_GE(rejected_in_status, 1.0);
  const sss::sim::SubframeTruth truth(*survey.mission);
  for (const LoopClosure& c : closures) {
    const sss::core::Subframe* a = nullptr;
    const sss::core::Subframe* b = nullptr;
    for (const auto& s : survey.subframes) {
      if (s.id == c.subframe_id_a) a = &s;
      if (s.id == c.subframe_id_b) b = &s;
    }
    ASSERT_NE(a, nullptr);
    ASSERT_NE(b, nullptr);
    EXPECT_NE(a->line_id, b->line_id);
    EXPECT_EQ(c.centre_utime_a_us, a->centre().utime_us);
    EXPECT_GT(c.correspondences.size(), 30u);
    // The closure went through 16-bit image quantisation and the wire: still within 3 sigma.
    const Eigen::Vector2d error = (c.T_a_b.translation - truth.trueRelativePose(*a, *b).translation).head<2>();
    const double nees = error.transpose() * c.covariance.topLeftCorner<2, 2>().inverse() * error;
    EXPECT_LT(nees, 13.8) << c.subframe_id_a << "-" << c.subframe_id_b;
  }
}

TEST(MatcherNode, RestartAfterSigkillRestoresStateAndMatchesNewLinesAgainstOldOnes) {
  const auto& survey = test::threeLineSurvey();
  const std::string dir = ::testing::TempDir() + "/matcher_node_restart_" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  const std::string lcm_url =
      "udpm://239.255.76.67:" + std::to_string(29000 + getpid() % 2000) + "?ttl=0&recv_buf_size=16777216";
  const std::string config = dir + "/matcher.yaml";
  {
    std::ofstream file(config);
    file << "matcher:\n  lcm_url: \"" << lcm_url << "\"\n  log_level: warn\n  state_directory: \"" << dir
         << "/state\"\n";
  }
  sss::core::HealthMonitor health(sss::core::monotonicUtime());
  sss::transport::LcmBus bus(lcm_url, health);
  ASSERT_TRUE(bus.good());
  std::vector<std::pair<int64_t, int64_t>> closures;  // in arrival order
  bus.subscribe<sss_msgs::loop_closure_t>("SSS_LOOP", [&](const sss_msgs::loop_closure_t& message) {
    closures.push_back({message.subframe_id_a, message.subframe_id_b});
  });
  std::map<std::string, double> status;  // the newest SSS_STATUS counters of sss-matcher
  bus.subscribe<sss_msgs::status_t>("SSS_STATUS", [&](const sss_msgs::status_t& message) {
    if (message.process != "sss-matcher") return;
    for (int i = 0; i < message.num_counters; ++i) status[message.counter_name[i]] = message.counter_value[i];
  });
  auto waitFor = [&](const std::function<bool()>& done) {
    const int64_t deadline = sss::core::monotonicUtime() + 60'000'000;
    while (!done() && sss::core::monotonicUtime() < deadline) bus.handleTimeout(100);
    return done();
  };
  auto publish = [&](int64_t id) {
    for (const auto& subframe : survey.subframes) {
      if (subframe.id == id) bus.publish("SSS_SUBFRAME", sss::messages::toSubframeMessage(subframe, 16, 16.0));
    }
    bus.handleTimeout(100);
  };

  // Lines 0 and 1, then SIGKILL once their three pairs are matched (the state file is written
  // before the closures go out).
  pid_t matcher = sss::test::spawnProcess({SSS_MATCHER_PATH, "--config", config});
  ASSERT_GT(matcher, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  for (int64_t id : {0, 1, 2, 3}) publish(id);
  EXPECT_TRUE(waitFor([&] { return closures.size() >= 3; })) << closures.size() << " closures";
  ::kill(matcher, SIGKILL);
  ::waitpid(matcher, nullptr, 0);
  const size_t closures_before = closures.size();
  status.clear();

  matcher = sss::test::spawnProcess({SSS_MATCHER_PATH, "--config", config});
  ASSERT_GT(matcher, 0);
  EXPECT_TRUE(waitFor([&] { return status.count("subframes_restored"); }));
  EXPECT_EQ(status["subframes_restored"], 4.0);
  EXPECT_EQ(status["pairs_restored"], 3.0);
  EXPECT_EQ(status["state_files_corrupt"], 0.0);
  for (int64_t id : {4, 5}) publish(id);
  // Line 2 overlaps lines 0 and 1 (pairs 0-4, 2-4, 3-4, 1-5, 2-5 in the DR round).
  EXPECT_TRUE(waitFor([&] { return status["pairs_attempted"] >= 4.0 && status["busy"] == 0.0; }));
  bus.handleTimeout(500);
  ::kill(matcher, SIGTERM);
  EXPECT_EQ(sss::test::waitExitCode(matcher), 0);
  std::filesystem::remove_all(dir);

  std::set<int64_t> old_partners_of_new;
  for (size_t i = closures_before; i < closures.size(); ++i) {
    EXPECT_GE(closures[i].second, 4) << "an old pair sent again: " << closures[i].first << "-" << closures[i].second;
    if (closures[i].first <= 3) old_partners_of_new.insert(closures[i].first);
  }
  EXPECT_GE(old_partners_of_new.size(), 2u);  // at least 0 and 2 (the full subframes)
}

}  // namespace
}  // namespace sss::matcher
