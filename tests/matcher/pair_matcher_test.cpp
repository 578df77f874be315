// A subframe pair from a simulated survey, end to end: geo-referenced images, dense matching and
// relative pose against the simulator's ray-cast ground truth, for anti-parallel and parallel
// lines with 3 m along-track and 2 m lateral DR error added between them; wrong pairs rejected.
#include "pipeline/matcher/pair_matcher.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "pipeline/core/georeference.hpp"
#include "tests/matcher/matcher_test_survey.hpp"

namespace sss::matcher {
namespace {

using sss::core::Pose;

struct PairCase {
  const char* name;
  int line_a;
  int line_b;
  double dr_along_m = 3.0;  // DR error added between the two subframes
  double dr_lateral_m = 2.0;
};

void expectPairRecoversDrError(const PairCase& pair_case) {
  const auto& survey = test::threeLineSurvey();
  const auto* a = test::fullSubframeOfLine(survey, pair_case.line_a);
  const auto* b = test::fullSubframeOfLine(survey, pair_case.line_b);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  PairMatcherOptions options;
  const DenseMatcher dense(options.dense);
  const PairMatch match =
      matchPair(*a, sss::core::drPoses(*a), *b, sss::sim::posesWithDrError(*a, *b, pair_case.dr_along_m, pair_case.dr_lateral_m), dense, options);
  const test::MatchEvaluation e = test::evaluateMatches(survey, *a, *b, match.matches, options.dense.stride, match.decimation);
  const sss::sim::SubframeTruth truth(*survey.mission);
  const Pose T_true = truth.trueRelativePose(*a, *b);
  const Eigen::Vector3d error = match.pose.T_a_b.translation - T_true.translation;
  const Pose T_dr = sss::core::between(a->centre().T_world_body, sss::sim::posesWithDrError(*a, *b, pair_case.dr_along_m, pair_case.dr_lateral_m)[b->centre_ping_index]);
  const Eigen::Vector3d dr_error = T_dr.translation - T_true.translation;
  std::printf("%s: decimation %d, %ld matches (%ld with truth), within 2 px %.3f, recall %.3f, mean error %.2f px; DR error "
              "[%.2f %.2f %.2f] m -> estimate error [%.3f %.3f %.3f] m, sigma [%.3f %.3f] m, %d inliers, %s; "
              "%.2f s (georef %.2f, dense %.2f, pose %.2f)\n",
              pair_case.name, match.decimation, e.matches, e.evaluated, e.withinFraction(), e.recall(), e.meanErrorPx(), dr_error.x(),
              dr_error.y(), dr_error.z(), error.x(), error.y(), error.z(), std::sqrt(match.pose.covariance(0, 0)),
              std::sqrt(match.pose.covariance(1, 1)), match.pose.num_inliers,
              match.accepted ? "accepted" : match.reason.c_str(), match.seconds, match.georeference_s,
              match.dense_timings.total_s, match.pose.seconds);
  std::printf("  opposed relief: %ld matches marked, %d inliers, statistic %.2f, %s\n",
              match.dense_timings.shadowed_relief_marked, match.opposed_relief_inliers, match.opposed_relief_statistic,
              match.opposed_relief_replaced ? "pose without them published" : "pose from all kept");
  // Both pairs see the strip between their lines from opposite sides (parallel lines too: one
  // looks to starboard, the other to port), so features are marked on both; at 20-40 m out their
  // matches are not biased, and the test must keep the pose from all the matches.
  EXPECT_GT(match.opposed_relief_inliers, 0);
  EXPECT_GE(match.opposed_relief_statistic, 0.0);
  EXPECT_FALSE(match.opposed_relief_replaced);
  // The matcher's acceptance: >= 80 % of the returned matches within 2 px of the true match.
  // The pairs overlap by 50 m along track; at stride 2 on 0.5 m pixels a few hundred matches is
  // what a textured stretch gives: 474 anti-parallel, 1576 parallel (recall 0.16-0.31) before the
  // aperture check (min_structure_ratio 0.2), which drops patches of one straight feature on
  // purpose: 225 and 1279 after it (recall 0.095-0.22); 264 and 1842 (recall 0.11-0.34, within
  // 2 px 0.91 / 0.88) with the rectified-contrast pass merged in. The floor is set under those:
  // it catches a matcher that stops finding matches, not that trade of recall for precision.
  EXPECT_GT(e.evaluated, 200);
  EXPECT_GE(e.withinFraction(), 0.8);
  EXPECT_GT(e.recall(), 0.08);
  // The matcher's acceptance: relative translation within 0.3 m of the truth along and across track.
  ASSERT_TRUE(match.accepted) << match.reason;
  // The error to remove is really there.
  EXPECT_GT(dr_error.head<2>().norm(), 0.9 * std::hypot(pair_case.dr_along_m, pair_case.dr_lateral_m));
  EXPECT_LT(std::abs(error.x()), 0.3);
  EXPECT_LT(std::abs(error.y()), 0.3);
  // The published covariance: covariance_scale calibrates the matches' model, the seabed relief
  // term is added unscaled (a physical size), then the floors.
  const sss::core::Matrix6d& relief = match.pose.relief_covariance;
  EXPECT_GT(relief(1, 1), 0.0) << "the simulated seabed has relief under the lines";
  for (int i = 0; i < 6; ++i) {
    const double floor = i < 3 ? options.min_translation_sigma_m : options.min_rotation_sigma_rad;
    const double expected = options.covariance_scale * match.pose.model_covariance(i, i) + relief(i, i);
    if (expected > floor * floor) {
      EXPECT_NEAR(match.pose.covariance(i, i), expected, 1e-9 * expected) << "row " << i;
    }
  }
}

TEST(PairMatcher, AntiParallelSimulatedPairRecovers3mAlongAnd2mLateralDrError) {
  expectPairRecoversDrError({"anti-parallel (lines 0-1, 40 m)", 0, 1});
}

TEST(PairMatcher, ParallelSimulatedPairRecovers3mAlongAnd2mLateralDrError) {
  expectPairRecoversDrError({"parallel (lines 0-2, 80 m)", 0, 2});
}

// The correspondence precision holds with DR error up to 5 m between the lines.
TEST(PairMatcher, ParallelSimulatedPairRecovers5mOfDrError) {
  expectPairRecoversDrError({"parallel (lines 0-2, 80 m), 5 m DR error", 0, 2, 4.0, 3.0});
}

TEST(PairMatcher, PassAgreementTestLeavesAPairWhosePassesAgreeAsItIs) {
  // test_pass_agreement (off by default): at 20 m out over the default seabed the raw and the
  // rectified pass see the same seabed and agree; the published pose and covariance stay those
  // of all the matches.
  const auto& survey = test::threeLineSurvey();
  const auto* a = test::fullSubframeOfLine(survey, 0);
  const auto* b = test::fullSubframeOfLine(survey, 1);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  PairMatcherOptions options;
  const DenseMatcher dense(options.dense);
  const std::vector<Pose> poses_b = sss::sim::posesWithDrError(*a, *b, 3.0, 2.0);
  const PairMatch plain = matchPair(*a, sss::core::drPoses(*a), *b, poses_b, dense, options);
  options.test_pass_agreement = true;
  const PairMatch tested = matchPair(*a, sss::core::drPoses(*a), *b, poses_b, dense, options);
  std::printf("anti-parallel (lines 0-1): passes %.2f m apart, statistic %.2f\n", tested.pass_disagreement_m,
              tested.pass_agreement_statistic);
  ASSERT_TRUE(plain.accepted);
  ASSERT_TRUE(tested.accepted);
  EXPECT_LT(plain.pass_agreement_statistic, 0.0);  // not run when off
  EXPECT_GE(tested.pass_agreement_statistic, 0.0);
  EXPECT_LT(tested.pass_agreement_statistic, options.pass_agreement_chi2);
  EXPECT_FALSE(tested.pass_disagreement_widened);
  EXPECT_LT((tested.pose.covariance - plain.pose.covariance).norm(), 1e-12);
  EXPECT_LT((tested.pose.T_a_b.translation - plain.pose.T_a_b.translation).norm(), 1e-12);
}

TEST(PairMatcher, ImagesOfDifferentSeabedClaimedToOverlapAreRejected) {
  // Line 2's subframe geo-referenced 60 m further along than it was taken: the footprints still
  // overlap by 40 m, but no pixel's true match lies within the search window (5 m of DR error),
  // so whatever the dense matcher finds is chance and must not become a loop closure.
  const auto& survey = test::threeLineSurvey();
  const auto* a = test::fullSubframeOfLine(survey, 0);
  const auto* b = test::fullSubframeOfLine(survey, 2);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  // Rejected by the match count, and still rejected by RANSAC when every chance match is let in.
  for (const int min_matches : {100, 0}) {
    PairMatcherOptions options;
    options.min_matches = min_matches;
    const DenseMatcher dense(options.dense);
    const PairMatch match =
        matchPair(*a, sss::core::drPoses(*a), *b, sss::sim::posesWithDrError(*a, *b, 60.0, 0.0), dense, options);
    std::printf("wrong pair (min_matches %d): %zu matches, %s\n", min_matches, match.matches.size(),
                match.accepted ? "accepted" : match.reason.c_str());
    EXPECT_FALSE(match.accepted);
  }
}

TEST(PairMatcher, TextureFreeSeabedIsRejected) {
  const auto& survey = test::threeLineSurvey(false);
  const auto* a = test::fullSubframeOfLine(survey, 0);
  const auto* b = test::fullSubframeOfLine(survey, 1);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  PairMatcherOptions options;
  const DenseMatcher dense(options.dense);
  const PairMatch match = matchPair(*a, sss::core::drPoses(*a), *b, sss::core::drPoses(*b), dense, options);
  std::printf("texture-free seabed: %zu matches, %s\n", match.matches.size(),
              match.accepted ? "accepted" : match.reason.c_str());
  EXPECT_FALSE(match.accepted);
}

TEST(PairMatcher, MergeKeepsSingleMatchesAndPrefersTheRectifiedPassWhereTheTwoDisagree) {
  const std::vector<Correspondence> raw = {
      {2.0f, 0.0f, 3.0f, 3.0f, 0.9f},   // disagrees with the rectified pass below
      {0.0f, 0.0f, 1.0f, 1.0f, 0.8f},   // raw only
      {0.0f, 2.0f, 5.0f, 5.0f, 0.85f},  // agrees within 1 px
  };
  const std::vector<Correspondence> rectified = {
      {0.0f, 2.0f, 5.5f, 5.4f, 0.7f},
      {2.0f, 0.0f, 6.0f, 3.0f, 0.75f},
      {4.0f, 4.0f, 7.0f, 7.0f, 0.72f},  // rectified only
  };
  const std::vector<Correspondence> merged = mergeMatches(raw, rectified);
  ASSERT_EQ(merged.size(), 4u);
  auto expect = [](const Correspondence& m, float row_a, float col_a, float row_b, float col_b, float zncc) {
    EXPECT_EQ(m.row_a, row_a);
    EXPECT_EQ(m.col_a, col_a);
    EXPECT_EQ(m.row_b, row_b);
    EXPECT_EQ(m.col_b, col_b);
    EXPECT_EQ(m.zncc, zncc);
  };
  expect(merged[0], 0.0f, 0.0f, 1.0f, 1.0f, 0.8f);   // raw only: kept
  expect(merged[1], 0.0f, 2.0f, 5.0f, 5.0f, 0.85f);  // agree: the raw one
  expect(merged[2], 2.0f, 0.0f, 6.0f, 3.0f, 0.75f);  // disagree: the rectified one
  expect(merged[3], 4.0f, 4.0f, 7.0f, 7.0f, 0.72f);  // rectified only: kept
  EXPECT_TRUE(mergeMatches({}, {}).empty());
}

TEST(PairMatcher, RectifiedContrastIsTheSameForReliefSeenFromEitherSide) {
  // A furrow across track on a uniform seabed: from one side its near wall is in shadow and its
  // far wall lit, from the other side the reverse. Raw intensity differs; rectified contrast does not.
  GeoImage from_a, from_b;
  for (GeoImage* image : {&from_a, &from_b}) {
    image->intensity = cv::Mat1f(40, 60, 1.0f);
    image->valid = cv::Mat1b(40, 60, static_cast<uint8_t>(255));
    image->position_ne_m = cv::Mat2f(40, 60, cv::Vec2f(0.0f, 0.0f));
    image->valid.col(59).setTo(0);  // a masked column stays as it is
  }
  from_a.intensity.col(29).setTo(0.0f);  // shadow
  from_a.intensity.col(30).setTo(2.0f);  // highlight
  from_b.intensity.col(29).setTo(2.0f);
  from_b.intensity.col(30).setTo(0.0f);
  const GeoImage rect_a = rectifiedContrast(from_a, 8.0), rect_b = rectifiedContrast(from_b, 8.0);
  EXPECT_GT(cv::norm(from_a.intensity, from_b.intensity, cv::NORM_INF), 1.7);
  EXPECT_LT(cv::norm(rect_a.intensity, rect_b.intensity, cv::NORM_INF), 1e-4);
  // The furrow stands out of a flat (zero) background in both; the local mean is ~1.
  EXPECT_NEAR(rect_a.intensity(20, 29), 1.0, 0.05);
  EXPECT_NEAR(rect_a.intensity(20, 30), 1.0, 0.05);
  EXPECT_LT(rect_a.intensity(20, 5), 0.01);
  EXPECT_EQ(rect_a.intensity(20, 59), 1.0f);
  EXPECT_EQ(cv::countNonZero(rect_a.valid != from_a.valid), 0);
}

TEST(PairMatcher, HausmanStatisticWeighsTheDifferenceByTheSpreadTheSubsetAdds) {
  // A subset of half the matches: C_all = C_subset / 2, so D = C_subset / 2.
  sss::core::Matrix6d c_subset = sss::core::Matrix6d::Identity() * 0.01;
  c_subset(0, 0) = 0.04;   // along, m^2
  c_subset(1, 1) = 0.09;   // lateral
  c_subset(0, 1) = c_subset(1, 0) = 0.02;
  c_subset(5, 5) = 1e-4;   // heading, rad^2
  const sss::core::Matrix6d c_all = 0.5 * c_subset;
  sss::core::Vector6d d = sss::core::Vector6d::Zero();
  d(5) = 0.01;  // heading alone: d^2 / D = 1e-4 / 5e-5
  EXPECT_NEAR(hausmanStatistic(d, c_subset, c_all), 2.0, 1e-9);
  d(2) = 5.0;  // depth and roll/pitch are not in the test
  d(3) = 0.3;
  EXPECT_NEAR(hausmanStatistic(d, c_subset, c_all), 2.0, 1e-9);

  // Drawn from N(0, D) the statistic is chi-square with 3 degrees of freedom: mean 3, 99 % under 11.34.
  const Eigen::Matrix3d d_planar = 0.5 * (Eigen::Matrix3d() << 0.04, 0.02, 0.0, 0.02, 0.09, 0.0, 0.0, 0.0, 1e-4).finished();
  const Eigen::Matrix3d l = d_planar.llt().matrixL();
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  double sum = 0.0;
  int over = 0;
  const int draws = 20000;
  for (int k = 0; k < draws; ++k) {
    const Eigen::Vector3d z = l * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    sss::core::Vector6d sample = sss::core::Vector6d::Zero();
    sample(0) = z(0);
    sample(1) = z(1);
    sample(5) = z(2);
    const double statistic = hausmanStatistic(sample, c_subset, c_all);
    sum += statistic;
    over += statistic > PairMatcherOptions{}.opposed_relief_chi2;
  }
  EXPECT_NEAR(sum / draws, 3.0, 0.1);
  EXPECT_NEAR(static_cast<double>(over) / draws, 0.01, 0.003);

  // A subset almost as good as all (or, by noise, better): D is floored at a tenth of C_subset.
  d = sss::core::Vector6d::Zero();
  d(0) = 0.2;
  EXPECT_NEAR(hausmanStatistic(d, c_subset, c_subset), 10.0 * 0.2 * 0.2 * 0.09 / (0.04 * 0.09 - 0.02 * 0.02), 1e-6);  // 10 d' C^-1 d
  EXPECT_NEAR(hausmanStatistic(d, c_subset, 1.5 * c_subset), hausmanStatistic(d, c_subset, c_subset), 1e-9);
  // No spread to weigh by: not tested.
  EXPECT_LT(hausmanStatistic(d, sss::core::Matrix6d::Zero(), c_all), 0.0);
}

TEST(PairMatcher, MalformedInputIsRejectedWithAReason) {
  const auto& survey = test::threeLineSurvey();
  const auto* a = test::fullSubframeOfLine(survey, 0);
  ASSERT_NE(a, nullptr);
  PairMatcherOptions options;
  const DenseMatcher dense(options.dense);
  const PairMatch match = matchPair(*a, {}, *a, sss::core::drPoses(*a), dense, options);
  EXPECT_FALSE(match.accepted);
  EXPECT_NE(match.reason.find("pose count"), std::string::npos);
}

}  // namespace
}  // namespace sss::matcher
