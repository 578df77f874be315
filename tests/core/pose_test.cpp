// Pose algebra identities and the NED/FRD Euler convention.
#include "pipeline/core/pose.hpp"

#include <gtest/gtest.h>

#include <random>

namespace sss::core {
namespace {

Pose randomPose(std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), half(-1.5, 1.5), metres(-100.0, 100.0);
  return Pose(quaternionFromEuler(angle(rng), half(rng), angle(rng)), Eigen::Vector3d(metres(rng), metres(rng), metres(rng)));
}

void expectPoseNear(const Pose& a, const Pose& b, double tolerance) {
  EXPECT_LT((a.translation - b.translation).norm(), tolerance);
  EXPECT_LT(a.rotation.angularDistance(b.rotation), tolerance);
}

TEST(Pose, InverseComposesToIdentity) {
  std::mt19937 rng(1);
  for (int i = 0; i < 100; ++i) {
    const Pose t = randomPose(rng);
    expectPoseNear(t * t.inverse(), Pose::identity(), 1e-12);
    expectPoseNear(t.inverse() * t, Pose::identity(), 1e-12);
  }
}

TEST(Pose, CompositionIsAssociativeAndMatchesMatrices) {
  std::mt19937 rng(2);
  for (int i = 0; i < 100; ++i) {
    const Pose a = randomPose(rng), b = randomPose(rng), c = randomPose(rng);
    expectPoseNear((a * b) * c, a * (b * c), 1e-9);
    EXPECT_TRUE(((a * b).matrix()).isApprox(a.matrix() * b.matrix(), 1e-12));
    const Eigen::Vector3d p(1.0, -2.0, 3.0);
    EXPECT_LT(((a * b) * p - a * (b * p)).norm(), 1e-9);
  }
}

TEST(Pose, BetweenGivesRelativePose) {
  std::mt19937 rng(3);
  const Pose a = randomPose(rng), b = randomPose(rng);
  expectPoseNear(a * between(a, b), b, 1e-9);
}

TEST(Pose, HeadingIsClockwiseFromNorthAboutDown) {
  // Heading 90 deg: the vehicle's forward axis points east (NED y).
  const Eigen::Quaterniond q = quaternionFromEuler(0.0, 0.0, M_PI / 2);
  EXPECT_LT((q * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  // Positive pitch raises the bow: forward gets a negative down component.
  const Eigen::Quaterniond pitch_up = quaternionFromEuler(0.0, 0.1, 0.0);
  EXPECT_LT((pitch_up * Eigen::Vector3d::UnitX()).z(), 0.0);
  // Positive roll lowers the starboard side: starboard (body y) gets a positive down component.
  const Eigen::Quaterniond roll_starboard = quaternionFromEuler(0.1, 0.0, 0.0);
  EXPECT_GT((roll_starboard * Eigen::Vector3d::UnitY()).z(), 0.0);
}

TEST(Pose, EulerRoundTrip) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> angle(-M_PI + 1e-6, M_PI), pitch(-1.5, 1.5);
  for (int i = 0; i < 1000; ++i) {
    const EulerAngles in{angle(rng), pitch(rng), angle(rng)};
    const EulerAngles out = eulerFromQuaternion(quaternionFromEuler(in));
    EXPECT_NEAR(wrapAngle(out.roll_rad - in.roll_rad), 0.0, 1e-9);
    EXPECT_NEAR(out.pitch_rad, in.pitch_rad, 1e-9);
    EXPECT_NEAR(wrapAngle(out.heading_rad - in.heading_rad), 0.0, 1e-9);
  }
}

TEST(Pose, EulerAtGimbalLockKeepsTheRotation) {
  const Eigen::Quaterniond q = quaternionFromEuler(0.3, M_PI / 2, 1.0);
  const EulerAngles e = eulerFromQuaternion(q);
  EXPECT_LT(quaternionFromEuler(e).angularDistance(q), 1e-6);
}

TEST(Pose, WrapAngleRange) {
  EXPECT_DOUBLE_EQ(wrapAngle(M_PI), M_PI);
  EXPECT_DOUBLE_EQ(wrapAngle(-M_PI), M_PI);
  EXPECT_NEAR(wrapAngle(3 * M_PI + 0.5), -M_PI + 0.5, 1e-12);
  EXPECT_NEAR(wrapAngle(-0.25), -0.25, 1e-15);
}

TEST(Pose, InterpolationEndpointsAndMidpoint) {
  const Pose a(quaternionFromEuler(0, 0, 0.0), Eigen::Vector3d(0, 0, 0));
  const Pose b(quaternionFromEuler(0, 0, 1.0), Eigen::Vector3d(10, -4, 2));
  expectPoseNear(interpolate(a, b, 0.0), a, 1e-12);
  expectPoseNear(interpolate(a, b, 1.0), b, 1e-12);
  const Pose mid = interpolate(a, b, 0.5);
  EXPECT_NEAR(eulerFromQuaternion(mid.rotation).heading_rad, 0.5, 1e-12);
  EXPECT_LT((mid.translation - Eigen::Vector3d(5, -2, 1)).norm(), 1e-12);
}

TEST(Pose, InterpolationAcrossHeadingWrapTakesTheShortWay) {
  const Pose a(quaternionFromEuler(0, 0, M_PI - 0.1), Eigen::Vector3d::Zero());
  const Pose b(quaternionFromEuler(0, 0, -M_PI + 0.1), Eigen::Vector3d::Zero());
  EXPECT_NEAR(std::abs(eulerFromQuaternion(interpolate(a, b, 0.5).rotation).heading_rad), M_PI, 1e-9);
}

TEST(Pose, ExpLogRoundTripIncludingTinyAngles) {
  for (const Eigen::Vector3d& v : {Eigen::Vector3d(0.3, -0.2, 1.1), Eigen::Vector3d(1e-12, 0, -2e-12),
                                  Eigen::Vector3d(0, 0, 3.0)}) {
    EXPECT_LT((logSO3(expSO3(v)) - v).norm(), 1e-12);
  }
}

TEST(Pose, BoxPlusMinusAreInverse) {
  std::mt19937 rng(5);
  for (int i = 0; i < 100; ++i) {
    const Pose a = randomPose(rng);
    Vector6d delta;
    delta << 0.5, -1.0, 2.0, 0.1, -0.2, 0.05;
    EXPECT_LT((boxMinus(boxPlus(a, delta), a) - delta).norm(), 1e-9);
    // The translation part of delta is in a's body frame.
    Vector6d forward = Vector6d::Zero();
    forward(0) = 1.0;
    EXPECT_LT((boxPlus(a, forward).translation - (a.translation + a.rotation * Eigen::Vector3d::UnitX())).norm(), 1e-12);
  }
}

}  // namespace
}  // namespace sss::core
