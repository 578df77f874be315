// See pose_message.hpp.
#include "pipeline/optimiser/pose_message.hpp"

#include <cmath>

namespace sss::optimiser {

using sss::core::Pose;

sss_msgs::pose_t toPoseMessage(int64_t utime_us, const Pose& T_world_body_dr, const Correction& correction,
                               const sss::core::LocalTangentPlane& plane) {
  sss_msgs::pose_t message{};
  message.utime = utime_us;
  const Pose corrected = correction.T_corrected_dr * T_world_body_dr;
  const sss::core::GeodeticPosition geodetic = plane.toGeodetic(corrected.translation);
  message.latitude_deg = geodetic.latitude_deg;
  message.longitude_deg = geodetic.longitude_deg;
  message.depth_m = corrected.translation.z();
  for (int i = 0; i < 3; ++i) message.position_ned_m[i] = corrected.translation[i];
  const Eigen::Quaterniond& q = corrected.rotation;
  message.orientation_wxyz[0] = q.w();
  message.orientation_wxyz[1] = q.x();
  message.orientation_wxyz[2] = q.y();
  message.orientation_wxyz[3] = q.z();
  const sss::core::EulerAngles euler = sss::core::eulerFromQuaternion(q);
  message.roll_rad = euler.roll_rad;
  message.pitch_rad = euler.pitch_rad;
  message.heading_rad = euler.heading_rad;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) message.covariance[r][c] = correction.covariance(r, c);
  // The correction as the vehicle applies it: position offset and heading offset of this sample.
  const Eigen::Vector3d offset = corrected.translation - T_world_body_dr.translation;
  for (int i = 0; i < 3; ++i) message.correction_translation_m[i] = offset[i];
  message.correction_heading_rad =
      sss::core::wrapAngle(euler.heading_rad - sss::core::eulerFromQuaternion(T_world_body_dr.rotation).heading_rad);
  message.correction_utime = correction.update_utime_us;
  switch (correction.status) {
    case CorrectionStatus::kDrOnly: message.status = sss_msgs::pose_t::STATUS_DR_ONLY; break;
    case CorrectionStatus::kCorrected: message.status = sss_msgs::pose_t::STATUS_CORRECTED; break;
    case CorrectionStatus::kDegraded: message.status = sss_msgs::pose_t::STATUS_DEGRADED; break;
  }
  return message;
}

sss_dds_NavigationCorrection toDdsCorrection(const sss_msgs::pose_t& pose, uint32_t vehicle_id, int accepted_closures) {
  sss_dds_NavigationCorrection sample{};
  sample.vehicle_id = vehicle_id;
  sample.utime_us = pose.utime;
  sample.latitude_deg = pose.latitude_deg;
  sample.longitude_deg = pose.longitude_deg;
  sample.depth_m = pose.depth_m;
  sample.roll_rad = pose.roll_rad;
  sample.pitch_rad = pose.pitch_rad;
  sample.heading_rad = pose.heading_rad;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) sample.covariance[r * 6 + c] = pose.covariance[r][c];
  sample.correction_north_m = pose.correction_translation_m[0];
  sample.correction_east_m = pose.correction_translation_m[1];
  sample.correction_down_m = pose.correction_translation_m[2];
  sample.correction_heading_rad = pose.correction_heading_rad;
  switch (pose.status) {
    case sss_msgs::pose_t::STATUS_CORRECTED: sample.status = sss_dds_CORRECTED; break;
    case sss_msgs::pose_t::STATUS_DEGRADED: sample.status = sss_dds_DEGRADED; break;
    default: sample.status = sss_dds_DR_ONLY; break;
  }
  const double horizontal_sigma_m = std::sqrt(std::max(0.0, pose.covariance[0][0] + pose.covariance[1][1]));
  sample.quality = accepted_closures > 0 ? static_cast<float>(1.0 / (1.0 + horizontal_sigma_m)) : 0.0f;
  sample.num_loop_closures = static_cast<uint32_t>(std::max(accepted_closures, 0));
  sample.correction_utime_us = pose.correction_utime;
  return sample;
}

}  // namespace sss::optimiser
