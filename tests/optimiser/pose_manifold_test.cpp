// The Ceres SE(3) manifold and the marginalisation-prior cost against numeric derivatives and the
// project's boxPlus/boxMinus convention.
#include "pipeline/optimiser/pose_manifold.hpp"

#include <ceres/manifold_test_utils.h>
#include <gtest/gtest.h>

#include <random>

namespace sss::optimiser {
namespace {

using sss::core::Matrix6d;
using sss::core::Pose;
using sss::core::Vector6d;

Pose randomPose(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Pose(sss::core::expSO3(Eigen::Vector3d(n(rng), n(rng), n(rng))),
              Eigen::Vector3d(10.0 * n(rng), 10.0 * n(rng), n(rng)));
}

TEST(PoseManifold, PlusAndMinusAreBoxPlusAndBoxMinus) {
  std::mt19937_64 rng(3);
  const PoseManifold manifold;
  for (int trial = 0; trial < 20; ++trial) {
    const Pose x = randomPose(rng);
    Vector6d delta;
    for (int i = 0; i < 6; ++i) delta(i) = 0.3 * std::normal_distribution<double>(0.0, 1.0)(rng);
    const PoseParameters px = toParameters(x);
    PoseParameters moved;
    ASSERT_TRUE(manifold.Plus(px.data(), delta.data(), moved.data()));
    const Pose expected = sss::core::boxPlus(x, delta);
    EXPECT_NEAR((fromParameters(moved.data()).translation - expected.translation).norm(), 0.0, 1e-12);
    EXPECT_NEAR(fromParameters(moved.data()).rotation.angularDistance(expected.rotation), 0.0, 1e-12);
    Vector6d back;
    ASSERT_TRUE(manifold.Minus(moved.data(), px.data(), back.data()));
    EXPECT_NEAR((back - delta).norm(), 0.0, 1e-10);
  }
}

// Ceres' own manifold invariants (Hertzberg et al.): Plus(x, 0) = x, Minus(x, x) = 0,
// Minus(Plus(x, d), x) = d, Plus(x, Minus(y, x)) = y, both Jacobians against numeric derivatives,
// MinusJacobian x PlusJacobian = I and RightMultiplyByPlusJacobian, at random poses. y is a
// perturbation of x so that both name the rotation by quaternions of the same sign.
TEST(PoseManifold, SatisfiesCeresManifoldInvariants) {
  using namespace ceres;  // the invariant macro names ceres' Vector and matchers unqualified
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  const PoseManifold manifold;
  for (int trial = 0; trial < 10; ++trial) {
    const PoseParameters px = toParameters(randomPose(rng));
    Vector delta(6), step(6);
    for (int i = 0; i < 6; ++i) {
      delta(i) = 0.3 * normal(rng);
      step(i) = 0.3 * normal(rng);
    }
    PoseParameters py;
    ASSERT_TRUE(manifold.Plus(px.data(), step.data(), py.data()));
    const Vector x = Eigen::Map<const Eigen::Matrix<double, 7, 1>>(px.data());
    const Vector y = Eigen::Map<const Eigen::Matrix<double, 7, 1>>(py.data());
    const double tolerance = 1e-6;
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, tolerance);
  }
}

TEST(PoseManifold, PlusAndMinusJacobiansMatchNumericDerivatives) {
  std::mt19937_64 rng(5);
  const PoseManifold manifold;
  for (int trial = 0; trial < 10; ++trial) {
    const PoseParameters x = toParameters(randomPose(rng));
    Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus;
    Eigen::Matrix<double, 6, 7, Eigen::RowMajor> minus;
    ASSERT_TRUE(manifold.PlusJacobian(x.data(), plus.data()));
    ASSERT_TRUE(manifold.MinusJacobian(x.data(), minus.data()));
    const double h = 1e-7;
    for (int k = 0; k < 6; ++k) {
      Vector6d d = Vector6d::Zero();
      d(k) = h;
      PoseParameters up, down;
      manifold.Plus(x.data(), d.data(), up.data());
      d(k) = -h;
      manifold.Plus(x.data(), d.data(), down.data());
      for (int r = 0; r < 7; ++r) EXPECT_NEAR(plus(r, k), (up[r] - down[r]) / (2 * h), 1e-6) << r << "," << k;
    }
    // Minus(Plus(x, d), x) = d: the Jacobians are inverse on the tangent space.
    EXPECT_NEAR((minus * plus - Matrix6d::Identity()).norm(), 0.0, 1e-12);
  }
}

TEST(MarginalPriorCost, JacobianMatchesNumericDerivativeOnTheTangentSpace) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  const std::vector<Pose> lin = {randomPose(rng), randomPose(rng)};
  Eigen::MatrixXd j(9, 12);
  for (int r = 0; r < 9; ++r)
    for (int c = 0; c < 12; ++c) j(r, c) = n(rng);
  Eigen::VectorXd r0(9);
  for (int r = 0; r < 9; ++r) r0(r) = n(rng);
  const MarginalPriorCost cost(lin, j, r0);
  // Away from the linearisation point so that the SO(3) Jacobian terms matter.
  Vector6d d0, d1;
  for (int i = 0; i < 6; ++i) {
    d0(i) = 0.4 * n(rng);
    d1(i) = 0.4 * n(rng);
  }
  PoseParameters x0 = toParameters(sss::core::boxPlus(lin[0], d0));
  PoseParameters x1 = toParameters(sss::core::boxPlus(lin[1], d1));
  const double* parameters[2] = {x0.data(), x1.data()};
  Eigen::VectorXd residual(9);
  Eigen::Matrix<double, 9, 7, Eigen::RowMajor> j0, j1;
  double* jacobians[2] = {j0.data(), j1.data()};
  ASSERT_TRUE(cost.Evaluate(parameters, residual.data(), jacobians));
  Eigen::VectorXd expected_residual = r0;
  expected_residual += j.leftCols<6>() * d0 + j.rightCols<6>() * d1;
  EXPECT_NEAR((residual - expected_residual).norm(), 0.0, 1e-9);

