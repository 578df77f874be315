// SE(3) pose helpers, see pose.hpp for conventions.
#include "pipeline/core/pose.hpp"

#include <algorithm>
#include <cmath>

namespace sss::core {

Eigen::Matrix4d Pose::matrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation.toRotationMatrix();
  m.topRightCorner<3, 1>() = translation;
  return m;
}

Eigen::Quaterniond quaternionFromEuler(double roll_rad, double pitch_rad, double heading_rad) {
  const Eigen::Quaterniond q = Eigen::AngleAxisd(heading_rad, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX());
  return q.normalized();
}

Eigen::Quaterniond quaternionFromEuler(const EulerAngles& euler) {
  return quaternionFromEuler(euler.roll_rad, euler.pitch_rad, euler.heading_rad);
}

EulerAngles eulerFromQuaternion(const Eigen::Quaterniond& q) {
  // Closed form for R = Rz(h) Ry(p) Rx(r); Eigen's eulerAngles() picks other branches.
  const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
  EulerAngles euler;
  euler.pitch_rad = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  if (std::abs(r(2, 0)) < 1.0 - 1e-12) {
    euler.roll_rad = std::atan2(r(2, 1), r(2, 2));
    euler.heading_rad = std::atan2(r(1, 0), r(0, 0));
  } else {
    // Gimbal lock (pitch = +-90 deg): only heading - roll or heading + roll is defined; keep roll 0.
    euler.roll_rad = 0.0;
    euler.heading_rad = std::atan2(-r(0, 1), r(1, 1));
  }
  euler.roll_rad = wrapAngle(euler.roll_rad);
  euler.heading_rad = wrapAngle(euler.heading_rad);
  return euler;
}

double wrapAngle(double angle_rad) {
  double wrapped = std::remainder(angle_rad, 2.0 * M_PI);  // in [-pi, pi]
  if (wrapped <= -M_PI) wrapped += 2.0 * M_PI;
  return wrapped;
}

Pose interpolate(const Pose& a, const Pose& b, double alpha) {
  return Pose(a.rotation.slerp(alpha, b.rotation), (1.0 - alpha) * a.translation + alpha * b.translation);
}

Eigen::Quaterniond expSO3(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (angle < 1e-10) {
    // First-order expansion keeps the map smooth (and exact to rounding) near zero.
    Eigen::Quaterniond q(1.0, 0.5 * rotation_vector.x(), 0.5 * rotation_vector.y(), 0.5 * rotation_vector.z());
    return q.normalized();
  }
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, rotation_vector / angle));
}

Eigen::Vector3d logSO3(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // shortest rotation
  const Eigen::Vector3d v = q.vec();
  const double sin_half = v.norm();
  if (sin_half < 1e-10) return 2.0 * v;
  const double angle = 2.0 * std::atan2(sin_half, q.w());
  return v * (angle / sin_half);
}

Pose boxPlus(const Pose& pose, const Vector6d& delta) {
  return Pose(pose.rotation * expSO3(delta.tail<3>()), pose.translation + pose.rotation * delta.head<3>());
}

Vector6d boxMinus(const Pose& b, const Pose& a) {
  Vector6d delta;
  delta.head<3>() = a.rotation.conjugate() * (b.translation - a.translation);
  delta.tail<3>() = logSO3(a.rotation.conjugate() * b.rotation);
  return delta;
}

}  // namespace sss::core
