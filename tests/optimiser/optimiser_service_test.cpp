// sss-optimiser's logic without middleware (OptimiserService), on LCM messages as the process gets
// them: nav samples are answered from their first position on and those that cannot be are counted
// and logged once; inputs that cannot be used are refused under their kind with the cause; the
// small synthetic lawnmower goes through the worker and its trajectory comes back; the end of the
// mission writes the products and a checkpoint that the next start resumes from.
#include "pipeline/optimiser/optimiser_service.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/core/time.hpp"
#include "pipeline/messages/closure_messages.hpp"
#include "pipeline/messages/subframe_messages.hpp"
#include "tests/optimiser/pose_graph_test_helpers.hpp"
#include "tools/fixtures/synthetic_subframes.hpp"

namespace sss::optimiser {
namespace {

namespace fs = std::filesystem;
using sss::core::HealthMonitor;
using sss::core::ServiceLog;

constexpr double kOriginLatDeg = 58.25, kOriginLonDeg = 11.45;

OptimiserServiceOptions serviceOptions(const std::string& state_directory = "") {
  OptimiserServiceOptions o;
  o.engine.graph = test_helpers::graphOptions(8);
  o.update_period_s = 0.0;
  o.state_directory = state_directory;
  if (!state_directory.empty()) o.products_directory = state_directory + "/products";
  return o;
}

sss_msgs::nav_t navMessage(int64_t utime_us, double north_m, double east_m) {
  sss_msgs::nav_t m{};
  m.utime = utime_us;
  m.origin_latitude_deg = kOriginLatDeg;
  m.origin_longitude_deg = kOriginLonDeg;
  m.position_ned_m[0] = north_m;
  m.position_ned_m[1] = east_m;
  m.position_ned_m[2] = 20.0;
  m.depth_m = 20.0;
  m.heading_rad = 0.3;
  m.altitude_m = 10.0;
  for (int i = 0; i < 3; ++i) m.position_std_ned_m[i] = 0.5;
  m.validity = sss_msgs::nav_t::VALID_POSITION | sss_msgs::nav_t::VALID_ATTITUDE | sss_msgs::nav_t::VALID_HEADING |
               sss_msgs::nav_t::VALID_VELOCITY | sss_msgs::nav_t::VALID_DEPTH | sss_msgs::nav_t::VALID_ALTITUDE;
  return m;
}

sss_msgs::fix_t fixMessage(int64_t utime_us, double origin_lat_deg) {
  sss_msgs::fix_t m{};
  m.utime = utime_us;
  m.source = "gnss";
  m.origin_latitude_deg = origin_lat_deg;
  m.origin_longitude_deg = kOriginLonDeg;
  m.covariance_ne_m2[0] = m.covariance_ne_m2[3] = 4.0;
  m.quality = 1;
  m.satellites = 9;
  m.hdop = 1.0;
  return m;
}

std::string temporaryDirectory(const std::string& name) {
  const std::string path = ::testing::TempDir() + "sss_service_" + std::to_string(::getpid()) + "_" + name;
  fs::remove_all(path);
  return path;
}

int64_t errorsTotal(HealthMonitor& health) { return health.snapshot(sss::core::monotonicUtime()).errors_total; }

TEST(OptimiserService, AnswersNavFromItsFirstPositionAndCountsTheSamplesItCannotAnswer) {
  OptimiserServiceOptions options = serviceOptions();
  options.configured_origin = sss::core::MissionOrigin{kOriginLatDeg + 0.01, kOriginLonDeg};
  ServiceLog log;
  OptimiserService service(options, [] {}, log);
  ASSERT_EQ(log.warnings.size(), 1u);  // no state directory: what a restart loses
  EXPECT_NE(log.warnings[0].find("no checkpoints"), std::string::npos) << log.warnings[0];
  log = {};
  HealthMonitor health(sss::core::monotonicUtime());

  // Before the INS's first fix: not answered, counted each time, logged once.
  sss_msgs::nav_t no_position = navMessage(1'000'000, 0.0, 0.0);
  no_position.validity &= ~sss_msgs::nav_t::VALID_POSITION;
  EXPECT_FALSE(service.addNav(no_position, health, log).has_value());
  EXPECT_FALSE(service.addNav(no_position, health, log).has_value());
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find("before the INS's first fix"), std::string::npos) << log.warnings[0];
  EXPECT_EQ(errorsTotal(health), 2);
  log = {};
  sss_msgs::nav_t no_heading = navMessage(2'000'000, 0.0, 0.0);
  no_heading.heading_rad = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(service.addNav(no_heading, health, log).has_value());
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find("non-finite pose"), std::string::npos) << log.warnings[0];
  log = {};

