// The matcher engine on a simulated three-line survey: subframes arrive in order, closures appear
// only between overlapping lines and agree with the truth, the covariance is consistent over the
// batch, optimised poses trigger the re-association round, memory stays bounded.
#include "pipeline/matcher/matcher_engine.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include "tests/matcher/matcher_test_survey.hpp"

namespace sss::matcher {
namespace {

struct Check {
  int accepted = 0;
  // Largest along- or across-track error (issue 6: "within 0.3 m in both directions") over
  // closures between two full (200-ping) subframes.
  double max_horizontal_error_m = 0.0;
  double max_nees = 0.0;
  double nees_sum = 0.0;  // horizontal translation, 2 dof
};

Check checkAgainstTruth(const std::vector<PairOutcome>& outcomes, const sss::sim::SimulatedSurvey& survey) {
  const sss::sim::SubframeTruth truth(*survey.mission);
  auto find = [&](int64_t id) -> const sss::subframe::Subframe& {
    for (const auto& s : survey.subframes) {
      if (s.id == id) return s;
    }
    throw std::runtime_error("unknown subframe");
  };
  Check check;
  for (const PairOutcome& o : outcomes) {
    const auto& a = find(o.subframe_id_a);
    const auto& b = find(o.subframe_id_b);
    if (!o.accepted) {
      std::printf("  pair %lld-%lld (lines %d-%d, rows %d/%d, round %d): rejected: %s\n", (long long)o.subframe_id_a,
                  (long long)o.subframe_id_b, a.line_id, b.line_id, a.rows(), b.rows(), o.association_round,
                  o.reason.c_str());
      continue;
    }
    ++check.accepted;
    EXPECT_NE(a.line_id, b.line_id);
    const Eigen::Vector3d error = o.closure.T_a_b.translation - truth.trueRelativePose(a, b).translation;
    const Eigen::Vector2d e2 = error.head<2>();
    const double nees = e2.transpose() * o.closure.covariance.topLeftCorner<2, 2>().inverse() * e2;
    check.nees_sum += nees;
    if (a.rows() == 200 && b.rows() == 200)
      check.max_horizontal_error_m = std::max(check.max_horizontal_error_m, e2.cwiseAbs().maxCoeff());
    check.max_nees = std::max(check.max_nees, nees);
    std::printf("  pair %lld-%lld (lines %d-%d, rows %d/%d, round %d): %d inliers of %d, error [%.3f %.3f %.3f] m, "
                "sigma [%.3f %.3f], NEES %.2f, %.2f s\n",
                (long long)o.subframe_id_a, (long long)o.subframe_id_b, a.line_id, b.line_id, a.rows(), b.rows(),
                o.association_round, o.closure.num_inliers, o.closure.num_matches, error.x(), error.y(), error.z(),
                std::sqrt(o.closure.covariance(0, 0)), std::sqrt(o.closure.covariance(1, 1)), nees, o.seconds);
    // Every inlier up to the cap goes to the optimiser's point cloud.
    EXPECT_EQ(o.closure.correspondences.size(),
              std::min<size_t>(o.closure.num_inliers, MatcherEngineOptions{}.max_closure_correspondences));
    for (const ClosureCorrespondence& c : o.closure.correspondences) EXPECT_TRUE(c.landmark_a_m.allFinite());
  }
  return check;
}

TEST(MatcherEngine, SurveyClosuresAgreeWithTheTruthAndReassociationRunsOnOptimisedPoses) {
  const auto& survey = test::threeLineSurvey();
  MatcherEngine engine{MatcherEngineOptions{}};
  std::vector<PairOutcome> outcomes;
  // DR error between the lines: line k is off by k * (2 m north, 1.5 m east) on top of the
  // simulated drift (which is only ~0.2 m on this short survey).
  for (auto s : survey.subframes) {
    const Eigen::Vector3d offset = s.line_id * Eigen::Vector3d(2.0, 1.5, 0.0);
    for (auto& ping : s.pings) ping.T_world_body.translation += offset;
    for (auto& o : engine.addSubframe(s)) outcomes.push_back(std::move(o));
  }
  std::printf("DR round: %zu pairs\n", outcomes.size());
  const Check dr = checkAgainstTruth(outcomes, survey);
  // Lines 0-1, 1-2 (anti-parallel) and 0-2 (parallel) each overlap in their full subframes.
  EXPECT_GE(dr.accepted, 3);
  // Issue 6: within 0.3 m for full subframe pairs. A line's 50-99 ping tail constrains heading,
  // and through it the along-track lever, less: up to ~1 m, which its covariance says (every
  // closure within the chi-square 2-dof 99.9 % bound, 13.8).
  EXPECT_LT(dr.max_horizontal_error_m, 0.3);
  EXPECT_LT(dr.max_nees, 13.8);
  EXPECT_EQ(engine.counters().closures_accepted, static_cast<uint64_t>(dr.accepted));

  // The optimiser's answer, here the truth: every pair moved by the DR error is re-matched once.
  std::vector<TrajectoryNode> nodes;
  for (const auto& s : survey.subframes) {
    nodes.push_back({s.id, s.centre().utime_us, sss::sim::truePoses(*survey.mission, s)[s.centre_ping_index]});
  }
  const std::vector<PairOutcome> round1 = engine.updateTrajectory(nodes);
  std::printf("round 1: %zu pairs\n", round1.size());
  const Check reassociated = checkAgainstTruth(round1, survey);
  // Pairs between lines that moved relative to each other (all but none: every line moved).
  EXPECT_GE(reassociated.accepted, dr.accepted - 1);
  for (const auto& o : round1) EXPECT_EQ(o.association_round, 1);
  EXPECT_LT(reassociated.max_horizontal_error_m, 0.3);
  EXPECT_LT(reassociated.max_nees, 13.8);
  // The same poses again: nothing moved, nothing re-matched.
  EXPECT_TRUE(engine.updateTrajectory(nodes).empty());

  const int total = dr.accepted + reassociated.accepted;
  const double mean_nees = (dr.nees_sum + reassociated.nees_sum) / std::max(total, 1);
  std::printf("mean horizontal NEES %.2f over %d closures (2 for a consistent covariance)\n", mean_nees, total);
  // Consistent within the spread of a batch of ~16 closures (chi-square 2 dof: mean 2).
  EXPECT_LT(mean_nees, 6.0);
  EXPECT_GT(mean_nees, 0.3);
}

TEST(MatcherEngine, StoredSubframesAreBoundedAndMalformedOnesRejected) {
  const auto& survey = test::threeLineSurvey();
  MatcherEngineOptions options;
  options.max_stored_subframes = 2;
  options.overlap.min_overlap_fraction = 0.99;  // no matching: this test is about storage
  MatcherEngine engine(options);
  for (const auto& s : survey.subframes) engine.addSubframe(s);
  EXPECT_EQ(engine.storedSubframes(), 2u);
  EXPECT_EQ(engine.counters().subframes_evicted, survey.subframes.size() - 2);
  EXPECT_LT(engine.memoryBytes(), 2u * 3u * 1024u * 1024u);
  sss::subframe::Subframe broken = survey.subframes.front();
  broken.id = 1000;
  broken.mask.pop_back();
  EXPECT_TRUE(engine.addSubframe(broken).empty());
  EXPECT_TRUE(engine.addSubframe(survey.subframes.back()).empty());  // a duplicate id
  EXPECT_EQ(engine.counters().subframes_rejected, 2u);
}

}  // namespace
}  // namespace sss::matcher
