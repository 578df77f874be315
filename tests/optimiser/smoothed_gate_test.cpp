// The chi-square gate at full smoothing (PoseGraphOptions::smoothed_gate_chi2): a closure that passed
// the pairwise test (through DR chains whose drift model is wide) but lies many sigmas from the
// survey everything else agrees on is rejected, and the graph solved without it. On the synthetic
// lawnmower with a good INS (DR drifts less than the graph's odometry model says, as the simulator's
// INS did against its reported accuracy) the fifth closure, which arrives before the window's own
// gate is active, is moved 4 m sideways (13 of its sigmas; a far-range pair on a rippled seabed in
// sss-sim was 6.9 m off, 9 of its sigmas); the truthful closures of the same mission must all stay.
// The graph bends towards an accepted outlier, so its residual under the solution alone stays small
// (this one's is below the gate on 3 of the 4 seeds): the test is of its leave-one-out innovation.
#include <gtest/gtest.h>

#include <cstdio>

#include "pipeline/optimiser/pose_graph.hpp"
#include "tests/optimiser/pose_graph_test_helpers.hpp"
#include "tools/fixtures/synthetic_mission.hpp"

namespace sss::optimiser {
namespace {

using namespace test_helpers;

struct Smoothed {
  double ate_m = 0.0;
  std::vector<ClosureRecord> closures;
  uint64_t rejected_gate = 0;
};

Smoothed smooth(const synthetic::Mission& mission, const PoseGraphOptions& options) {
  SlidingWindowPoseGraph graph(options);
  feed(graph, mission, 0, mission.nodes.size());
  const UpdateReport report = graph.fullSmoothing();
  EXPECT_TRUE(report.ok) << report.message;
  return {synthetic::translationRmse(estimates(graph), mission.nodes), graph.closures(),
          graph.counters().closures_rejected_gate};
}

int countStatus(const std::vector<ClosureRecord>& closures, ClosureStatus status) {
  int n = 0;
  for (const ClosureRecord& c : closures) n += c.status == status ? 1 : 0;
  return n;
}

TEST(SmoothedGate, IsOnByDefaultAtTheWindowGatesLevel) {
  const PoseGraphOptions defaults;
  EXPECT_EQ(defaults.smoothed_gate_chi2, defaults.gate_chi2);
  PoseGraphOptions negative;
  negative.smoothed_gate_chi2 = -1.0;
  EXPECT_FALSE(validatePoseGraphOptions(negative).empty());
}

constexpr size_t kOutlier = 4;
constexpr double kOffset_m = 4.0;

TEST(SmoothedGate, AClosureManySigmasFromTheSmoothedSurveyIsRejected) {
  PoseGraphOptions off = graphOptions();
  off.smoothed_gate_chi2 = 0.0;
  const PoseGraphOptions on = graphOptions();
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    const synthetic::Mission truthful = synthetic::makeLawnmowerMission(goodInsMissionOptions(seed));
    synthetic::Mission corrupted = truthful;
    ASSERT_FALSE(corrupted.closures.empty());
    corrupted.closures[kOutlier].closure.T_a_b.translation.y() += kOffset_m;

    const Smoothed plain = smooth(corrupted, off);
    ASSERT_EQ(plain.closures[kOutlier].status, ClosureStatus::kAccepted)
        << "seed " << seed << ": the pairwise test lets it through (else this test shows nothing)";
    const Smoothed gated = smooth(corrupted, on);
    const Smoothed reference = smooth(truthful, off);
    std::printf("seed %llu: a closure 4 m off: ATE accepted %.3f, rejected at smoothing %.3f, without it %.3f m\n",
                static_cast<unsigned long long>(seed), plain.ate_m, gated.ate_m, reference.ate_m);
    EXPECT_EQ(gated.closures[kOutlier].status, ClosureStatus::kRejected) << "seed " << seed;
    EXPECT_EQ(gated.closures[kOutlier].rejection, ClosureRejection::kChiSquareGate) << "seed " << seed;
    // Only that one: the truthful closures hold.
    EXPECT_EQ(countStatus(gated.closures, ClosureStatus::kAccepted),
              countStatus(plain.closures, ClosureStatus::kAccepted) - 1)
        << "seed " << seed;
    EXPECT_LT(gated.ate_m, plain.ate_m) << "seed " << seed;
    EXPECT_LT(gated.ate_m, reference.ate_m + 0.5 * (plain.ate_m - reference.ate_m)) << "seed " << seed;
  }
}

// Truthful closures: none is rejected at smoothing and the trajectory is the one without the gate,
// bit for bit.
TEST(SmoothedGate, TruthfulClosuresAllHold) {
  PoseGraphOptions off = graphOptions();
  off.smoothed_gate_chi2 = 0.0;
  const PoseGraphOptions on = graphOptions();
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    const synthetic::Mission truthful = synthetic::makeLawnmowerMission(goodInsMissionOptions(seed));
    const Smoothed plain = smooth(truthful, off);
    const Smoothed gated = smooth(truthful, on);
    EXPECT_EQ(gated.rejected_gate, plain.rejected_gate) << "seed " << seed;
    EXPECT_EQ(countStatus(gated.closures, ClosureStatus::kAccepted),
              countStatus(plain.closures, ClosureStatus::kAccepted))
        << "seed " << seed;
    EXPECT_EQ(gated.ate_m, plain.ate_m) << "seed " << seed;
  }
}

}  // namespace
}  // namespace sss::optimiser