  // The first sample with a position: answered with its DR pose (no graph yet), and its frame is
  // the navigation's, with a warning that the configuration says otherwise.
  const std::optional<CorrectedPose> answer = service.addNav(navMessage(3'000'000, 12.5, -7.25), health, log);
  ASSERT_TRUE(answer.has_value());
  EXPECT_EQ(answer->pose.utime, 3'000'000);
  EXPECT_NEAR(answer->pose.position_ned_m[0], 12.5, 1e-9);
  EXPECT_NEAR(answer->pose.position_ned_m[1], -7.25, 1e-9);
  EXPECT_EQ(answer->accepted_closures, 0);
  ASSERT_EQ(log.info.size(), 1u);
  EXPECT_EQ(log.info[0], "mission origin (from SSS_NAV): 58.2500000 11.4500000");
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find("differs from mission.origin_*"), std::string::npos) << log.warnings[0];
  log = {};
  // The next sample: answered, nothing more to say.
  EXPECT_TRUE(service.addNav(navMessage(3'005'000, 12.6, -7.25), health, log).has_value());
  EXPECT_TRUE(log.empty());
  service.finish(log);
}

TEST(OptimiserService, RefusesInputsItCannotUseUnderTheirKindWithTheCause) {
  ServiceLog log;
  OptimiserService service(serviceOptions(), [] {}, log);
  log = {};
  HealthMonitor health(sss::core::monotonicUtime());

  sss_msgs::subframe_t empty_subframe{};
  empty_subframe.subframe_id = 42;
  service.addSubframe(empty_subframe, health, log);
  service.addSubframe(empty_subframe, health, log);
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_EQ(log.warnings[0].rfind("subframe 42 rejected: ", 0), 0u) << log.warnings[0];
  EXPECT_EQ(errorsTotal(health), 2);
  log = {};

  sss::core::LoopClosure closure;
  closure.subframe_id_a = 1;
  closure.subframe_id_b = 2;
  closure.covariance = sss::core::Matrix6d::Identity();
  sss_msgs::loop_closure_t nan_closure = sss::messages::toLoopClosureMessage(closure, 1'000'000);
  nan_closure.translation_ab_m[0] = std::numeric_limits<double>::quiet_NaN();
  service.addLoopClosure(nan_closure, health, log);
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_EQ(log.warnings[0].rfind("loop closure rejected: ", 0), 0u) << log.warnings[0];
  log = {};

  sss_msgs::fix_t sonar_fix = fixMessage(1'000'000, kOriginLatDeg);
  sonar_fix.source = "sonar";
  service.addFix(sonar_fix, health, log);
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find("neither gnss nor usbl"), std::string::npos) << log.warnings[0];
  log = {};

  // Once the navigation's frame is known, a fix placed in another frame is refused (counted; the
  // kind was logged already).
  ASSERT_TRUE(service.addNav(navMessage(1'000'000, 0.0, 0.0), health, log).has_value());
  log = {};
  const int64_t before = errorsTotal(health);
  service.addFix(fixMessage(2'000'000, kOriginLatDeg + 0.5), health, log);
  EXPECT_TRUE(log.warnings.empty());
  const sss::core::HealthSnapshot snapshot = health.snapshot(sss::core::monotonicUtime());
  EXPECT_EQ(snapshot.errors_total - before, 1);
  EXPECT_NE(snapshot.last_error.find("mission origin differs"), std::string::npos) << snapshot.last_error;
  // In the navigation's frame: taken.
  service.addFix(fixMessage(3'000'000, kOriginLatDeg), health, log);
  EXPECT_EQ(errorsTotal(health), snapshot.errors_total);
  service.finish(log);
}

