// sss-ins-bridge's state across restarts: the odometer and the mission origin the first fix chose
// come back in a new bridge; a configured origin wins over a kept one; a damaged file is not
// resumed and says why; without a state directory nothing is written.
#include "drivers/ins/bridge_state.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace sss::ins {
namespace {

namespace fs = std::filesystem;

class BridgeStateTest : public ::testing::Test {
 protected:
  void SetUp() override {
    directory_ = (fs::temp_directory_path() / ("sss_bridge_state_" + std::to_string(::getpid()))).string();
    fs::remove_all(directory_);
    fs::create_directories(directory_);
  }
  void TearDown() override { fs::remove_all(directory_); }
  std::string directory_;
};

OdometerState odometerAt(double distance_m, int64_t utime_us) {
  OdometerState state;
  state.distance_travelled_m = distance_m;
  state.utime_us = utime_us;
  state.position_ned_m = Eigen::Vector3d(120.5, -33.25, 18.0);
  return state;
}

TEST_F(BridgeStateTest, TheOdometerAndTheFirstFixsOriginComeBackAfterARestart) {
  {
    InsBridge bridge(InsBridgeOptions{});
    BridgeStateStore store(directory_);
    BridgeStateLog log;
    store.restore(bridge, log);  // nothing kept yet
    EXPECT_TRUE(log.info.empty() && log.errors.empty());
    bridge.resumeOrigin({58.2501234, 11.4509876});  // as the first fix would choose it
    store.noteOrigin(bridge, log);
    ASSERT_EQ(log.info.size(), 1u);
    EXPECT_NE(log.info[0].find("first INS fix"), std::string::npos) << log.info[0];
    store.noteOrigin(bridge, log);  // said once
    EXPECT_EQ(log.info.size(), 1u);
    bridge.resumeOdometer(odometerAt(1234.56789, 1'700'000'000'000'000));
    store.saveOdometerIfMoved(bridge, log);
    EXPECT_TRUE(log.errors.empty());
    EXPECT_TRUE(fs::exists(store.odometerPath()));
    EXPECT_TRUE(fs::exists(store.originPath()));
  }
  InsBridge restarted(InsBridgeOptions{});
  BridgeStateStore store(directory_);
  BridgeStateLog log;
  store.restore(restarted, log);
  EXPECT_TRUE(log.errors.empty());
  ASSERT_TRUE(restarted.origin().has_value());
  EXPECT_DOUBLE_EQ(restarted.origin()->latitude_deg, 58.2501234);
  EXPECT_DOUBLE_EQ(restarted.origin()->longitude_deg, 11.4509876);
  const OdometerState odometer = restarted.odometer();
  EXPECT_DOUBLE_EQ(odometer.distance_travelled_m, 1234.56789);  // %.17g: exact
  EXPECT_EQ(odometer.utime_us, 1'700'000'000'000'000);
  EXPECT_DOUBLE_EQ(odometer.position_ned_m.y(), -33.25);
  // The kept origin is not said again as a first fix.
  store.noteOrigin(restarted, log);
  for (const std::string& line : log.info) EXPECT_EQ(line.find("first INS fix"), std::string::npos) << line;
}

TEST_F(BridgeStateTest, AConfiguredOriginWinsAndADamagedOdometerIsNotResumed) {
  {
    InsBridge bridge(InsBridgeOptions{});
    BridgeStateStore store(directory_);
    BridgeStateLog log;
    store.restore(bridge, log);
    bridge.resumeOrigin({10.0, 20.0});
    store.noteOrigin(bridge, log);
  }
  std::ofstream(directory_ + "/odometer") << "sss-ins-bridge odometer 1\ndistance_travelled_m -5\n";
  InsBridgeOptions configured;
  configured.origin = sss::core::MissionOrigin{58.0, 11.0};
  InsBridge bridge(configured);
  BridgeStateStore store(directory_);
  BridgeStateLog log;
  store.restore(bridge, log);
  ASSERT_EQ(log.errors.size(), 1u);
  EXPECT_NE(log.errors[0].find("odometer not resumed"), std::string::npos) << log.errors[0];
  EXPECT_DOUBLE_EQ(bridge.odometer().distance_travelled_m, 0.0);
  ASSERT_TRUE(bridge.origin().has_value());
  EXPECT_DOUBLE_EQ(bridge.origin()->latitude_deg, 58.0);
  ASSERT_EQ(log.info.size(), 1u);
  EXPECT_NE(log.info[0].find("configured"), std::string::npos) << log.info[0];
}

TEST_F(BridgeStateTest, ADamagedOriginFileLeavesTheChoiceToTheFirstFix) {
  std::ofstream(directory_ + "/origin") << "not an origin\n";
  InsBridge bridge(InsBridgeOptions{});
  BridgeStateStore store(directory_);
  BridgeStateLog log;
  store.restore(bridge, log);
  ASSERT_EQ(log.errors.size(), 1u);
  EXPECT_NE(log.errors[0].find("mission origin not resumed"), std::string::npos) << log.errors[0];
  EXPECT_FALSE(bridge.origin().has_value());
}

TEST_F(BridgeStateTest, WithoutAStateDirectoryNothingIsKept) {
  InsBridge bridge(InsBridgeOptions{});
  BridgeStateStore store("");
  BridgeStateLog log;
  store.restore(bridge, log);
  bridge.resumeOrigin({10.0, 20.0});
  bridge.resumeOdometer(odometerAt(50.0, 1'000'000));
  store.noteOrigin(bridge, log);
  store.saveOdometerIfMoved(bridge, log);
  EXPECT_TRUE(log.errors.empty());
  EXPECT_EQ(log.info.size(), 1u);  // the origin is still said
  EXPECT_TRUE(fs::is_empty(directory_));
  EXPECT_EQ(store.odometerWriteFailures(), 0u);
}

}  // namespace
}  // namespace sss::ins
