// SE(3) for Ceres in the project's tangent convention (pose.hpp boxPlus: [dt, dr], perturbation in
// the pose's own frame), and the pose-graph residuals, so solver, covariances and priors agree.
#pragma once

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <vector>

#include "pipeline/core/pose.hpp"

namespace sss::optimiser {

// Parameter block of one pose: [tx ty tz qx qy qz qw] (translation first, like the tangent).
constexpr int kPoseAmbientSize = 7;
constexpr int kPoseTangentSize = 6;
using PoseParameters = std::array<double, kPoseAmbientSize>;

PoseParameters toParameters(const sss::core::Pose& pose);
// Copies the quaternion as stored (no re-normalisation), so a round trip is bit-exact.
sss::core::Pose fromParameters(const double* x);

// Plus(x, delta) = boxPlus(x, delta); Minus(y, x) = boxMinus(y, x). A custom manifold rather than
// EigenQuaternionManifold + Euclidean because Ceres' quaternion manifold perturbs on the left (world
// frame): with it every covariance and the marginalisation prior would need converting.
class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kPoseAmbientSize; }
  int TangentSize() const override { return kPoseTangentSize; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;  // 7x6 row-major at delta = 0
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;  // 6x7 row-major at y = x
};

// d Plus(x, delta) / d delta at delta = 0, and its left inverse (P^+ P = I for a unit quaternion).
Eigen::Matrix<double, 7, 6> plusJacobian(const double* x);
Eigen::Matrix<double, 6, 7> plusJacobianLeftInverse(const double* x);

// Adjoint in the [dt, dr] ordering: T * boxPlus(I, d) * T^-1 = boxPlus(I, adjoint(T) d) to first
// order, so a right perturbation of A in A*B moves to B's frame with adjoint(B^-1).
sss::core::Matrix6d adjoint(const sss::core::Pose& T);
// Inverse of the SO(3) right Jacobian: d Log(R Exp(e)) / d e = J_r^-1(Log(R)).
Eigen::Matrix3d rightJacobianInverseSO3(const Eigen::Vector3d& rotation_vector);

// Whitening matrix W with W^T W = covariance^-1 (W = L^-1, covariance = L L^T); false when the
// covariance is not symmetric positive definite or not finite.
bool sqrtInformation(const sss::core::Matrix6d& covariance, sss::core::Matrix6d& sqrt_information);

namespace detail {

// Log of a unit quaternion, shortest rotation, safe (and differentiable) at the identity.
template <typename T>
Eigen::Matrix<T, 3, 1> logQuaternion(const Eigen::Quaternion<T>& q) {
  T wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
  if (wxyz[0] < T(0)) {
    for (T& c : wxyz) c = -c;
  }
  Eigen::Matrix<T, 3, 1> angle_axis;
  ceres::QuaternionToAngleAxis(wxyz, angle_axis.data());
  return angle_axis;
}

// boxMinus(b, a) on templated poses.
template <typename T>
Eigen::Matrix<T, 6, 1> boxMinus(const Eigen::Matrix<T, 3, 1>& t_b, const Eigen::Quaternion<T>& q_b,
                                const Eigen::Matrix<T, 3, 1>& t_a, const Eigen::Quaternion<T>& q_a) {
  const Eigen::Quaternion<T> q_a_inverse = q_a.conjugate();
  Eigen::Matrix<T, 6, 1> e;
  e.template head<3>() = q_a_inverse * (t_b - t_a);
  e.template tail<3>() = logQuaternion<T>(q_a_inverse * q_b);
  return e;
}

}  // namespace detail

// Error of a relative pose measurement Z = T_a_b (odometry or loop closure):
// e = boxMinus(T_a^-1 T_b, Z), i.e. T_a^-1 T_b = boxPlus(Z, e), whitened by W (W^T W = Sigma^-1).
struct RelativePoseError {
  sss::core::Pose measured;
  sss::core::Matrix6d sqrt_information;

