// The INS's drift rate from its reported position accuracy (pipeline/optimiser/ins_drift_estimator.hpp).
#include "pipeline/optimiser/ins_drift_estimator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace sss::optimiser {
namespace {

// An INS reporting 0.5 m at the start growing by 0.13 % of the distance: the rate once 300 m are
// behind it, nothing before.
TEST(InsDriftEstimator, ReadsTheGrowthOfTheReportedSigmaPerMetre) {
  InsDriftEstimator estimator;
  for (double d = 0.0; d < 299.0; d += 2.0) estimator.add(d, 0.5 + 0.0013 * d);
  EXPECT_FALSE(estimator.driftFraction());
  for (double d = 300.0; d <= 1000.0; d += 2.0) estimator.add(d, 0.5 + 0.0013 * d);
  ASSERT_TRUE(estimator.driftFraction());
  EXPECT_NEAR(*estimator.driftFraction(), 0.0013, 1e-9);
}

// A constant report (an aided INS, or one that reports a fixed figure) is not a dead-reckoning
// model: no rate. Reports without a value are ignored, not taken as a reset.
TEST(InsDriftEstimator, GivesNothingForAConstantOrMissingReport) {
  InsDriftEstimator estimator;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (double d = 0.0; d <= 2000.0; d += 5.0) {
    estimator.add(d, 1.0);
    estimator.add(d, 0.0);
    estimator.add(d, nan);
    estimator.add(nan, 1.0);
  }
  EXPECT_FALSE(estimator.driftFraction());
  EXPECT_EQ(estimator.reports(), 401);
}

// A GNSS fix at the surface drops the reported sigma: the rate before it is kept until the INS has
// drifted 300 m again, then the new stretch's rate replaces it. An odometer that goes back (the
// bridge restarted) starts a new stretch too.
TEST(InsDriftEstimator, StartsAgainAfterAnAidingOrAnOdometerReset) {
  InsDriftEstimator estimator;
  for (double d = 0.0; d <= 500.0; d += 1.0) estimator.add(d, 0.5 + 0.002 * d);
  ASSERT_TRUE(estimator.driftFraction());
  EXPECT_NEAR(*estimator.driftFraction(), 0.002, 1e-9);
  for (double d = 501.0; d <= 700.0; d += 1.0) estimator.add(d, 0.3 + 0.004 * (d - 501.0));
  EXPECT_NEAR(*estimator.driftFraction(), 0.002, 1e-9);  // 199 m since the fix: the old rate
  for (double d = 701.0; d <= 900.0; d += 1.0) estimator.add(d, 0.3 + 0.004 * (d - 501.0));
  EXPECT_NEAR(*estimator.driftFraction(), 0.004, 1e-9);
  // Odometer back to 0 with a sigma that keeps growing at 0.001 from there.
  const double sigma0 = 0.3 + 0.004 * 399.0;
  for (double d = 0.0; d <= 299.0; d += 1.0) estimator.add(d, sigma0 + 0.001 * d);
  EXPECT_NEAR(*estimator.driftFraction(), 0.004, 1e-9);
  for (double d = 300.0; d <= 400.0; d += 1.0) estimator.add(d, sigma0 + 0.001 * d);
  EXPECT_NEAR(*estimator.driftFraction(), 0.001, 1e-9);
}

TEST(InsDriftEstimator, ClampsToTheConfiguredRange) {
  InsDriftEstimatorOptions options;
  options.min_fraction = 0.0005;
  options.max_fraction = 0.02;
  InsDriftEstimator fast(options);
  for (double d = 0.0; d <= 400.0; d += 1.0) fast.add(d, 0.5 + 0.1 * d);
  EXPECT_DOUBLE_EQ(*fast.driftFraction(), 0.02);
  InsDriftEstimator slow(options);
  for (double d = 0.0; d <= 4000.0; d += 1.0) slow.add(d, 0.5 + 0.0001 * d);  // 0.4 m over 4 km
  EXPECT_DOUBLE_EQ(*slow.driftFraction(), 0.0005);
}

// Restored into an estimator with another range (the configuration changed since the checkpoint),
// the rate is clamped to the new range; a NaN or negative value is refused and changes nothing.
TEST(InsDriftEstimator, RestoresItsStateClampedAndRefusesBadValues) {
  InsDriftEstimator learnt;
  for (double d = 0.0; d <= 600.0; d += 2.0) learnt.add(d, 0.5 + 0.003 * d);
  InsDriftEstimatorOptions narrow;
  narrow.max_fraction = 0.002;
  InsDriftEstimator restored(narrow);
  ASSERT_TRUE(restored.restore(learnt.state()));
  EXPECT_DOUBLE_EQ(*restored.driftFraction(), 0.002);
  EXPECT_EQ(restored.reports(), learnt.reports());
  // The stretch goes on from where it was.
  InsDriftEstimator same;
  ASSERT_TRUE(same.restore(learnt.state()));
  for (double d = 602.0; d <= 900.0; d += 2.0) {
    learnt.add(d, 0.5 + 0.003 * d);
    same.add(d, 0.5 + 0.003 * d);
  }
  EXPECT_DOUBLE_EQ(*same.driftFraction(), *learnt.driftFraction());

  InsDriftState bad = learnt.state();
  bad.min_sigma_m = -0.1;
  EXPECT_FALSE(restored.restore(bad));
  bad = learnt.state();
  bad.estimate = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(restored.restore(bad));
  bad = learnt.state();
  bad.last_distance_m = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(restored.restore(bad));
  EXPECT_DOUBLE_EQ(*restored.driftFraction(), 0.002);
}

}  // namespace
}  // namespace sss::optimiser
