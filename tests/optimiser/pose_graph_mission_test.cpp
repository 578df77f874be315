// Sliding-window pose graph accuracy on synthetic lawnmowers of subframe-centre nodes (5 lines of
// 400 m, 100 m subframes, lines 100 m apart, several seeds) and on a 2000-node mission: ATE against
// DR, false closures, window against batch, covariance consistency, bounded problem size.
#include "pipeline/optimiser/pose_graph.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tools/fixtures/synthetic_mission.hpp"
#include "tests/optimiser/pose_graph_test_helpers.hpp"
#include "tests/support/status_assertions.hpp"

namespace sss::optimiser {
namespace {

using sss::core::Matrix6d;
using sss::core::Pose;
using namespace test_helpers;

constexpr int kSeeds = 6;

TEST(PoseGraphSyntheticMission, HasTheExpectedShapeAndDrift) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(1));
  EXPECT_EQ(mission.nodes.size(), 20u);    // 5 lines x 4 subframes of 100 m
  EXPECT_EQ(mission.closures.size(), 16u); // 4 line pairs x 4 side-by-side subframes
  const double ate_dr = synthetic::translationRmse(synthetic::drPoses(mission), mission.nodes);
  const double end_error = (mission.nodes.back().dr.translation - mission.nodes.back().truth.translation).norm();
  EXPECT_GT(end_error, 3.0);
  EXPECT_GT(ate_dr, 1.5);
}

// ATE of the optimised nodes at most 40 % of DR's, for every seed.
TEST(PoseGraph, ClosuresReduceTheTrajectoryErrorWellBelowDr) {
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(seed));
    const MissionRun r = run(mission, graphOptions());
    std::printf("seed %llu: ATE DR %.2f m, window %.2f m, full %.2f m, %d closures accepted\n",
                static_cast<unsigned long long>(seed), r.ate_dr_m, r.ate_window_m, r.ate_full_m, r.true_accepted);
    EXPECT_LE(r.ate_window_m, 0.4 * r.ate_dr_m) << "seed " << seed;
    EXPECT_LE(r.ate_full_m, 0.4 * r.ate_dr_m) << "seed " << seed;
    EXPECT_EQ(r.true_accepted, static_cast<int>(mission.closures.size())) << "seed " << seed;
  }
}

// 20 % of the closures replaced by wrong relative poses (3-10 m, 2-10 deg): the mean ATE stays
// within 10 % of the clean runs and every run stays below DR.
TEST(PoseGraph, FalseClosuresAreRejected) {
  double clean_sum = 0.0, false_sum = 0.0;
  int false_total = 0, false_accepted = 0;
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const synthetic::Mission clean = synthetic::makeLawnmowerMission(missionOptions(seed));
    const synthetic::Mission corrupted = synthetic::makeLawnmowerMission(missionOptions(seed, 0.2));
    const MissionRun c = run(clean, graphOptions());
    const MissionRun f = run(corrupted, graphOptions());
    for (const auto& closure : corrupted.closures) false_total += closure.is_false ? 1 : 0;
    false_accepted += f.false_accepted;
    std::printf("seed %llu: ATE DR %.2f m, clean %.2f m, 20%% false %.2f m (%d false accepted)\n",
                static_cast<unsigned long long>(seed), c.ate_dr_m, c.ate_window_m, f.ate_window_m, f.false_accepted);
    clean_sum += c.ate_window_m;
    false_sum += f.ate_window_m;
    EXPECT_LT(f.ate_window_m, c.ate_dr_m) << "seed " << seed;
    EXPECT_LT(f.ate_full_m, c.ate_dr_m) << "seed " << seed;
  }
  std::printf("mean ATE clean %.3f m, with false closures %.3f m; %d of %d false closures accepted\n",
              clean_sum / kSeeds, false_sum / kSeeds, false_accepted, false_total);
  EXPECT_LE(std::abs(false_sum - clean_sum), 0.1 * clean_sum);
  EXPECT_EQ(false_accepted, 0);
}

// Each defence on its own, same missions (20 % false): PCM alone and the chi-square gate alone
// (active from the first closure) reject every false closure; the Cauchy loss alone accepts them but
// keeps the ATE near the clean result; with no defence at all the ATE is several times worse, which
// shows the false closures are harmful enough for the test to mean something.
TEST(PoseGraph, EachDefenceAloneContainsFalseClosures) {
  enum class Defence { kPcm, kGate, kCauchy, kNone };
  auto optionsFor = [](Defence d) {
    PoseGraphOptions o = graphOptions();
    if (d != Defence::kPcm) {
      o.pcm_chi2 = 1e12;  // every pair consistent
      o.min_consistent_closures = 1;
    }
    o.gate_min_accepted_closures = d == Defence::kGate ? 0 : 1000000;
    if (d == Defence::kNone) o.robust_loss = "none";
    return o;
  };
  double clean = 0.0, pcm = 0.0, gate = 0.0, cauchy = 0.0, none = 0.0;
  int pcm_false = 0, gate_false = 0;
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const synthetic::Mission clean_mission = synthetic::makeLawnmowerMission(missionOptions(seed));
    const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(seed, 0.2));
    clean += run(clean_mission, graphOptions()).ate_window_m;
    const MissionRun p = run(mission, optionsFor(Defence::kPcm));
    const MissionRun g = run(mission, optionsFor(Defence::kGate));
    pcm += p.ate_window_m;
    gate += g.ate_window_m;
    pcm_false += p.false_accepted;
    gate_false += g.false_accepted;
    cauchy += run(mission, optionsFor(Defence::kCauchy)).ate_window_m;
    none += run(mission, optionsFor(Defence::kNone)).ate_window_m;
  }
  std::printf("mean ATE: clean %.3f m; 20%% false with PCM only %.3f m, gate only %.3f m, Cauchy only %.3f m, "
              "nothing %.3f m\n", clean / kSeeds, pcm / kSeeds, gate / kSeeds, cauchy / kSeeds, none / kSeeds);
  EXPECT_EQ(pcm_false, 0);
  EXPECT_EQ(gate_false, 0);
  EXPECT_LE(pcm, 1.1 * clean);
  EXPECT_LE(gate, 1.1 * clean);
  EXPECT_LE(cauchy, 1.25 * clean);
  EXPECT_GT(none, 2.0 * clean);
}

