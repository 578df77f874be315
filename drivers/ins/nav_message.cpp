// NavSample -> nav_t, see nav_message.hpp.
#include "drivers/ins/nav_message.hpp"

#include <limits>

namespace sss::ins {

sss_msgs::nav_t toNavMessage(const NavSample& sample, uint32_t extra_stale) {
  const InsState& s = sample.ins;
  sss_msgs::nav_t nav{};
  nav.utime = s.utime_us;
  nav.latitude_deg = s.latitude_deg;
  nav.longitude_deg = s.longitude_deg;
  nav.depth_m = s.depth_m;
  for (int i = 0; i < 3; ++i) {
    nav.position_ned_m[i] = sample.position_ned_m[i];
    nav.velocity_body_m_s[i] = sample.velocity_body_m_s[i];
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  nav.origin_latitude_deg = sample.origin ? sample.origin->latitude_deg : nan;
  nav.origin_longitude_deg = sample.origin ? sample.origin->longitude_deg : nan;
  nav.roll_rad = s.roll_rad;
  nav.pitch_rad = s.pitch_rad;
  nav.heading_rad = s.heading_rad;
  nav.altitude_m = s.altitude_m;
  nav.distance_travelled_m = sample.distance_travelled_m;
  nav.position_std_ned_m[0] = s.latitude_std_m;
  nav.position_std_ned_m[1] = s.longitude_std_m;
  nav.position_std_ned_m[2] = s.depth_std_m;
  nav.attitude_std_rad[0] = s.roll_std_rad;
  nav.attitude_std_rad[1] = s.pitch_std_rad;
  nav.attitude_std_rad[2] = s.heading_std_rad;
  nav.velocity_std_m_s[0] = s.velocity_north_std_m_s;
  nav.velocity_std_m_s[1] = s.velocity_east_std_m_s;
  nav.velocity_std_m_s[2] = s.velocity_down_std_m_s;
  nav.altitude_std_m = s.altitude_std_m;
  // The low validity bits of InsState are defined equal to nav_t's VALID_*/STALE_* bits.
  const uint32_t stale = (s.validity | extra_stale) &
                         (kStalePosition | kStaleHeading | kStaleVelocity | kStaleAltitude);
  const uint32_t valid = s.validity & (kValidPosition | kValidAttitude | kValidHeading | kValidVelocity |
                                       kValidDepth | kValidAltitude);
  nav.validity = static_cast<int32_t>(valid | stale);
  return nav;
}

static_assert(kValidPosition == static_cast<uint32_t>(sss_msgs::nav_t::VALID_POSITION) &&
                  kValidAltitude == static_cast<uint32_t>(sss_msgs::nav_t::VALID_ALTITUDE) &&
                  kStalePosition == static_cast<uint32_t>(sss_msgs::nav_t::STALE_POSITION) &&
                  kStaleAltitude == static_cast<uint32_t>(sss_msgs::nav_t::STALE_ALTITUDE),
              "InsState validity bits must match nav_t");

}  // namespace sss::ins
