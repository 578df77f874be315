// SSS_NAV -> NavSample: the fields the stages use, including the INS's own position accuracy
// (the first node's anchor), with unreported or invalid accuracies read as "not reported".
#include "pipeline/messages/sensor_messages.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace sss::messages {
namespace {

sss_msgs::nav_t navMessage() {
  sss_msgs::nav_t m{};
  m.utime = 1'700'000'000'000'000;
  m.position_ned_m[0] = 12.5;
  m.position_ned_m[1] = -3.25;
  m.position_ned_m[2] = 40.0;
  m.origin_latitude_deg = 59.35;
  m.origin_longitude_deg = 18.07;
  m.heading_rad = 1.5;
  m.altitude_m = 14.0;
  m.distance_travelled_m = 250.0;
  m.position_std_ned_m[0] = 2.5;
  m.position_std_ned_m[1] = 1.75;
  m.position_std_ned_m[2] = 0.1;
  m.validity = sss_msgs::nav_t::VALID_POSITION | sss_msgs::nav_t::VALID_ALTITUDE;
  return m;
}

TEST(SensorMessages, NavCarriesPositionAltitudeAndTheInsPositionAccuracy) {
  const sss::core::NavSample nav = fromNavMessage(navMessage());
  EXPECT_EQ(nav.utime_us, 1'700'000'000'000'000);
  EXPECT_TRUE(nav.position_valid);
  ASSERT_TRUE(nav.origin.has_value());
  EXPECT_EQ(nav.position_ned_m, Eigen::Vector3d(12.5, -3.25, 40.0));
  EXPECT_TRUE(nav.altitude_valid);
  EXPECT_EQ(nav.altitude_m, 14.0);
  EXPECT_EQ(nav.distance_travelled_m, 250.0);
  EXPECT_EQ(nav.position_std_north_m, 2.5);
  EXPECT_EQ(nav.position_std_east_m, 1.75);
}

TEST(SensorMessages, UnreportedOrInvalidPositionAccuracyReadsAsNotReported) {
  for (const double bad : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    sss_msgs::nav_t m = navMessage();
    m.position_std_ned_m[0] = bad;
    m.position_std_ned_m[1] = bad;
    const sss::core::NavSample nav = fromNavMessage(m);
    EXPECT_EQ(nav.position_std_north_m, 0.0) << bad;
    EXPECT_EQ(nav.position_std_east_m, 0.0) << bad;
  }
}

TEST(SensorMessages, NavWithoutAnOriginHasNoPosition) {
  sss_msgs::nav_t m = navMessage();
  m.origin_latitude_deg = std::numeric_limits<double>::quiet_NaN();
  const sss::core::NavSample nav = fromNavMessage(m);
  EXPECT_FALSE(nav.position_valid);
  EXPECT_FALSE(nav.origin.has_value());
  m = navMessage();
  m.validity |= sss_msgs::nav_t::STALE_ALTITUDE;
  EXPECT_FALSE(fromNavMessage(m).altitude_valid);
}

}  // namespace
}  // namespace sss::messages
