// LCM translation of subframes. See subframe_messages.hpp.
#include "pipeline/messages/subframe_messages.hpp"

#include <algorithm>
#include <cmath>

namespace sss::messages {

sss_msgs::subframe_t toSubframeMessage(const Subframe& subframe, int intensity_bits, double max_intensity,
                                       float horizontal_beam_width_rad, float vertical_beam_width_rad) {
  sss_msgs::subframe_t m{};
  const int rows = subframe.rows();
  m.utime = subframe.centre().utime_us;
  m.subframe_id = subframe.id;
  m.line_id = subframe.line_id;
  m.num_pings = rows;
  m.centre_ping_index = subframe.centre_ping_index;
  m.ping_number.resize(rows);
  m.ping_utime.resize(rows);
  m.position_ned_m.resize(rows);
  m.orientation_wxyz.resize(rows);
  m.altitude_m.resize(rows);
  m.distance_travelled_m.resize(rows);
  for (int r = 0; r < rows; ++r) {
    const SubframePing& p = subframe.pings[r];
    m.ping_number[r] = p.ping_number;
    m.ping_utime[r] = p.utime_us;
    m.position_ned_m[r] = {p.T_world_body.translation.x(), p.T_world_body.translation.y(),
                           p.T_world_body.translation.z()};
    const Eigen::Quaterniond& q = p.T_world_body.rotation;
    m.orientation_wxyz[r] = {q.w(), q.x(), q.y(), q.z()};
    m.altitude_m[r] = static_cast<float>(p.altitude_m);
    m.distance_travelled_m[r] = p.distance_travelled_m;
  }
  const sss::core::Pose& mount = subframe.geometry.T_body_sonar;
  for (int i = 0; i < 3; ++i) m.sonar_position_body_m[i] = mount.translation[i];
  m.sonar_orientation_body_wxyz[0] = mount.rotation.w();
  m.sonar_orientation_body_wxyz[1] = mount.rotation.x();
  m.sonar_orientation_body_wxyz[2] = mount.rotation.y();
  m.sonar_orientation_body_wxyz[3] = mount.rotation.z();
  m.horizontal_beam_width_rad = horizontal_beam_width_rad;
  m.vertical_beam_width_rad = vertical_beam_width_rad;
  m.num_bins_per_side = subframe.geometry.bins_per_side;
  m.bin_size_m = static_cast<float>(subframe.geometry.bin_size_m);
  m.first_bin_range_m = static_cast<float>(subframe.geometry.first_bin_range_m);
  m.intensity_bits = static_cast<int8_t>(intensity_bits);
  const double max_code = intensity_bits == 8 ? 255.0 : 65535.0;
  const double scale = max_intensity / max_code;
  m.intensity_scale = static_cast<float>(scale);
  const size_t pixels = subframe.image.size();
  const size_t bytes_per_pixel = intensity_bits == 8 ? 1 : 2;
  m.image.resize(pixels * bytes_per_pixel);
  for (size_t i = 0; i < pixels; ++i) {
    const uint32_t code = static_cast<uint32_t>(std::lround(std::clamp(subframe.image[i] / scale, 0.0, max_code)));
    if (bytes_per_pixel == 1) {
      m.image[i] = static_cast<uint8_t>(code);
    } else {
      m.image[2 * i] = static_cast<uint8_t>(code & 0xff);
      m.image[2 * i + 1] = static_cast<uint8_t>(code >> 8);
    }
  }
  m.num_image_bytes = static_cast<int32_t>(m.image.size());
  m.mask = subframe.mask;
  m.num_mask_bytes = static_cast<int32_t>(m.mask.size());
  return m;
}

Result<Subframe> fromSubframeMessage(const sss_msgs::subframe_t& m) {
  const int rows = m.num_pings;
  const size_t pixels = static_cast<size_t>(rows) * 2 * static_cast<size_t>(std::max(0, m.num_bins_per_side));
  const size_t bytes_per_pixel = m.intensity_bits == 8 ? 1 : 2;
  if (rows <= 0 || m.num_bins_per_side <= 0 || (m.intensity_bits != 8 && m.intensity_bits != 16) ||
      m.image.size() != pixels * bytes_per_pixel || m.mask.size() != pixels || m.centre_ping_index < 0 ||
      m.centre_ping_index >= rows) {
    return Status::error("subframe " + std::to_string(m.subframe_id) + ": inconsistent sizes (pings " +
                         std::to_string(rows) + ", bins per side " + std::to_string(m.num_bins_per_side) + ", bits " +
                         std::to_string(m.intensity_bits) + ", image bytes " + std::to_string(m.image.size()) +
                         ", mask bytes " + std::to_string(m.mask.size()) + ")");
  }
  Subframe subframe;
  subframe.id = m.subframe_id;
  subframe.line_id = m.line_id;
  subframe.centre_ping_index = m.centre_ping_index;
  subframe.geometry.bins_per_side = m.num_bins_per_side;
  subframe.geometry.bin_size_m = m.bin_size_m;
  subframe.geometry.first_bin_range_m = m.first_bin_range_m;
  subframe.geometry.T_body_sonar = sss::core::Pose(
      Eigen::Quaterniond(m.sonar_orientation_body_wxyz[0], m.sonar_orientation_body_wxyz[1],
                         m.sonar_orientation_body_wxyz[2], m.sonar_orientation_body_wxyz[3]),
      Eigen::Vector3d(m.sonar_position_body_m[0], m.sonar_position_body_m[1], m.sonar_position_body_m[2]));
  for (int r = 0; r < rows; ++r) {
    SubframePing p;
    p.utime_us = m.ping_utime[r];
    p.ping_number = m.ping_number[r];
    p.T_world_body = sss::core::Pose(Eigen::Quaterniond(m.orientation_wxyz[r][0], m.orientation_wxyz[r][1],
                                                        m.orientation_wxyz[r][2], m.orientation_wxyz[r][3]),
                                     Eigen::Vector3d(m.position_ned_m[r][0], m.position_ned_m[r][1], m.position_ned_m[r][2]));
    p.altitude_m = m.altitude_m[r];
    p.distance_travelled_m = m.distance_travelled_m[r];
    subframe.pings.push_back(p);
  }
  subframe.image.resize(pixels);
  for (size_t i = 0; i < pixels; ++i) {
    const uint32_t code = bytes_per_pixel == 1 ? m.image[i] : (m.image[2 * i] | (m.image[2 * i + 1] << 8));
    subframe.image[i] = static_cast<float>(code * static_cast<double>(m.intensity_scale));
  }
  subframe.mask = m.mask;
  return subframe;
}

}  // namespace sss::messages
