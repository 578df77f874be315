// INS bridge logic: local NED from geodetic, body velocity, distance travelled, ordering,
// staleness while the INS is silent, and the SSS_NAV translation.
#include "drivers/ins/ins_bridge.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "drivers/ins/nav_message.hpp"
#include "ins_test_states.hpp"

namespace sss::ins {
namespace {

InsBridgeOptions testOptions() {
  InsBridgeOptions options;
  options.origin = sss::core::MissionOrigin{test::kOriginLatitudeDeg, test::kOriginLongitudeDeg};
  return options;
}

std::vector<NavSample> feedAll(InsBridge& bridge, const std::string& stream, int64_t host_us = 0) {
  std::vector<NavSample> samples;
  bridge.onBytes(reinterpret_cast<const uint8_t*>(stream.data()), stream.size(), host_us, samples);
  return samples;
}

TEST(InsBridge, GivesLocalNedBodyVelocityAndDistanceTravelled) {
  InsBridge bridge(testOptions());
  const std::vector<NavSample> samples = feedAll(bridge, test::eastboundStream(51));
  ASSERT_EQ(samples.size(), 51u);  // every burst ends with STATUS: no epoch waits
  const NavSample& last = samples.back();
  // 5 s east at 2 m/s from (10, 0, 40): lat/lon at 1e-8 deg (~1 mm), depth at 1 mm.
  EXPECT_NEAR(last.position_ned_m.x(), 10.0, 0.005);
  EXPECT_NEAR(last.position_ned_m.y(), 10.0, 0.005);
  EXPECT_NEAR(last.position_ned_m.z(), 40.0, 0.002);
  EXPECT_NEAR(last.distance_travelled_m, 10.0, 0.02);
  // Heading east with 2 m/s east: forward speed 2, small cross terms from roll/pitch only.
  EXPECT_NEAR(last.velocity_body_m_s.x(), 2.0 * std::cos(0.02), 1e-3);
  EXPECT_NEAR(last.velocity_body_m_s.y(), 0.0, 1e-3);
  EXPECT_EQ(last.ins.utime_us, test::kStartUtime + 5'000'000);
}

// A bridge restarted mid-mission (kill -9, systemd restarts it) resumes the saved odometer; the
// samples it never saw (saved every second, 2 s down) count as the straight line between the
// saved position and the first new one, so distance travelled never goes back.
TEST(InsBridge, ResumedOdometerBridgesTheRestartAndNeverGoesBack) {
  InsBridge before(testOptions());
  const std::vector<NavSample> seen = feedAll(before, test::eastboundStream(31));  // 0..3 s: 6 m
  const OdometerState saved = before.odometer();
  EXPECT_NEAR(saved.distance_travelled_m, 6.0, 0.02);
  EXPECT_EQ(saved.utime_us, test::kStartUtime + 3'000'000);

  InsBridge after(testOptions());
  after.resumeOdometer(saved);
  std::string stream;
  for (int e = 51; e <= 60; ++e) stream += encodeInsState(test::eastboundState(e));  // 5.1..6 s
  const std::vector<NavSample> resumed = feedAll(after, stream);
  ASSERT_EQ(resumed.size(), 10u);
  EXPECT_NEAR(resumed.front().distance_travelled_m, 10.2, 0.02);  // 6 m + the 4.2 m gap
  EXPECT_NEAR(resumed.back().distance_travelled_m, 12.0, 0.02);   // as if never restarted
  EXPECT_GT(resumed.front().distance_travelled_m, seen.back().distance_travelled_m);

  // Saved long ago (another dive): the distance carries on, the gap adds nothing.
  InsBridgeOptions options = testOptions();
  options.odometer_max_bridged_gap_s = 1.0;
  InsBridge later(options);
  later.resumeOdometer(saved);
  const std::vector<NavSample> next_dive = feedAll(later, stream);
  ASSERT_EQ(next_dive.size(), 10u);
  EXPECT_NEAR(next_dive.front().distance_travelled_m, 6.0, 0.02);
  EXPECT_NEAR(next_dive.back().distance_travelled_m, 7.8, 0.02);
}

TEST(InsBridge, OlderOrRepeatedEpochIsDroppedAndCounted) {
  InsBridge bridge(testOptions());
  std::string stream = encodeInsState(test::eastboundState(0)) + encodeInsState(test::eastboundState(2)) +
                       encodeInsState(test::eastboundState(1)) + encodeInsState(test::eastboundState(3));
  const std::vector<NavSample> samples = feedAll(bridge, stream);
  ASSERT_EQ(samples.size(), 3u);
  EXPECT_EQ(bridge.epochsOutOfOrder(), 1u);
  EXPECT_EQ(samples[2].ins.utime_us, test::kStartUtime + 300'000);
}

TEST(InsBridge, SilentInsBecomesStaleAndRecovers) {
  InsBridge bridge(testOptions());
  feedAll(bridge, test::eastboundStream(10), 0);
  EXPECT_EQ(bridge.staleFlagsAt(500'000), 0u);
  // 1.5 s without data: heading (1 s timeout) is stale, position (5 s) not yet.
  const uint32_t stale = bridge.staleFlagsAt(1'500'000);
  EXPECT_TRUE(stale & kStaleHeading);
  EXPECT_FALSE(stale & kStalePosition);
  EXPECT_NE(bridge.describeStale(1'500'000).find("heading"), std::string::npos);
  EXPECT_TRUE(bridge.staleFlagsAt(7'000'000) & kStalePosition);
  // Data returns: clear again.
  std::string more;
  for (int e = 70; e < 72; ++e) more += encodeInsState(test::eastboundState(e));
  feedAll(bridge, more, 7'000'000);
  EXPECT_EQ(bridge.staleFlagsAt(7'050'000), 0u);
  EXPECT_TRUE(bridge.describeStale(7'050'000).empty());
}

TEST(InsBridge, CorruptSentencesAreCountedAndReportedOnce) {
  InsBridge bridge(testOptions());
  std::string stream = test::eastboundStream(5);
  stream[stream.find("ATITUD") + 8] ^= 0x01;  // checksum no longer matches
  stream.insert(stream.find("$PIXSE,POSITI"), "\x01\x02garbage");
  const std::vector<NavSample> samples = feedAll(bridge, stream);
  EXPECT_EQ(samples.size(), 5u);  // the epoch keeps the other quantities
  EXPECT_EQ(bridge.streamCounters().bad_checksum, 1);
  const auto faults = bridge.takeNewFaultMessages();
  EXPECT_GE(faults.size(), 2u);
  EXPECT_TRUE(bridge.takeNewFaultMessages().empty());
}

// No origin configured: the first valid fix is the origin, so the mission starts at (0, 0) in
// its own frame wherever on Earth it is; epochs before it have no position and no frame.
TEST(InsBridge, WithoutConfiguredOriginTheFirstFixIsTheOrigin) {
  std::string stream;
  ins::InsState null_island = test::eastboundState(1);  // what some INSs send before their first fix
  null_island.latitude_deg = 0.0;
  null_island.longitude_deg = 0.0;
  ins::InsState no_fix = test::eastboundState(0);
  no_fix.validity &= ~(kValidPosition | kValidDepth);  // heading, attitude, speed; no position yet
  no_fix.latitude_deg = 0.0;
  no_fix.longitude_deg = 0.0;
  stream += encodeInsState(no_fix);
  null_island.utime_us = no_fix.utime_us + 50'000;
  stream += encodeInsState(null_island);
  for (int e = 1; e <= 20; ++e) stream += encodeInsState(test::eastboundState(e));
  InsBridge bridge(InsBridgeOptions{});
  EXPECT_FALSE(bridge.origin());
  const std::vector<NavSample> samples = feedAll(bridge, stream);
  ASSERT_EQ(samples.size(), 22u);
  EXPECT_FALSE(samples[0].origin);
  EXPECT_FALSE(samples[1].origin);  // 0 N 0 E is not a fix
  const sss_msgs::nav_t before_fix = toNavMessage(samples[0], 0);
  EXPECT_TRUE(std::isnan(before_fix.origin_latitude_deg));
  EXPECT_EQ(before_fix.validity & sss_msgs::nav_t::VALID_POSITION, 0);
  ASSERT_TRUE(bridge.origin());
  EXPECT_EQ(bridge.originSource(), sss::core::OriginSource::kFirstFix);
  const ins::InsState first = test::eastboundState(1);
  // As the NMEA carried it (8 decimals).
  EXPECT_NEAR(bridge.origin()->latitude_deg, first.latitude_deg, 1e-8);
  EXPECT_NEAR(bridge.origin()->longitude_deg, first.longitude_deg, 1e-8);
  EXPECT_NEAR(samples[2].position_ned_m.head<2>().norm(), 0.0, 1e-6);
  EXPECT_NEAR(samples[2].position_ned_m.z(), 40.0, 0.002);  // depth stays absolute
  // 1.9 s later at 2 m/s east: 3.8 m east of the first fix (the configured frame says 10 m north too).
  EXPECT_NEAR(samples[21].position_ned_m.x(), 0.0, 0.005);
  EXPECT_NEAR(samples[21].position_ned_m.y(), 3.8, 0.005);
  EXPECT_NEAR(samples[21].distance_travelled_m, 3.8, 0.01);
  const sss_msgs::nav_t nav = toNavMessage(samples[21], 0);
  EXPECT_DOUBLE_EQ(nav.origin_latitude_deg, bridge.origin()->latitude_deg);
  EXPECT_DOUBLE_EQ(nav.origin_longitude_deg, bridge.origin()->longitude_deg);
}

// A configured origin is an override; a resumed one (state directory) is kept over the first fix.
TEST(InsBridge, ConfiguredOrResumedOriginIsKept) {
  InsBridge configured(testOptions());
  EXPECT_EQ(configured.originSource(), sss::core::OriginSource::kConfigured);
  configured.resumeOrigin({1.0, 2.0});  // ignored: the configuration wins
  EXPECT_DOUBLE_EQ(configured.origin()->latitude_deg, test::kOriginLatitudeDeg);

  InsBridge resumed(InsBridgeOptions{});
  resumed.resumeOrigin({test::kOriginLatitudeDeg, test::kOriginLongitudeDeg});
  const std::vector<NavSample> samples = feedAll(resumed, test::eastboundStream(5));
  EXPECT_EQ(resumed.originSource(), sss::core::OriginSource::kResumed);
  EXPECT_NEAR(samples.back().position_ned_m.x(), 10.0, 0.005);  // the earlier run's frame
  EXPECT_NEAR(samples.back().position_ned_m.y(), 0.8, 0.005);
}

TEST(NavMessage, CopiesFieldsAndMapsValidityBits) {
  InsBridge bridge(testOptions());
  const std::vector<NavSample> samples = feedAll(bridge, test::eastboundStream(3));
  const sss_msgs::nav_t nav = toNavMessage(samples[2], kStaleAltitude);
  EXPECT_EQ(nav.utime, test::kStartUtime + 200'000);
  EXPECT_NEAR(nav.heading_rad, M_PI / 2, 1e-4);
  EXPECT_NEAR(nav.altitude_m, 18.0, 1e-3);
  EXPECT_DOUBLE_EQ(nav.position_std_ned_m[0], samples[2].ins.latitude_std_m);
  const int32_t expected_valid = sss_msgs::nav_t::VALID_POSITION | sss_msgs::nav_t::VALID_ATTITUDE |
                                 sss_msgs::nav_t::VALID_HEADING | sss_msgs::nav_t::VALID_VELOCITY |
                                 sss_msgs::nav_t::VALID_DEPTH | sss_msgs::nav_t::VALID_ALTITUDE;
  EXPECT_EQ(nav.validity, expected_valid | sss_msgs::nav_t::STALE_ALTITUDE);
}

}  // namespace
}  // namespace sss::ins
