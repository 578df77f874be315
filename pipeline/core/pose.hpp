// SE(3) poses on Eigen: composition, inverse, interpolation, Euler angles and tangent-space maps.
// Conventions (README: Architecture): world = local NED, body = FRD; T_a_b maps b-frame coordinates into a.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace sss::core {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// A rigid transform T_a_b: p_a = rotation * p_b + translation.
struct Pose {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Pose() = default;
  Pose(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) : rotation(q.normalized()), translation(t) {}

  static Pose identity() { return Pose(); }

  // T_a_c = T_a_b * T_b_c
  Pose operator*(const Pose& other) const {
    return Pose(rotation * other.rotation, rotation * other.translation + translation);
  }
  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const { return rotation * point + translation; }

  Pose inverse() const {
    const Eigen::Quaterniond inverse_rotation = rotation.conjugate();
    return Pose(inverse_rotation, -(inverse_rotation * translation));
  }

  Eigen::Matrix4d matrix() const;
};

// Euler angles in the aerospace/marine convention: yaw (heading, clockwise from north about down),
// then pitch (bow up positive, about the new starboard axis), then roll (starboard down positive,
// about the new forward axis): R_world_body = Rz(heading) * Ry(pitch) * Rx(roll).
struct EulerAngles {
  double roll_rad = 0.0;
  double pitch_rad = 0.0;
  double heading_rad = 0.0;
};

Eigen::Quaterniond quaternionFromEuler(double roll_rad, double pitch_rad, double heading_rad);
Eigen::Quaterniond quaternionFromEuler(const EulerAngles& euler);
// Inverse of quaternionFromEuler; pitch in [-pi/2, pi/2], roll and heading in (-pi, pi].
EulerAngles eulerFromQuaternion(const Eigen::Quaterniond& q);

// Wraps an angle to (-pi, pi].
double wrapAngle(double angle_rad);

// Interpolates between a (alpha = 0) and b (alpha = 1): slerp for rotation, linear translation.
Pose interpolate(const Pose& a, const Pose& b, double alpha);

// SO(3) exponential and logarithm (rotation vector <-> quaternion).
Eigen::Quaterniond expSO3(const Eigen::Vector3d& rotation_vector);
Eigen::Vector3d logSO3(const Eigen::Quaterniond& q);

// Tangent space used for every pose covariance in sss-slam: delta = [dt (3), dr (3)],
// T = boxPlus(T_hat, delta) with t = t_hat + R_hat * dt and R = R_hat * Exp(dr): a perturbation
// in the pose's own (body) frame, translation first.
Pose boxPlus(const Pose& pose, const Vector6d& delta);
// The delta with boxPlus(a, delta) == b.
Vector6d boxMinus(const Pose& b, const Pose& a);

// Relative pose a^-1 * b: where b lies in a's frame.
inline Pose between(const Pose& a, const Pose& b) { return a.inverse() * b; }

}  // namespace sss::core