  template <typename T>
  bool operator()(const T* x_a, const T* x_b, T* residual) const {
    whitenedRelativeError<T>(x_a, x_b, measured.translation.cast<T>(), measured, sqrt_information, residual);
    return true;
  }

  // The residual of both functors: W boxMinus(T_a^-1 T_b, (R_Z, t_measured)).
  template <typename T>
  static void whitenedRelativeError(const T* x_a, const T* x_b, const Eigen::Matrix<T, 3, 1>& t_measured,
                                    const sss::core::Pose& measured, const sss::core::Matrix6d& sqrt_information,
                                    T* residual) {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_a(x_a), t_b(x_b);
    const Eigen::Map<const Eigen::Quaternion<T>> q_a(x_a + 3), q_b(x_b + 3);
    const Eigen::Quaternion<T> q_a_inverse = q_a.conjugate();
    const Eigen::Matrix<T, 3, 1> t_ab = q_a_inverse * (t_b - t_a);
    const Eigen::Quaternion<T> q_ab = q_a_inverse * q_b;
    const Eigen::Matrix<T, 6, 1> e = detail::boxMinus<T>(t_ab, q_ab, t_measured, measured.rotation.cast<T>());
    Eigen::Map<Eigen::Matrix<T, 6, 1>> whitened(residual);
    whitened = sqrt_information.cast<T>() * e;
  }

  static ceres::CostFunction* create(const sss::core::Pose& measured, const sss::core::Matrix6d& sqrt_information) {
    return new ceres::AutoDiffCostFunction<RelativePoseError, 6, kPoseAmbientSize, kPoseAmbientSize>(
        new RelativePoseError{measured, sqrt_information});
  }
};

// A loop closure whose measured B is moved along a fixed direction (A's frame) by a shared bias
// parameter b: e = boxMinus(T_a^-1 T_b, Z'), Z' = (R_Z, t_Z + b u). The separation bias of
// opposite-side closures (PoseGraphOptions::separation_bias_sigma_m).
struct BiasedRelativePoseError {
  sss::core::Pose measured;
  Eigen::Vector3d direction;
  sss::core::Matrix6d sqrt_information;

  template <typename T>
  bool operator()(const T* x_a, const T* x_b, const T* bias, T* residual) const {
    const Eigen::Matrix<T, 3, 1> t_measured = measured.translation.cast<T>() + bias[0] * direction.cast<T>();
    RelativePoseError::whitenedRelativeError<T>(x_a, x_b, t_measured, measured, sqrt_information, residual);
    return true;
  }

  static ceres::CostFunction* create(const sss::core::Pose& measured, const Eigen::Vector3d& direction,
                                     const sss::core::Matrix6d& sqrt_information) {
    return new ceres::AutoDiffCostFunction<BiasedRelativePoseError, 6, kPoseAmbientSize, kPoseAmbientSize, 1>(
        new BiasedRelativePoseError{measured, direction, sqrt_information});
  }
};

// The DR sensor calibration of the pose graph, one parameter block [s, b, a_c, a_s]: DVL scale factor
// s (DR's horizontal distance is (1 + s) times the true one) and the INS heading error
// e(psi) = b + a_c cos(psi) + a_s sin(psi) (the heading DR used minus the true heading).
constexpr int kCalibrationSize = 4;

// DR odometry predicted from the true poses with the calibration [s, b, a_c, a_s]. DR integrates
// (1 + s) times the distance along a heading off by e(psi), and its node attitudes are off by e too:
//   rotation:    R_dr_a^T R_dr_b = R_a^T Rz(e_b - e_a) R_b
//   translation: R_dr_a^T dp_dr ~= (1 + s) R_a^T [dp + J (a_c D_c + a_s D_s)]   (horizontal)
// with J the quarter turn in the north-east plane and D_c, D_s the DR path's moments between the
// nodes, D_c = integral of (cos psi - cos psi_a) dp (zero along a straight line; a turn between lines
// gives them, see PathMoments in pose_graph.cpp). A constant bias b cancels: it rotates both ends.
// The calibration is held (first form, the last estimate) or a parameter block (second).
struct CalibratedOdometryError {
  sss::core::Pose measured;
  sss::core::Matrix6d sqrt_information;
  Eigen::Vector2d moment_cos = Eigen::Vector2d::Zero();  // D_c, world north/east
  Eigen::Vector2d moment_sin = Eigen::Vector2d::Zero();  // D_s
  double heading_a_rad = 0.0;                             // DR headings of the two nodes
  double heading_b_rad = 0.0;
  Eigen::Vector3d held = Eigen::Vector3d::Zero();         // s, a_c, a_s

