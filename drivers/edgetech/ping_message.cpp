// DriverPing -> ping_t, see ping_message.hpp.
#include "drivers/edgetech/ping_message.hpp"

namespace sss::edgetech {

sss_msgs::ping_t toPingMessage(const DriverPing& driver_ping) {
  const AssembledPing& ping = driver_ping.ping;
  const SonarChannelRecord& any = ping.port ? *ping.port : *ping.starboard;
  sss_msgs::ping_t message{};
  message.utime = driver_ping.utime_us;
  message.sonar_utime = driver_ping.sonar_utime_us;
  message.ping_number = ping.ping_number;
  message.sound_speed_m_s = any.sound_speed_m_s;
  message.frequency_hz = 0.5f * (any.start_frequency_hz + any.end_frequency_hz);
  message.sample_interval_s = any.sample_interval_s;
  message.start_range_m = any.slantRangeM(0);
  message.altitude_m = (any.validity & kValidAltitude) ? static_cast<float>(any.altitude_m) : -1.0f;
  if (ping.port) message.port_intensity = ping.port->samples;
  if (ping.starboard) message.starboard_intensity = ping.starboard->samples;
  message.num_port_samples = static_cast<int32_t>(message.port_intensity.size());
  message.num_starboard_samples = static_cast<int32_t>(message.starboard_intensity.size());
  message.has_nav = (any.validity & kValidLatLon) != 0;
  message.latitude_deg = any.latitude_deg;
  message.longitude_deg = any.longitude_deg;
  message.depth_m = any.depth_m;
  message.roll_rad = any.roll_rad;
  message.pitch_rad = any.pitch_rad;
  message.heading_rad = any.heading_rad;
  message.flags = (ping.port ? 0 : sss_msgs::ping_t::FLAG_PORT_MISSING) |
                  (ping.starboard ? 0 : sss_msgs::ping_t::FLAG_STARBOARD_MISSING);
  return message;
}

}  // namespace sss::edgetech