TEST(OptimiserService, SolvesOffTheLoopWritesProductsAndTheNextStartResumes) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(test_helpers::missionOptions(3));
  synthetic::SubframeOptions subframe_options;
  subframe_options.correspondences_per_closure = 50;
  std::vector<std::vector<sss::core::Pose>> truth;
  std::vector<sss::core::Subframe> subframes = synthetic::makeSubframes(mission, subframe_options, &truth);
  for (sss::core::Subframe& subframe : subframes) {  // poses only: a small blank image to travel with them
    subframe.geometry.bins_per_side = 8;
    subframe.geometry.bin_size_m = 0.5;
    subframe.image.assign(static_cast<size_t>(subframe.rows() * subframe.cols()), 0.0f);
    subframe.mask.assign(static_cast<size_t>(subframe.rows() * subframe.cols()), 0);
  }
  const std::string state_directory = temporaryDirectory("resume");

  std::atomic<int> results_ready{0};
  ServiceLog log;
  HealthMonitor health(sss::core::monotonicUtime());
  {
    OptimiserService service(serviceOptions(state_directory), [&] { ++results_ready; }, log);
    EXPECT_TRUE(log.empty());  // a fresh state directory: nothing to resume, nothing to warn of
    EXPECT_EQ(service.checkpointPath(), state_directory + "/optimiser.checkpoint");
    service.start();
    for (const sss::core::Subframe& subframe : subframes) {
      service.addSubframe(sss::messages::toSubframeMessage(subframe, 16, 16.0), health, log);
    }
    for (size_t c = 0; c < mission.closures.size(); ++c) {
      const sss::core::LoopClosure closure = synthetic::makeMatcherClosure(mission, c, truth, subframe_options, 0);
      service.addLoopClosure(sss::messages::toLoopClosureMessage(closure, 1'000'000), health, log);
    }
    EXPECT_TRUE(log.warnings.empty()) << log.warnings.front();
    // The worker's results come back until the trajectory holds every subframe (bounded wait).
    size_t trajectory_nodes = 0;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (trajectory_nodes < subframes.size() && std::chrono::steady_clock::now() < deadline) {
      if (results_ready.load() == 0) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        continue;
      }
      --results_ready;
      if (const auto trajectory = service.takeResults(health, 5'000'000, log)) {
        EXPECT_EQ(trajectory->utime, 5'000'000);
        trajectory_nodes = static_cast<size_t>(trajectory->num_nodes);
      }
    }
    EXPECT_EQ(trajectory_nodes, subframes.size());
    EXPECT_EQ(health.counter("nodes"), static_cast<double>(subframes.size()));
    service.finish(log);
  }
  EXPECT_TRUE(fs::exists(state_directory + "/optimiser.checkpoint"));
  EXPECT_TRUE(fs::exists(state_directory + "/products/slam.tum"));
  EXPECT_TRUE(fs::exists(state_directory + "/products/loop_closures.csv"));

  ServiceLog resumed_log;
  OptimiserService resumed(serviceOptions(state_directory), [] {}, resumed_log);
  ASSERT_EQ(resumed_log.info.size(), 1u);
  EXPECT_EQ(resumed_log.info[0].rfind("resumed from " + state_directory + "/optimiser.checkpoint: " +
                                          std::to_string(subframes.size()) + " nodes",
                                      0),
            0u)
      << resumed_log.info[0];
  EXPECT_TRUE(resumed_log.errors.empty());
  // A checkpoint that cannot be read is refused with the cause and the graph starts empty.
  { std::ofstream(state_directory + "/optimiser.checkpoint") << "not a checkpoint"; }
  ServiceLog refused_log;
  OptimiserService refused(serviceOptions(state_directory), [] {}, refused_log);
  ASSERT_EQ(refused_log.errors.size(), 1u);
  EXPECT_NE(refused_log.errors[0].find("refused"), std::string::npos) << refused_log.errors[0];
  fs::remove_all(state_directory);
}

}  // namespace
}  // namespace sss::optimiser