  template <typename T>
  bool evaluate(const T* x_a, const T* x_b, const T& scale, const T& a_c, const T& a_s, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_a(x_a), t_b(x_b);
    const Eigen::Map<const Eigen::Quaternion<T>> q_a(x_a + 3), q_b(x_b + 3);
    const Eigen::Quaternion<T> q_a_inverse = q_a.conjugate();
    // The heading error's sideways displacement of the DR path, world frame.
    const Eigen::Matrix<T, 2, 1> moment = a_c * moment_cos.cast<T>() + a_s * moment_sin.cast<T>();
    const Eigen::Matrix<T, 3, 1> sideways(-moment.y(), moment.x(), T(0));
    const Eigen::Matrix<T, 3, 1> t_ab = q_a_inverse * (t_b - t_a + sideways);
    const T delta_e = a_c * T(std::cos(heading_b_rad) - std::cos(heading_a_rad)) +
                      a_s * T(std::sin(heading_b_rad) - std::sin(heading_a_rad));
    const Eigen::Quaternion<T> q_delta_e(ceres::cos(delta_e / T(2)), T(0), T(0), ceres::sin(delta_e / T(2)));
    const Eigen::Quaternion<T> q_ab = q_a_inverse * q_delta_e * q_b;
    Eigen::Matrix<T, 3, 1> t_measured = measured.translation.cast<T>();
    t_measured.x() /= T(1) + scale;
    t_measured.y() /= T(1) + scale;
    const Eigen::Matrix<T, 6, 1> e = detail::boxMinus<T>(t_ab, q_ab, t_measured, measured.rotation.cast<T>());
    Eigen::Map<Eigen::Matrix<T, 6, 1>> whitened(residual);
    whitened = sqrt_information.cast<T>() * e;
    return true;
  }
  template <typename T>
  bool operator()(const T* x_a, const T* x_b, T* residual) const {
    return evaluate(x_a, x_b, T(held(0)), T(held(1)), T(held(2)), residual);
  }
  template <typename T>
  bool operator()(const T* x_a, const T* x_b, const T* calibration, T* residual) const {
    return evaluate(x_a, x_b, calibration[0], calibration[2], calibration[3], residual);
  }

  static ceres::CostFunction* createHeld(const CalibratedOdometryError& error) {
    return new ceres::AutoDiffCostFunction<CalibratedOdometryError, 6, kPoseAmbientSize, kPoseAmbientSize>(
        new CalibratedOdometryError(error));
  }
  static ceres::CostFunction* createEstimated(const CalibratedOdometryError& error) {
    return new ceres::AutoDiffCostFunction<CalibratedOdometryError, 6, kPoseAmbientSize, kPoseAmbientSize,
                                           kCalibrationSize>(new CalibratedOdometryError(error));
  }
};

// Error of an absolute pose prior: e = boxMinus(T, prior), whitened.
struct PosePriorError {
  sss::core::Pose prior;
  sss::core::Matrix6d sqrt_information;

  template <typename T>
  bool operator()(const T* x, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(x);
    const Eigen::Map<const Eigen::Quaternion<T>> q(x + 3);
    const Eigen::Matrix<T, 6, 1> e = detail::boxMinus<T>(Eigen::Matrix<T, 3, 1>(t), Eigen::Quaternion<T>(q),
                                                         prior.translation.cast<T>(), prior.rotation.cast<T>());
    Eigen::Map<Eigen::Matrix<T, 6, 1>> whitened(residual);
    whitened = sqrt_information.cast<T>() * e;
    return true;
  }

