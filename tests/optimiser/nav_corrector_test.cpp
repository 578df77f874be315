// The answer to a nav sample: bad samples and samples before the first fix are not answered and
// say why; the navigation's origin is followed (first, unchanged, moved); the corrected pose is the
// DR pose under the graph's correction, slewed.
#include "pipeline/optimiser/nav_corrector.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tools/fixtures/synthetic_mission.hpp"
#include "tests/optimiser/pose_graph_test_helpers.hpp"
#include "tests/support/status_assertions.hpp"

namespace sss::optimiser {
namespace {

sss::core::NavSample sampleAt(int64_t utime_us, double latitude_deg = 58.25) {
  sss::core::NavSample nav;
  nav.utime_us = utime_us;
  nav.position_ned_m = Eigen::Vector3d(10.0, -4.0, 20.0);
  nav.heading_rad = 0.3;
  nav.origin = sss::core::MissionOrigin{latitude_deg, 11.45};
  return nav;
}

TEST(NavCorrector, BadSamplesAndSamplesBeforeTheFirstFixAreNotAnswered) {
  NavCorrector corrector;
  const SlidingWindowPoseGraph graph(test_helpers::graphOptions());
  sss::core::NavSample nav = sampleAt(1'000'000);
  nav.heading_rad = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(corrector.correct(nav, graph).verdict, NavVerdict::kBadSample);
  nav = sampleAt(0);
  EXPECT_EQ(corrector.correct(nav, graph).verdict, NavVerdict::kBadSample);  // no time
  nav = sampleAt(1'000'000);
  nav.position_valid = false;
  EXPECT_EQ(corrector.correct(nav, graph).verdict, NavVerdict::kNoPosition);
  nav = sampleAt(1'000'000);
  nav.origin.reset();
  EXPECT_EQ(corrector.correct(nav, graph).verdict, NavVerdict::kNoPosition);
  EXPECT_FALSE(corrector.plane().has_value());  // no frame yet
}

TEST(NavCorrector, FollowsTheNavigationsOriginAndAnswersWithTheDrPoseBeforeAnyNode) {
  NavCorrector corrector;
  const SlidingWindowPoseGraph graph(test_helpers::graphOptions());
  NavCorrection first = corrector.correct(sampleAt(1'000'000), graph);
  ASSERT_EQ(first.verdict, NavVerdict::kCorrected);
  EXPECT_TRUE(first.origin_changed);
  EXPECT_FALSE(first.previous_origin.has_value());
  ASSERT_TRUE(corrector.plane().has_value());
  EXPECT_DOUBLE_EQ(corrector.plane()->originLatitudeDeg(), 58.25);
  EXPECT_NEAR((first.dr.translation - Eigen::Vector3d(10.0, -4.0, 20.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(first.correction.T_corrected_dr.translation.norm(), 0.0, 1e-12);  // no node: DR as it is
  EXPECT_EQ(first.correction.status, CorrectionStatus::kDrOnly);
  EXPECT_FALSE(corrector.correct(sampleAt(1'005'000), graph).origin_changed);
  const NavCorrection moved = corrector.correct(sampleAt(1'010'000, 58.30), graph);
  EXPECT_TRUE(moved.origin_changed);
  ASSERT_TRUE(moved.previous_origin.has_value());
  EXPECT_DOUBLE_EQ(moved.previous_origin->latitude_deg, 58.25);
  EXPECT_DOUBLE_EQ(corrector.plane()->originLatitudeDeg(), 58.30);
}

// With closures the graph corrects the present pose; the corrector publishes that correction
// (slewed from the first sample on, which it takes as it is).
TEST(NavCorrector, AnswersWithTheGraphsCorrectionOnceThereAreNodes) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(test_helpers::missionOptions(4));
  SlidingWindowPoseGraph graph(test_helpers::graphOptions());
  for (const synthetic::Node& n : mission.nodes) ASSERT_TRUE(graph.addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m).ok);
  for (const auto& c : mission.closures) EXPECT_OK(graph.addLoopClosure(c.closure));
  ASSERT_TRUE(graph.optimize().ok);
  const synthetic::Node& last = mission.nodes.back();
  sss::core::NavSample nav = sampleAt(last.utime_us);
  nav.position_ned_m = last.dr.translation;
  NavCorrector corrector;
  const NavCorrection answer = corrector.correct(nav, graph);
  ASSERT_EQ(answer.verdict, NavVerdict::kCorrected);
  const Correction expected = graph.correctionAt(last.utime_us);
  EXPECT_GT(expected.T_corrected_dr.translation.norm(), 0.05);  // the closures moved the present pose
  EXPECT_NEAR((answer.correction.T_corrected_dr.translation - expected.T_corrected_dr.translation).norm(), 0.0, 1e-12);
  EXPECT_EQ(answer.correction.accepted_closures, expected.accepted_closures);
}

}  // namespace
}  // namespace sss::optimiser
