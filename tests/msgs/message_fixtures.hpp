// Filled-in instances of every LCM type, shared by the message tests.
#pragma once

#include "sss_msgs/loop_closure_t.hpp"
#include "sss_msgs/nav_t.hpp"
#include "sss_msgs/ping_t.hpp"
#include "sss_msgs/pose_t.hpp"
#include "sss_msgs/status_t.hpp"
#include "sss_msgs/subframe_t.hpp"
#include "sss_msgs/trajectory_t.hpp"

#include <cstdint>
#include <vector>

namespace sss::test {

inline sss_msgs::ping_t makePing(int samples_per_side) {
  sss_msgs::ping_t ping{};
  ping.utime = 1795300125123456LL;
  ping.ping_number = 4242;
  ping.sonar_utime = ping.utime - 250;
  ping.sound_speed_m_s = 1500.0f;
  ping.frequency_hz = 410000.0f;
  ping.sample_interval_s = 2.0e-5;
  ping.start_range_m = 0.0;
  ping.altitude_m = 18.2f;
  ping.num_port_samples = samples_per_side;
  ping.num_starboard_samples = samples_per_side;
  for (int i = 0; i < samples_per_side; ++i) {
    ping.port_intensity.push_back(static_cast<float>(i) * 0.5f);
    ping.starboard_intensity.push_back(static_cast<float>(samples_per_side - i));
  }
  ping.has_nav = true;
  ping.latitude_deg = 59.35;
  ping.longitude_deg = 18.07;
  ping.depth_m = 42.0;
  ping.heading_rad = 1.5;
  ping.flags = sss_msgs::ping_t::FLAG_SATURATED;
  return ping;
}

inline sss_msgs::nav_t makeNav() {
  sss_msgs::nav_t nav{};
  nav.utime = 1795300125000000LL;
  nav.latitude_deg = 59.35;
  nav.longitude_deg = 18.07;
  nav.depth_m = 40.0;
  nav.position_ned_m[0] = 100.0;
  nav.position_ned_m[1] = -50.0;
  nav.position_ned_m[2] = 40.0;
  nav.origin_latitude_deg = 59.349101;
  nav.origin_longitude_deg = 18.0717;
  nav.heading_rad = -2.0;
  nav.velocity_body_m_s[0] = 2.0;
  nav.altitude_m = 18.0;
  nav.distance_travelled_m = 1234.5;
  nav.position_std_ned_m[0] = 1.5;
  nav.attitude_std_rad[2] = 0.01;
  nav.validity = sss_msgs::nav_t::VALID_POSITION | sss_msgs::nav_t::VALID_HEADING;
  return nav;
}

// A subframe of num_pings x (2 * bins_per_side) pixels at 16 bits: 200 x 2 x 3000 is ~3.6 MB.
inline sss_msgs::subframe_t makeSubframe(int num_pings, int bins_per_side) {
  sss_msgs::subframe_t sf{};
  sf.utime = 1795300125000000LL;
  sf.subframe_id = 17;
  sf.line_id = 3;
  sf.num_pings = num_pings;
  sf.centre_ping_index = num_pings / 2;
  for (int i = 0; i < num_pings; ++i) {
    sf.ping_number.push_back(1000 + i);
    sf.ping_utime.push_back(sf.utime + i * 250000);
    sf.position_ned_m.push_back({0.5 * i, 1.0, 40.0});
    sf.orientation_wxyz.push_back({1.0, 0.0, 0.0, 0.0});
    sf.altitude_m.push_back(18.0f);
    sf.distance_travelled_m.push_back(0.5 * i);
  }
  sf.sonar_orientation_body_wxyz[0] = 1.0;
  sf.horizontal_beam_width_rad = 0.0035f;
  sf.vertical_beam_width_rad = 0.87f;
  sf.num_bins_per_side = bins_per_side;
  sf.bin_size_m = 0.1f;
  sf.intensity_bits = 16;
  sf.intensity_scale = 1.0f / 65535.0f;
  const size_t pixels = static_cast<size_t>(num_pings) * 2 * bins_per_side;
  sf.num_image_bytes = static_cast<int32_t>(pixels * 2);
  sf.image.resize(pixels * 2);
  for (size_t i = 0; i < sf.image.size(); ++i) sf.image[i] = static_cast<uint8_t>((i * 2654435761u) >> 24);
  sf.num_mask_bytes = static_cast<int32_t>(pixels);
  sf.mask.resize(pixels);
  for (size_t i = 0; i < pixels; ++i) sf.mask[i] = static_cast<uint8_t>(i % 6);
  return sf;
}

inline sss_msgs::loop_closure_t makeLoopClosure() {
  sss_msgs::loop_closure_t loop{};
  loop.utime = 1795300125000000LL;
  loop.subframe_id_a = 3;
  loop.subframe_id_b = 11;
  loop.translation_ab_m[0] = 1.0;
  loop.translation_ab_m[1] = 60.0;
  loop.rotation_ab_wxyz[0] = 0.0;
  loop.rotation_ab_wxyz[3] = 1.0;
  for (int i = 0; i < 6; ++i) loop.covariance[i][i] = 0.01 * (i + 1);
  loop.num_matches = 5000;
  loop.num_inliers = 4000;
  loop.total_cost = 12.5;
  loop.mean_zncc = 0.8f;
  loop.num_correspondences = 3;
  for (int i = 0; i < 3; ++i) {
    loop.ping_index_a.push_back(i);
    loop.column_a.push_back(100 + i);
    loop.ping_index_b.push_back(199 - i);
    loop.column_b.push_back(2000 - i);
    loop.slant_range_a_m.push_back(30.0f + i);
    loop.slant_range_b_m.push_back(40.0f + i);
    loop.landmark_a_m.push_back({1.0f * i, 25.0f, 18.0f});
  }
  return loop;
}

inline sss_msgs::pose_t makePose() {
  sss_msgs::pose_t pose{};
  pose.utime = 1795300125000000LL;
  pose.latitude_deg = 59.35;
  pose.orientation_wxyz[0] = 1.0;
  pose.covariance[5][5] = 1e-4;
  pose.correction_translation_m[1] = -2.5;
  pose.correction_heading_rad = 0.01;
  pose.status = sss_msgs::pose_t::STATUS_CORRECTED;
  return pose;
}

inline sss_msgs::trajectory_t makeTrajectory() {
  sss_msgs::trajectory_t trajectory{};
  trajectory.utime = 1795300125000000LL;
  trajectory.num_nodes = 2;
  trajectory.subframe_id = {1, 2};
  trajectory.node_utime = {10, 20};
  trajectory.position_ned_m = {{0, 0, 40}, {100, 0, 40}};
  trajectory.orientation_wxyz = {{1, 0, 0, 0}, {0, 0, 0, 1}};
  return trajectory;
}

inline sss_msgs::status_t makeStatus() {
  sss_msgs::status_t status{};
  status.utime = 1795300125000000LL;
  status.process = "sss-sonar-driver";
  status.pid = 1234;
  status.uptime_s = 12.5;
  status.state = sss_msgs::status_t::STATE_WARNING;
  status.state_text = "reconnecting";
  sss_msgs::channel_stats_t ch{};
  ch.channel = "SSS_PING";
  ch.outgoing = true;
  ch.messages = 100;
  ch.rate_hz = 4.0;
  ch.drops = 2;
  status.channels.push_back(ch);
  status.num_channels = 1;
  status.counter_name = {"reconnects", "clock_offset_s"};
  status.counter_value = {3.0, -0.25};
  status.num_counters = 2;
  status.errors_total = 5;
  status.last_error = "JSF message at byte 81920: bad start marker";
  return status;
}

template <typename Message>
std::vector<uint8_t> encode(const Message& message) {
  std::vector<uint8_t> bytes(static_cast<size_t>(message.getEncodedSize()));
  message.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

}  // namespace sss::test
