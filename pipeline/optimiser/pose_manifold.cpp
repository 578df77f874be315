// SE(3) manifold and marginalisation-prior cost for Ceres, see pose_manifold.hpp.
#include "pipeline/optimiser/pose_manifold.hpp"

#include <Eigen/Cholesky>
#include <cmath>

namespace sss::optimiser {

using sss::core::Matrix6d;
using sss::core::Pose;

namespace {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// d(q * [v/2, 1]) / dv at v = 0 for q stored as [x y z w]: the vector part is (w I + [q_v]x) v / 2,
// the scalar part -q_v . v / 2.
Eigen::Matrix<double, 4, 3> quaternionPlusJacobian(const double* q_xyzw) {
  const double x = q_xyzw[0], y = q_xyzw[1], z = q_xyzw[2], w = q_xyzw[3];
  Eigen::Matrix<double, 4, 3> j;
  j << w, -z, y,  //
      z, w, -x,   //
      -y, x, w,   //
      -x, -y, -z;
  return 0.5 * j;
}

}  // namespace

PoseParameters toParameters(const Pose& pose) {
  return {pose.translation.x(), pose.translation.y(), pose.translation.z(), pose.rotation.x(),
          pose.rotation.y(),    pose.rotation.z(),    pose.rotation.w()};
}

Pose fromParameters(const double* x) {
  Pose pose;
  pose.translation = Eigen::Vector3d(x[0], x[1], x[2]);
  pose.rotation.coeffs() = Eigen::Vector4d(x[3], x[4], x[5], x[6]);  // Eigen stores [x y z w]
  return pose;
}

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  Pose pose = fromParameters(x);
  sss::core::Vector6d d;
  for (int i = 0; i < 6; ++i) d(i) = delta[i];
  const Pose moved = sss::core::boxPlus(pose, d);  // normalises the quaternion
  const PoseParameters p = toParameters(moved);
  for (int i = 0; i < kPoseAmbientSize; ++i) x_plus_delta[i] = p[i];
  return true;
}

Eigen::Matrix<double, 7, 6> plusJacobian(const double* x) {
  Eigen::Matrix<double, 7, 6> j = Eigen::Matrix<double, 7, 6>::Zero();
  const Eigen::Quaterniond q(x[6], x[3], x[4], x[5]);
  j.topLeftCorner<3, 3>() = q.toRotationMatrix();
  j.bottomRightCorner<4, 3>() = quaternionPlusJacobian(x + 3);
  return j;
}

Eigen::Matrix<double, 6, 7> plusJacobianLeftInverse(const double* x) {
  // Columns of the quaternion block are orthogonal with norm 1/2, so its left inverse is 4 J^T.
  Eigen::Matrix<double, 6, 7> j = Eigen::Matrix<double, 6, 7>::Zero();
  const Eigen::Quaterniond q(x[6], x[3], x[4], x[5]);
  j.topLeftCorner<3, 3>() = q.toRotationMatrix().transpose();
  j.bottomRightCorner<3, 4>() = 4.0 * quaternionPlusJacobian(x + 3).transpose();
  return j;
}

bool PoseManifold::PlusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> j(jacobian);
  j = plusJacobian(x);
  return true;
}

bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const sss::core::Vector6d d = sss::core::boxMinus(fromParameters(y), fromParameters(x));
  for (int i = 0; i < 6; ++i) y_minus_x[i] = d(i);
  return true;
}

bool PoseManifold::MinusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> j(jacobian);
  j = plusJacobianLeftInverse(x);  // at y = x, d Minus / dy is the left inverse of d Plus / d delta
  return true;
}

Matrix6d adjoint(const Pose& T) {
  const Eigen::Matrix3d R = T.rotation.toRotationMatrix();
  Matrix6d ad = Matrix6d::Zero();
  ad.topLeftCorner<3, 3>() = R;
  ad.topRightCorner<3, 3>() = skew(T.translation) * R;
  ad.bottomRightCorner<3, 3>() = R;
  return ad;
}

Eigen::Matrix3d rightJacobianInverseSO3(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d phi_x = skew(phi);
  if (theta < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * phi_x + phi_x * phi_x / 12.0;
  const double coefficient = 1.0 / (theta * theta) - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  return Eigen::Matrix3d::Identity() + 0.5 * phi_x + coefficient * phi_x * phi_x;
}

bool sqrtInformation(const Matrix6d& covariance, Matrix6d& sqrt_information) {
  if (!covariance.allFinite()) return false;
  if (!(covariance - covariance.transpose()).isZero(1e-9 * (1.0 + covariance.cwiseAbs().maxCoeff()))) return false;
  const Matrix6d symmetric = 0.5 * (covariance + covariance.transpose());
  const Eigen::LLT<Matrix6d> llt(symmetric);
  if (llt.info() != Eigen::Success) return false;
  const Matrix6d L = llt.matrixL();
  if (!(L.diagonal().array() > 0.0).all()) return false;
  sqrt_information = L.triangularView<Eigen::Lower>().solve(Matrix6d::Identity());
  return sqrt_information.allFinite();
}

MarginalPriorCost::MarginalPriorCost(std::vector<Pose> linearisation_points, Eigen::MatrixXd jacobian,
                                     Eigen::VectorXd residual)
    : linearisation_points_(std::move(linearisation_points)),
      jacobian_(std::move(jacobian)),
      residual_(std::move(residual)) {
  set_num_residuals(static_cast<int>(residual_.size()));
  for (size_t i = 0; i < linearisation_points_.size(); ++i) mutable_parameter_block_sizes()->push_back(kPoseAmbientSize);
}

bool MarginalPriorCost::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const int k = static_cast<int>(linearisation_points_.size());
  const int rows = static_cast<int>(residual_.size());
  Eigen::VectorXd delta(6 * k);
  std::vector<Eigen::Matrix<double, 6, 7>> ambient(jacobians ? k : 0);
  for (int i = 0; i < k; ++i) {
    const Pose x = fromParameters(parameters[i]);
    const Pose& x_lin = linearisation_points_[i];
    delta.segment<6>(6 * i) = sss::core::boxMinus(x, x_lin);
    if (jacobians && jacobians[i]) {
      // d boxMinus(boxPlus(x, e), x_lin) / de, mapped to the ambient parameters through the left
      // inverse of the manifold's Plus Jacobian (Ceres multiplies back by PlusJacobian).
      Matrix6d tangent = Matrix6d::Zero();
      tangent.topLeftCorner<3, 3>() = (x_lin.rotation.conjugate() * x.rotation).toRotationMatrix();
      tangent.bottomRightCorner<3, 3>() = rightJacobianInverseSO3(delta.segment<3>(6 * i + 3));
      ambient[i] = tangent * plusJacobianLeftInverse(parameters[i]);
    }
  }
  Eigen::Map<Eigen::VectorXd> r(residuals, rows);
  r = residual_ + jacobian_ * delta;
  if (jacobians) {
    for (int i = 0; i < k; ++i) {
      if (!jacobians[i]) continue;
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor>> j(jacobians[i], rows, 7);
      j = jacobian_.middleCols<6>(6 * i) * ambient[i];
    }
  }
  return true;
}

}  // namespace sss::optimiser
