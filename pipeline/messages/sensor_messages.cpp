// LCM translation of pings and nav. See sensor_messages.hpp.
#include "pipeline/messages/sensor_messages.hpp"

#include <cmath>

namespace sss::messages {

using sss::core::NavSample;
using sss::core::PingSample;

PingSample fromPingMessage(const sss_msgs::ping_t& message, int64_t arrival_monotonic_us) {
  PingSample ping;
  ping.utime_us = message.utime;
  ping.ping_number = message.ping_number;
  ping.sound_speed_m_s = message.sound_speed_m_s;
  ping.sample_interval_s = message.sample_interval_s;
  ping.start_range_m = message.start_range_m;
  ping.altitude_m = message.altitude_m;
  if (!(message.flags & sss_msgs::ping_t::FLAG_PORT_MISSING)) ping.port = message.port_intensity;
  if (!(message.flags & sss_msgs::ping_t::FLAG_STARBOARD_MISSING)) ping.starboard = message.starboard_intensity;
  ping.arrival_monotonic_us = arrival_monotonic_us;
  return ping;
}

NavSample fromNavMessage(const sss_msgs::nav_t& message) {
  NavSample nav;
  nav.utime_us = message.utime;
  nav.position_ned_m = Eigen::Vector3d(message.position_ned_m[0], message.position_ned_m[1], message.position_ned_m[2]);
  // Before the INS's first fix the bridge has no frame (origin NaN) and no position to give.
  nav.position_valid = (message.validity & sss_msgs::nav_t::VALID_POSITION) != 0 &&
                       sss::core::isValidOrigin(message.origin_latitude_deg, message.origin_longitude_deg);
  if (nav.position_valid) nav.origin = sss::core::MissionOrigin{message.origin_latitude_deg, message.origin_longitude_deg};
  nav.roll_rad = message.roll_rad;
  nav.pitch_rad = message.pitch_rad;
  nav.heading_rad = message.heading_rad;
  nav.altitude_m = message.altitude_m;
  nav.altitude_valid = (message.validity & sss_msgs::nav_t::VALID_ALTITUDE) &&
                       !(message.validity & sss_msgs::nav_t::STALE_ALTITUDE);
  nav.distance_travelled_m = message.distance_travelled_m;
  auto reportedStd = [](double std_m) { return std::isfinite(std_m) && std_m > 0.0 ? std_m : 0.0; };
  nav.position_std_north_m = reportedStd(message.position_std_ned_m[0]);
  nav.position_std_east_m = reportedStd(message.position_std_ned_m[1]);
  return nav;
}

}  // namespace sss::messages