  static ceres::CostFunction* create(const sss::core::Pose& prior, const sss::core::Matrix6d& sqrt_information) {
    return new ceres::AutoDiffCostFunction<PosePriorError, 6, kPoseAmbientSize>(
        new PosePriorError{prior, sqrt_information});
  }
};

// The INS's absolute measurements of one node: depth (pressure sensor) and attitude (roll and pitch
// against gravity, heading from gyrocompassing), which do not drift with distance. Residual
// [(z - z_dr) / sigma_depth; Log(R_dr^T R) ./ (sigma_roll, sigma_pitch, sigma_heading)]; for a
// level vehicle the body-frame rotation error is (roll, pitch, heading) error. A zero weight
// switches a component off.
struct InsAbsoluteError {
  sss::core::Pose dr;
  Eigen::Vector4d weight;  // 1 / sigma of depth, roll, pitch, heading (0: not used)

  template <typename T>
  bool operator()(const T* x, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(x + 3);
    residual[0] = T(weight(0)) * (x[2] - T(dr.translation.z()));
    const Eigen::Matrix<T, 3, 1> rotation_error =
        detail::logQuaternion<T>(dr.rotation.conjugate().cast<T>() * Eigen::Quaternion<T>(q));
    for (int i = 0; i < 3; ++i) residual[1 + i] = T(weight(1 + i)) * rotation_error(i);
    return true;
  }

  static ceres::CostFunction* create(const sss::core::Pose& dr, const Eigen::Vector4d& weight) {
    return new ceres::AutoDiffCostFunction<InsAbsoluteError, 4, kPoseAmbientSize>(new InsAbsoluteError{dr, weight});
  }
};

// An absolute horizontal position fix of a point fixed in a node's body frame (the DR position at
// the fix time): e = W ((R p_body + t)_ne - fix_ne), W^T W = Sigma^-1 (2 x 2).
struct PositionFixError {
  Eigen::Vector3d p_body;
  Eigen::Vector2d fix_ne;
  Eigen::Matrix2d sqrt_information;

  template <typename T>
  bool operator()(const T* x, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(x);
    const Eigen::Map<const Eigen::Quaternion<T>> q(x + 3);
    const Eigen::Matrix<T, 3, 1> p_world = q * p_body.cast<T>() + t;
    Eigen::Map<Eigen::Matrix<T, 2, 1>> whitened(residual);
    whitened = sqrt_information.cast<T>() * (p_world.template head<2>() - fix_ne.cast<T>());
    return true;
  }

  static ceres::CostFunction* create(const Eigen::Vector3d& p_body, const Eigen::Vector2d& fix_ne,
                                     const Eigen::Matrix2d& sqrt_information) {
    return new ceres::AutoDiffCostFunction<PositionFixError, 2, kPoseAmbientSize>(
        new PositionFixError{p_body, fix_ne, sqrt_information});
  }
};

// InsAbsoluteError with the heading error model removed from the INS attitude: the INS says
// R_dr = Rz(e) R_true (heading about the world's down axis), so the residual rotation is
// Log(R_dr^T Rz(e) R). The calibration is held (first form) or a parameter block (second).
struct CalibratedInsAbsoluteError {
  sss::core::Pose dr;
  Eigen::Vector4d weight;
  double dr_heading_rad = 0.0;
  Eigen::Vector3d held = Eigen::Vector3d::Zero();  // b, a_c, a_s

