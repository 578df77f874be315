// CorrectionSlew: the published correction follows the graph's at a bounded rate, says how far it
// still has to go (covariance, lag) and reports each jump once.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "pipeline/optimiser/correction_slew.hpp"

namespace sss::optimiser {
namespace {

Correction shift(double north_m, double heading_rad = 0.0) {
  Correction c;
  c.T_corrected_dr = sss::core::Pose(Eigen::Quaterniond(Eigen::AngleAxisd(heading_rad, Eigen::Vector3d::UnitZ())),
                                     Eigen::Vector3d(north_m, 0.0, 0.0));
  c.covariance = 0.01 * sss::core::Matrix6d::Identity();
  c.status = CorrectionStatus::kCorrected;
  return c;
}

constexpr int64_t kT0 = 1780300800000000;

TEST(CorrectionSlew, AJumpIsFollowedAtTheBoundedRate) {
  CorrectionSlewOptions options;
  options.max_rate_m_s = 0.5;
  CorrectionSlew slew(options);
  EXPECT_EQ(slew.apply(shift(1.0), kT0).T_corrected_dr.translation.x(), 1.0);  // the first is taken as it is
  EXPECT_FALSE(slew.takeNewJump());
  // A fix moves the graph's correction by 3 m: 0.05 m per 0.1 s, there after 6 s.
  int64_t t = kT0;
  Correction out;
  for (int step = 1; step <= 30; ++step) {
    t += 100000;
    out = slew.apply(shift(4.0), t);
    EXPECT_NEAR(out.T_corrected_dr.translation.x(), 1.0 + 0.05 * step, 1e-9) << step;
  }
  EXPECT_NEAR(slew.lagM(), 1.5, 1e-9);
  EXPECT_NEAR(out.covariance(0, 0), 0.01 + 1.5 * 1.5, 1e-9) << "what is left widens the covariance";
  EXPECT_NEAR(out.covariance(5, 5), 0.01, 1e-12);
  const std::optional<double> jump = slew.takeNewJump();
  ASSERT_TRUE(jump);
  EXPECT_NEAR(*jump, 3.0, 1e-12);
  EXPECT_FALSE(slew.takeNewJump()) << "one report per jump";
  EXPECT_EQ(slew.jumps(), 1u);
  for (int step = 0; step < 40; ++step) out = slew.apply(shift(4.0), t += 100000);
  EXPECT_EQ(out.T_corrected_dr.translation.x(), 4.0);
  EXPECT_EQ(slew.lagM(), 0.0);
  EXPECT_EQ(out.status, CorrectionStatus::kCorrected);
}

TEST(CorrectionSlew, HeadingIsBoundedToo) {
  CorrectionSlewOptions options;
  options.max_heading_rate_rad_s = 0.01;
  CorrectionSlew slew(options);
  slew.apply(shift(0.0), kT0);
  const Correction out = slew.apply(shift(0.0, 0.05), kT0 + 1000000);  // 0.05 rad in 1 s: 0.01 allowed
  EXPECT_NEAR(Eigen::AngleAxisd(out.T_corrected_dr.rotation).angle(), 0.01, 1e-9);
  EXPECT_NEAR(slew.lagHeadingRad(), 0.04, 1e-9);
  EXPECT_NEAR(out.covariance(5, 5), 0.01 + 0.04 * 0.04, 1e-9);
}

TEST(CorrectionSlew, NoBoundOrTimeGoingBackTakesTheTarget) {
  CorrectionSlewOptions unbounded;
  unbounded.max_rate_m_s = 0.0;
  CorrectionSlew slew(unbounded);
  slew.apply(shift(0.0), kT0);
  EXPECT_EQ(slew.apply(shift(5.0), kT0 + 1000).T_corrected_dr.translation.x(), 5.0);
  CorrectionSlew bounded;
  bounded.apply(shift(0.0), kT0);
  EXPECT_EQ(bounded.apply(shift(5.0), kT0 - 1000).T_corrected_dr.translation.x(), 5.0);  // a replay restarted
  CorrectionSlewOptions bad;
  bad.max_rate_m_s = -1.0;
  bad.report_jump_m = 0.0;
  EXPECT_EQ(validateCorrectionSlewOptions(bad).size(), 2u);
}

}  // namespace
}  // namespace sss::optimiser
