// InsBridgeService, sss-ins-bridge's logic without sockets or LCM: live samples go out as they come
// with the fixes they place, a file replay leaves at the recorded pace, the odometer and the first
// fix's origin survive a restart, and input faults are handed out once.
#include "drivers/ins/ins_bridge_service.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "ins_test_states.hpp"

namespace sss::ins {
namespace {

namespace fs = std::filesystem;

InsInputChunk chunkOf(const std::string& bytes, int64_t arrival_us, bool stream_break = true) {
  InsInputChunk chunk;
  chunk.data = reinterpret_cast<const uint8_t*>(bytes.data());
  chunk.size = bytes.size();
  chunk.arrival_us = arrival_us;
  chunk.stream_break = stream_break;
  return chunk;
}

std::string eastboundEpochs(int first, int last) {
  std::string stream;
  for (int e = first; e <= last; ++e) stream += encodeInsState(test::eastboundState(e));
  return stream;
}

// A USBL fix (talker "US": not a satellite system) at epoch time t_s, north/east of the origin.
std::string usblFixAt(double t_s, double north_m, double east_m) {
  const sss::core::LocalTangentPlane plane(test::kOriginLatitudeDeg, test::kOriginLongitudeDeg);
  const sss::core::GeodeticPosition geo = plane.toGeodetic(Eigen::Vector3d(north_m, east_m, 0.0));
  PositionFix fix;
  fix.utime_us = test::kStartUtime + static_cast<int64_t>(t_s * 1e6);
  fix.seconds_of_day = 8 * 3600.0 + t_s;
  fix.dated = true;
  fix.latitude_deg = geo.latitude_deg;
  fix.longitude_deg = geo.longitude_deg;
  fix.sigma_north_m = 1.5;
  fix.sigma_east_m = 1.5;
  fix.source = FixSource::kUsbl;
  fix.quality = 1;
  fix.satellites = 0;
  fix.hdop = 1.0;
  return encodePositionFix(fix, "US");
}

InsBridgeServiceOptions liveOptions() {
  InsBridgeServiceOptions options;
  options.bridge.origin = sss::core::MissionOrigin{test::kOriginLatitudeDeg, test::kOriginLongitudeDeg};
  options.read_fixes = true;
  return options;
}

TEST(InsBridgeService, LiveSamplesGoOutAtOnceAndAFixLeavesWhenTheNavigationHasPassedItsTime) {
  sss::core::ServiceLog log;
  InsBridgeService service(liveOptions(), log);
  ASSERT_EQ(log.info.size(), 1u);  // no state directory: only the configured origin is said
  EXPECT_NE(log.info[0].find("mission origin (configured)"), std::string::npos) << log.info[0];
  log = {};

  // USBL fixes at 2 s and 3.5 s (relayed by the modem: they arrive before the navigation of their time).
  const std::string fixes = usblFixAt(2.0, 10.5, 4.2) + usblFixAt(3.5, 10.2, 7.1);
  BridgeMessages from_fixes = service.onFixChunk(chunkOf(fixes, 1'000));
  EXPECT_TRUE(from_fixes.empty());  // no navigation yet: nothing to tie them to

  const BridgeMessages first = service.onInsChunk(chunkOf(eastboundEpochs(0, 10), 2'000), log);
  ASSERT_EQ(first.nav.size(), 11u);  // 0..1 s, every epoch closed by its STATUS
  EXPECT_EQ(first.nav.front().utime, test::kStartUtime);
  EXPECT_EQ(first.nav.back().utime, test::kStartUtime + 1'000'000);
  EXPECT_EQ(first.since_monotonic_us, 2'000);
  EXPECT_TRUE(first.fixes.empty());  // the navigation has not reached 2 s

  const BridgeMessages second = service.onInsChunk(chunkOf(eastboundEpochs(11, 30), 3'000), log);
  ASSERT_EQ(second.nav.size(), 20u);
  EXPECT_NEAR(second.nav.back().distance_travelled_m, 6.0, 0.02);  // 3 s at 2 m/s
  ASSERT_EQ(second.fixes.size(), 1u);
  const sss_msgs::fix_t& fix = second.fixes[0];
  EXPECT_EQ(fix.source, "usbl");
  EXPECT_EQ(fix.utime, test::kStartUtime + 2'000'000);
  EXPECT_NEAR(fix.position_ne_m[0], 10.5, 0.01);
  EXPECT_NEAR(fix.position_ne_m[1], 4.2, 0.01);
  // The DR state at the fix's time: 2 s east at 2 m/s from (10, 0, 40).
  EXPECT_NEAR(fix.dr_position_ned_m[0], 10.0, 0.01);
  EXPECT_NEAR(fix.dr_position_ned_m[1], 4.0, 0.01);
  EXPECT_DOUBLE_EQ(fix.origin_latitude_deg, test::kOriginLatitudeDeg);
  const BridgeMessages third = service.onInsChunk(chunkOf(eastboundEpochs(31, 35), 4'000), log);
  ASSERT_EQ(third.fixes.size(), 1u);  // 3.5 s passed
  EXPECT_EQ(third.fixes[0].utime, test::kStartUtime + 3'500'000);
  EXPECT_NEAR(third.fixes[0].dr_position_ned_m[1], 7.0, 0.01);

  sss::core::HealthMonitor health(0);
  service.reportHealth(health, 4'000);
  EXPECT_EQ(health.counter("ins_epochs"), 36.0);
  EXPECT_EQ(health.counter("fixes_in"), 2.0);
  EXPECT_EQ(health.counter("fixes_published"), 2.0);
  EXPECT_NEAR(health.counter("odometer_m"), 7.0, 0.02);
  EXPECT_EQ(service.fixesPublished(), 2u);
  EXPECT_TRUE(log.empty());
}

TEST(InsBridgeService, AReplayedFileLeavesAtItsRecordedPace) {
  InsBridgeServiceOptions options = liveOptions();
  options.replay = true;
  options.replay_speed = 2.0;
  options.state_directory = "/nonexistent/never-written";  // a replay keeps nothing
  sss::core::ServiceLog log;
  InsBridgeService service(options, log);
  EXPECT_TRUE(service.onInsChunk(chunkOf(eastboundEpochs(0, 40), 0), log).empty());  // queued
  EXPECT_TRUE(service.wantsReplayInput());

  const int64_t start_us = 5'000'000;
  EXPECT_EQ(service.takeDue(start_us, log).nav.size(), 1u);                // the first is due at once
  EXPECT_EQ(service.takeDue(start_us + 499'999, log).nav.size(), 9u);      // up to 0.9 s of INS time
  const BridgeMessages at_half_second = service.takeDue(start_us + 500'000, log);  // 1.0 s at speed 2
  ASSERT_EQ(at_half_second.nav.size(), 1u);
  EXPECT_EQ(at_half_second.nav[0].utime, test::kStartUtime + 1'000'000);
  EXPECT_EQ(at_half_second.since_monotonic_us, start_us + 500'000);
  EXPECT_EQ(service.takeDue(start_us + 10'000'000, log, 5).nav.size(), 5u);  // the budget per call
  EXPECT_EQ(service.takeDue(start_us + 10'000'000, log).nav.size(), 25u);
  EXPECT_TRUE(service.replayQueueEmpty());

  // Reading stays at most a queue's worth ahead of the pace.
  service.onInsChunk(chunkOf(eastboundEpochs(41, 400), 0), log);
  EXPECT_FALSE(service.wantsReplayInput());
  service.saveOdometerIfMoved(log);
  EXPECT_TRUE(log.errors.empty());
  EXPECT_FALSE(fs::exists("/nonexistent/never-written"));
}

class InsBridgeServiceStateTest : public ::testing::Test {
 protected:
  void SetUp() override {
    directory_ = (fs::temp_directory_path() / ("sss_ins_bridge_service_" + std::to_string(::getpid()))).string();
    fs::remove_all(directory_);
    fs::create_directories(directory_);
  }
  void TearDown() override { fs::remove_all(directory_); }
  std::string directory_;
};

// A bridge restarted mid-mission (no origin configured) keeps the frame the first fix chose and
// goes on counting distance from where it stood.
TEST_F(InsBridgeServiceStateTest, TheOdometerAndTheFirstFixsOriginSurviveARestart) {
  InsBridgeServiceOptions options;
  options.state_directory = directory_;
  double distance_before_m = 0.0;
  {
    sss::core::ServiceLog log;
    InsBridgeService service(options, log);
    const BridgeMessages out = service.onInsChunk(chunkOf(eastboundEpochs(0, 30), 0), log);
    ASSERT_EQ(out.nav.size(), 31u);
    ASSERT_EQ(log.info.size(), 1u);  // the origin chosen by the first fix, said once
    EXPECT_NE(log.info[0].find("first INS fix"), std::string::npos) << log.info[0];
    service.onInsChunk(chunkOf(eastboundEpochs(31, 40), 0), log);
    EXPECT_EQ(log.info.size(), 1u);
    service.saveOdometerIfMoved(log);
    EXPECT_TRUE(log.errors.empty());
    distance_before_m = service.bridge().odometer().distance_travelled_m;
    EXPECT_NEAR(distance_before_m, 8.0, 0.02);
  }
  sss::core::ServiceLog log;
  InsBridgeService restarted(options, log);
  EXPECT_TRUE(log.errors.empty());
  EXPECT_FALSE(log.info.empty());  // what was restored
  ASSERT_TRUE(restarted.bridge().origin().has_value());
  // 2 s missed during the restart: bridged as the straight line.
  const BridgeMessages out = restarted.onInsChunk(chunkOf(eastboundEpochs(61, 70), 0), log);
  ASSERT_EQ(out.nav.size(), 10u);
  EXPECT_NEAR(out.nav.front().distance_travelled_m, distance_before_m + 4.2, 0.02);
  // The first run's frame: its origin is the first fix, (10, 0) in the frame of the test states.
  EXPECT_NEAR(out.nav.front().position_ned_m[0], 0.0, 0.01);
  EXPECT_NEAR(out.nav.front().position_ned_m[1], 12.2, 0.01);
}

TEST(InsBridgeService, InputFaultsAreHandedOutOncePerKind) {
  sss::core::ServiceLog log;
  InsBridgeService service(liveOptions(), log);
  std::string corrupt = eastboundEpochs(0, 0);
  corrupt[corrupt.find('*') + 1] ^= 1;  // a wrong checksum
  service.onInsChunk(chunkOf(corrupt + corrupt, 0), log);
  const std::vector<std::string> ins_faults = service.takeInsFaults();
  ASSERT_FALSE(ins_faults.empty());
  EXPECT_NE(ins_faults[0].find("checksum"), std::string::npos) << ins_faults[0];
  EXPECT_TRUE(service.takeInsFaults().empty());

  const std::string bad_gga = "$USGGA,080002.00,5921.0000,N,01804.2000,E,1,00,1.0,-40.0,M,,M,,*00\r\n";
  service.onFixChunk(chunkOf(bad_gga + bad_gga, 0));
  const std::vector<std::string> fix_faults = service.takeFixFaults();
  ASSERT_EQ(fix_faults.size(), 1u);
  EXPECT_EQ(fix_faults[0].rfind("fixes: ", 0), 0u) << fix_faults[0];
  EXPECT_TRUE(service.takeFixFaults().empty());

  sss::core::HealthMonitor health(0);
  service.reportHealth(health, 0);
  EXPECT_EQ(health.counter("fix_sentences_skipped"), 2.0);
  EXPECT_GT(health.counter("nmea_bad_checksum"), 0.0);
}

}  // namespace
}  // namespace sss::ins