  template <typename T>
  bool evaluate(const T* x, const T& b, const T& a_c, const T& a_s, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(x + 3);
    residual[0] = T(weight(0)) * (x[2] - T(dr.translation.z()));
    const T e = b + a_c * T(std::cos(dr_heading_rad)) + a_s * T(std::sin(dr_heading_rad));
    const Eigen::Quaternion<T> q_e(ceres::cos(e / T(2)), T(0), T(0), ceres::sin(e / T(2)));
    const Eigen::Matrix<T, 3, 1> rotation_error =
        detail::logQuaternion<T>(dr.rotation.conjugate().cast<T>() * q_e * Eigen::Quaternion<T>(q));
    for (int i = 0; i < 3; ++i) residual[1 + i] = T(weight(1 + i)) * rotation_error(i);
    return true;
  }
  template <typename T>
  bool operator()(const T* x, T* residual) const {
    return evaluate(x, T(held(0)), T(held(1)), T(held(2)), residual);
  }
  template <typename T>
  bool operator()(const T* x, const T* calibration, T* residual) const {
    return evaluate(x, calibration[1], calibration[2], calibration[3], residual);
  }

  static ceres::CostFunction* createHeld(const sss::core::Pose& dr, const Eigen::Vector4d& weight, double dr_heading_rad,
                                         const Eigen::Vector3d& heading_error) {
    return new ceres::AutoDiffCostFunction<CalibratedInsAbsoluteError, 4, kPoseAmbientSize>(
        new CalibratedInsAbsoluteError{dr, weight, dr_heading_rad, heading_error});
  }
  static ceres::CostFunction* createEstimated(const sss::core::Pose& dr, const Eigen::Vector4d& weight,
                                              double dr_heading_rad) {
    return new ceres::AutoDiffCostFunction<CalibratedInsAbsoluteError, 4, kPoseAmbientSize, kCalibrationSize>(
        new CalibratedInsAbsoluteError{dr, weight, dr_heading_rad, Eigen::Vector3d::Zero()});
  }
};

// The first node's anchor (PosePriorError) with the INS heading error removed from the DR attitude,
// the calibration a parameter block: e = boxMinus(T, (t_dr, Rz(-e(psi)) R_dr)).
struct CalibratedPosePriorError {
  sss::core::Pose prior;
  sss::core::Matrix6d sqrt_information;
  double dr_heading_rad = 0.0;

  template <typename T>
  bool operator()(const T* x, const T* calibration, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(x);
    const Eigen::Map<const Eigen::Quaternion<T>> q(x + 3);
    const T e = calibration[1] + calibration[2] * T(std::cos(dr_heading_rad)) + calibration[3] * T(std::sin(dr_heading_rad));
    const Eigen::Quaternion<T> q_minus_e(ceres::cos(e / T(2)), T(0), T(0), -ceres::sin(e / T(2)));
    const Eigen::Quaternion<T> prior_rotation = q_minus_e * prior.rotation.cast<T>();
    const Eigen::Matrix<T, 6, 1> error = detail::boxMinus<T>(Eigen::Matrix<T, 3, 1>(t), Eigen::Quaternion<T>(q),
                                                             prior.translation.cast<T>(), prior_rotation);
    Eigen::Map<Eigen::Matrix<T, 6, 1>> whitened(residual);
    whitened = sqrt_information.cast<T>() * error;
    return true;
  }

  static ceres::CostFunction* create(const sss::core::Pose& prior, const sss::core::Matrix6d& sqrt_information,
                                     double dr_heading_rad) {
    return new ceres::AutoDiffCostFunction<CalibratedPosePriorError, 6, kPoseAmbientSize, kCalibrationSize>(
        new CalibratedPosePriorError{prior, sqrt_information, dr_heading_rad});
  }
};

// The marginalisation prior: r = r0 + J [boxMinus(x_1, x_lin_1); ...; boxMinus(x_k, x_lin_k)],
// a Gaussian on the tangent spaces at the linearisation points (Schur complement, see pose_graph.cpp).
class MarginalPriorCost final : public ceres::CostFunction {
 public:
  MarginalPriorCost(std::vector<sss::core::Pose> linearisation_points, Eigen::MatrixXd jacobian,
                    Eigen::VectorXd residual);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  std::vector<sss::core::Pose> linearisation_points_;
  Eigen::MatrixXd jacobian_;  // rows x (6 * nodes)
  Eigen::VectorXd residual_;  // r0
};

}  // namespace sss::optimiser