// The window's marginalisation prior is exact up to linearisation, so the nodes still in the
// window agree with the batch solution (same information) to a fraction of the closure noise
// (0.3 m); marginalised nodes do not see later closures, so the whole trajectory is compared
// by its ATE only.
TEST(PoseGraph, WindowSolutionIsCloseToTheFullBatch) {
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(seed));
    SlidingWindowPoseGraph window(graphOptions(8));
    SlidingWindowPoseGraph batch(graphOptions(1000));  // never marginalises
    feed(window, mission, 0, mission.nodes.size());
    feed(batch, mission, 0, mission.nodes.size());
    ASSERT_TRUE(batch.fullSmoothing().ok);
    double max_difference = 0.0;
    for (const NodeState& n : window.nodes()) {
      if (n.marginalised) continue;
      max_difference =
          std::max(max_difference, (n.T_world_body.translation - batch.estimate(n.subframe_id)->translation).norm());
    }
    const double ate_window = synthetic::translationRmse(estimates(window), mission.nodes);
    const double ate_batch = synthetic::translationRmse(estimates(batch), mission.nodes);
    std::printf("seed %llu: window nodes vs batch max %.3f m; ATE window %.3f m, batch %.3f m\n",
                static_cast<unsigned long long>(seed), max_difference, ate_window, ate_batch);
    EXPECT_LT(max_difference, 0.1) << "seed " << seed;
    EXPECT_LT(ate_window, 1.25 * ate_batch + 0.05) << "seed " << seed;
  }
}

// Thousands of nodes: the optimisation problem stops growing once the window is full.
TEST(PoseGraph, WindowStaysBoundedOverThousandsOfNodes) {
  synthetic::MissionOptions mission_options = missionOptions(9, 0.05);
  mission_options.num_lines = 500;  // 2000 nodes, ~270 km
  mission_options.heading_bias_rad = 0.0005;
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(mission_options);
  ASSERT_EQ(mission.nodes.size(), 2000u);
  PoseGraphOptions options = graphOptions(8);
  options.pcm_max_closures = 30;
  SlidingWindowPoseGraph graph(options);
  size_t next_closure = 0;
  int max_variables = 0, max_prior_rows = 0, max_residuals = 0, max_constants = 0, max_candidates = 0;
  for (size_t i = 0; i < mission.nodes.size(); ++i) {
    const synthetic::Node& n = mission.nodes[i];
    ASSERT_TRUE(graph.addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m).ok);
    while (next_closure < mission.closures.size() && mission.closures[next_closure].newer_node == static_cast<int>(i))
      EXPECT_OK(graph.addLoopClosure(mission.closures[next_closure++].closure));
    ASSERT_TRUE(graph.optimize().ok);
    if (i < 100) continue;
    const WindowStats& s = graph.windowStats();
    max_variables = std::max(max_variables, s.variable_blocks);
    max_prior_rows = std::max(max_prior_rows, s.prior_rows);
    max_residuals = std::max(max_residuals, s.residual_blocks);
    max_constants = std::max(max_constants, s.constant_blocks);
    max_candidates = std::max(max_candidates, s.pcm_candidates);
  }
  EXPECT_EQ(max_variables, 9);  // window + the new node
  EXPECT_LE(max_prior_rows, 6 * 8);
  EXPECT_LE(max_residuals, 2 + 8 + 2 * 9);  // prior, odometry, at most a couple of closures a node
  EXPECT_LE(max_candidates, 30);
  EXPECT_LE(max_constants, 4);
  const double ate_dr = synthetic::translationRmse(synthetic::drPoses(mission), mission.nodes);
  const double ate = synthetic::translationRmse(estimates(graph), mission.nodes);
  std::printf("2000 nodes: ATE DR %.1f m, window %.1f m, last update %.4f s\n", ate_dr, ate,
              graph.counters().last_update_s);
  EXPECT_LT(ate, ate_dr);
}

// The window covariance of the newest node against its actual error over several seeds: the
// normalised squared horizontal error should average about 2 (two dof); accept 0.2-10.
TEST(PoseGraph, NewestNodeCovarianceIsConsistentWithItsError) {
  double nees = 0.0;
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(seed));
    SlidingWindowPoseGraph graph(graphOptions());
    feed(graph, mission, 0, mission.nodes.size());
    const synthetic::Node& last = mission.nodes.back();
    const Pose e = *graph.estimate(last.subframe_id);
    const Matrix6d c = *graph.covariance(last.subframe_id);
    // Horizontal error in the node's body frame (the covariance's translation is body-frame).
    const Eigen::Vector3d error = e.rotation.conjugate() * (last.truth.translation - e.translation);
    const Eigen::Vector2d h = error.head<2>();
    nees += h.dot(c.topLeftCorner<2, 2>().inverse() * h);
  }
  nees /= kSeeds;
  std::printf("mean horizontal NEES of the newest node: %.2f\n", nees);
  EXPECT_GT(nees, 0.2);
  EXPECT_LT(nees, 10.0);
}

}  // namespace
}  // namespace sss::optimiser