  const Eigen::Matrix<double, 9, 6> tangent0 = j0 * plusJacobian(x0.data());
  const PoseManifold manifold;
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    Vector6d e = Vector6d::Zero();
    e(k) = h;
    PoseParameters up, down;
    manifold.Plus(x0.data(), e.data(), up.data());
    e(k) = -h;
    manifold.Plus(x0.data(), e.data(), down.data());
    Eigen::VectorXd r_up(9), r_down(9);
    const double* p_up[2] = {up.data(), x1.data()};
    const double* p_down[2] = {down.data(), x1.data()};
    cost.Evaluate(p_up, r_up.data(), nullptr);
    cost.Evaluate(p_down, r_down.data(), nullptr);
    EXPECT_NEAR((tangent0.col(k) - (r_up - r_down) / (2 * h)).norm(), 0.0, 1e-6) << k;
  }
}

TEST(PoseManifoldAdjoint, MovesARightPerturbationThroughAProduct) {
  std::mt19937_64 rng(11);
  const Pose a = randomPose(rng), b = randomPose(rng);
  Vector6d d;
  d << 1e-6, -2e-6, 3e-6, 2e-6, 1e-6, -1e-6;
  // a * Exp(d) * b = a * b * Exp(Ad(b^-1) d)
  const Pose left = sss::core::boxPlus(a, d) * b;
  const Vector6d moved = sss::core::boxMinus(left, a * b);
  EXPECT_NEAR((moved - adjoint(b.inverse()) * d).norm(), 0.0, 1e-10);
}

TEST(PoseManifoldSqrtInformation, WhitensAndRefusesBadCovariances) {
  Matrix6d covariance = Matrix6d::Identity();
  covariance(0, 0) = 4.0;
  covariance(0, 1) = covariance(1, 0) = 0.5;
  Matrix6d w;
  ASSERT_TRUE(sqrtInformation(covariance, w));
  EXPECT_NEAR((w.transpose() * w - covariance.inverse()).norm(), 0.0, 1e-12);
  Matrix6d singular = Matrix6d::Identity();
  singular(5, 5) = 0.0;
  EXPECT_FALSE(sqrtInformation(singular, w));
  Matrix6d not_finite = Matrix6d::Identity();
  not_finite(2, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(sqrtInformation(not_finite, w));
  Matrix6d asymmetric = Matrix6d::Identity();
  asymmetric(0, 3) = 0.5;
  EXPECT_FALSE(sqrtInformation(asymmetric, w));
}

}  // namespace
}  // namespace sss::optimiser
