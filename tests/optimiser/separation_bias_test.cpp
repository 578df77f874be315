// The survey-wide separation bias of closures between lines that look at their overlap from opposite
// sides (PoseGraphOptions::separation_bias_sigma_m): raised features show each line the face turned
// towards it, so every such closure puts the two lines closer together by a common amount. On the
// synthetic lawnmower every closure is shortened by a known amount; full smoothing must find it and
// undo its effect, and find nothing where the closures are truthful.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <utility>

#include "pipeline/optimiser/pose_graph.hpp"
#include "tools/fixtures/synthetic_mission.hpp"
#include "tests/optimiser/pose_graph_test_helpers.hpp"

namespace sss::optimiser {
namespace {

using namespace test_helpers;

PoseGraphOptions withBias(PoseGraphOptions options) {
  options.odometry_random_walk_m_per_sqrt_m = 0.01;
  options.odometry_drift_fraction = 0.002;
  options.separation_bias_sigma_m = 2.0;
  options.separation_bias_apply = true;
  return options;
}

// Every closure's B moved towards A by bias_m (laterally in A's frame: the lines run 100 m apart).
synthetic::Mission shortened(synthetic::Mission mission, double bias_m) {
  for (synthetic::Closure& c : mission.closures) {
    double& lateral_m = c.closure.T_a_b.translation.y();
    lateral_m -= (lateral_m > 0.0 ? 1.0 : -1.0) * bias_m;
  }
  return mission;
}

struct Solved {
  double ate_m = 0.0;
  SeparationBias bias;
};

Solved smooth(const synthetic::Mission& mission, const PoseGraphOptions& options) {
  SlidingWindowPoseGraph graph(options);
  feed(graph, mission, 0, mission.nodes.size());
  const UpdateReport report = graph.fullSmoothing();
  EXPECT_TRUE(report.ok) << report.message;
  return {synthetic::translationRmse(estimates(graph), mission.nodes), graph.separationBias()};
}

// Closures 1.5 m short on every pair (what rock outcrops did on randomised sss-sim missions): the
// estimate is within 2 sigma of 1.5 m, and the trajectory is about as good as with truthful
// closures, where the uncorrected graph pulls every line 1.5 m towards its neighbour.
TEST(SeparationBias, ACommonShorteningOfOppositeSideClosuresIsEstimatedAndUndone) {
  const double bias_m = 1.5;
  PoseGraphOptions off = withBias(graphOptions());
  off.separation_bias_sigma_m = 0.0;
  const PoseGraphOptions on = withBias(graphOptions());
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    const synthetic::Mission truthful = synthetic::makeLawnmowerMission(goodInsMissionOptions(seed));
    const synthetic::Mission biased = shortened(truthful, bias_m);
    const Solved reference = smooth(truthful, off);
    const Solved plain = smooth(biased, off);
    const Solved corrected = smooth(biased, on);
    const double ate_dr = synthetic::translationRmse(synthetic::drPoses(truthful), truthful.nodes);
    std::printf("seed %llu: closures %.1f m short: bias %.3f +- %.3f m over %d closures; ATE DR %.3f, truthful "
                "closures %.3f, uncorrected %.3f, corrected %.3f m\n",
                static_cast<unsigned long long>(seed), bias_m, corrected.bias.estimate_m, corrected.bias.sigma_m,
                corrected.bias.closures, ate_dr, reference.ate_m, plain.ate_m, corrected.ate_m);
    EXPECT_EQ(corrected.bias.closures, 16) << "every closure runs between adjacent lines";
    ASSERT_TRUE(std::isfinite(corrected.bias.sigma_m));
    EXPECT_GT(corrected.bias.sigma_m, 0.01);
    EXPECT_LT(corrected.bias.sigma_m, 1.0) << "16 closures against a good DR say more than the 2 m prior";
    EXPECT_NEAR(corrected.bias.tested_m, bias_m, 2.0 * corrected.bias.sigma_m) << "seed " << seed;
    EXPECT_TRUE(corrected.bias.applied) << "seed " << seed << ": 1.5 m is several sigmas";
    EXPECT_EQ(corrected.bias.estimate_m, corrected.bias.tested_m);
    EXPECT_LT(corrected.ate_m, plain.ate_m) << "seed " << seed;
    EXPECT_LT(corrected.ate_m, reference.ate_m + 0.5 * (plain.ate_m - reference.ate_m)) << "seed " << seed;
    // Off: nothing estimated.
    EXPECT_EQ(plain.bias.estimate_m, 0.0);
    EXPECT_TRUE(std::isnan(plain.bias.sigma_m));
  }
}

// The default measures it and applies nothing: the bias is found significant, and the trajectory
// is the one the graph gives without it, bit for bit.
TEST(SeparationBias, ByDefaultItIsMeasuredNotApplied) {
  const PoseGraphOptions defaults;
  EXPECT_GT(defaults.separation_bias_sigma_m, 0.0);
  EXPECT_FALSE(defaults.separation_bias_apply);
  PoseGraphOptions off = withBias(graphOptions());
  off.separation_bias_sigma_m = 0.0;
  PoseGraphOptions measured = withBias(graphOptions());
  measured.separation_bias_apply = false;
  const synthetic::Mission biased = shortened(synthetic::makeLawnmowerMission(goodInsMissionOptions(3)), 1.5);
  const Solved plain = smooth(biased, off);
  const Solved diagnosed = smooth(biased, measured);
  EXPECT_TRUE(diagnosed.bias.significant);
  EXPECT_FALSE(diagnosed.bias.applied);
  EXPECT_EQ(diagnosed.bias.estimate_m, 0.0);
  EXPECT_NEAR(diagnosed.bias.tested_m, 1.5, 2.0 * diagnosed.bias.sigma_m);
  EXPECT_EQ(diagnosed.ate_m, plain.ate_m);
}

// Truthful closures: the estimate is within 2 sigma of 0, is not significant and so is not applied:
// the trajectory is that of the graph without it. (Applied, a free bias of 0.1-0.4 +- 0.3 m per pair
// spread the lines and doubled the ATE on these seeds: hence the significance test.)
TEST(SeparationBias, TruthfulClosuresGiveNoBias) {
  PoseGraphOptions off = withBias(graphOptions());
  off.separation_bias_sigma_m = 0.0;
  const PoseGraphOptions on = withBias(graphOptions());
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    const synthetic::Mission truthful = synthetic::makeLawnmowerMission(goodInsMissionOptions(seed));
    const Solved plain = smooth(truthful, off);
    const Solved estimated = smooth(truthful, on);
    std::printf("seed %llu: truthful closures: bias %.3f +- %.3f m (not applied); ATE %.3f -> %.3f m\n",
                static_cast<unsigned long long>(seed), estimated.bias.tested_m, estimated.bias.sigma_m, plain.ate_m,
                estimated.ate_m);
    EXPECT_LT(std::abs(estimated.bias.tested_m), 2.0 * estimated.bias.sigma_m) << "seed " << seed;
    EXPECT_FALSE(estimated.bias.applied) << "seed " << seed;
    EXPECT_FALSE(estimated.bias.significant) << "seed " << seed;
    EXPECT_EQ(estimated.bias.estimate_m, 0.0);
    EXPECT_NEAR(estimated.ate_m, plain.ate_m, 0.01 * plain.ate_m) << "seed " << seed;
  }
}

// separation_bias_widen: the bias is found but not applied (it may be DR's), and the opposite-side
// closures' lateral variance grows by the disputed amount. They then stop pulling the lines 1.5 m
// together: the trajectory is better than the plain graph's. Truthful closures are never
// significant, and closures that lengthen the separation are not what feature faces do: in both
// nothing is widened and the trajectory is the plain one.
TEST(SeparationBias, WideningTheDisputedSeparationStopsBiasedClosuresPullingTheLines) {
  PoseGraphOptions plain_options = withBias(graphOptions());
  plain_options.separation_bias_apply = false;
  PoseGraphOptions widen_options = plain_options;
  widen_options.separation_bias_widen = true;
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    const synthetic::Mission truthful = synthetic::makeLawnmowerMission(goodInsMissionOptions(seed));
    const synthetic::Mission biased = shortened(truthful, 1.5);
    const Solved plain = smooth(biased, plain_options);
    const Solved widened = smooth(biased, widen_options);
    const Solved truthful_plain = smooth(truthful, plain_options);
    const Solved truthful_widened = smooth(truthful, widen_options);
    const double ate_dr = synthetic::translationRmse(synthetic::drPoses(truthful), truthful.nodes);
    std::printf("seed %llu: closures 1.5 m short: ATE DR %.3f, plain %.3f, widened %.3f m (bias %.2f +- %.2f); "
                "truthful closures %.3f / %.3f m\n",
                static_cast<unsigned long long>(seed), ate_dr, plain.ate_m, widened.ate_m, widened.bias.tested_m,
                widened.bias.sigma_m, truthful_plain.ate_m, truthful_widened.ate_m);
    EXPECT_TRUE(widened.bias.significant) << "seed " << seed;
    EXPECT_FALSE(widened.bias.applied) << "seed " << seed;
    EXPECT_LT(widened.ate_m, 0.75 * plain.ate_m) << "seed " << seed;
    EXPECT_FALSE(truthful_widened.bias.significant) << "seed " << seed;
    EXPECT_EQ(truthful_widened.ate_m, truthful_plain.ate_m) << "seed " << seed;
    // Closures that put the lines farther apart than DR: not what feature faces do; nothing widened.
    const synthetic::Mission lengthened = shortened(truthful, -1.5);
    const Solved lengthened_plain = smooth(lengthened, plain_options);
    const Solved lengthened_widened = smooth(lengthened, widen_options);
    EXPECT_TRUE(lengthened_widened.bias.significant) << "seed " << seed;
    EXPECT_LT(lengthened_widened.bias.tested_m, 0.0) << "seed " << seed;
    EXPECT_EQ(lengthened_widened.ate_m, lengthened_plain.ate_m) << "seed " << seed;
  }
}

// separation_bias_widen_with_fixes (default): once absolute fixes were accepted the DVL scale is
// estimated with the bias, so a significant shortening is the closures', and the same widening is
// done without separation_bias_widen. USBL (1 m) at every other node: with the closures
// 1.5 m short the widened graph is nearer the truth than the one that trusts them; truthful closures
// are not significant, and without fixes nothing is widened: in both the estimate is the plain one.
// (USBL at every other node pins the scale; GNSS at the two ends alone, measured before the fix gate's
// drift term, left the bias at 1.4-1.7 +- 0.54 m, significant on 1 seed of 4.)
TEST(SeparationBias, WithAcceptedFixesTheDisputedSeparationIsWidenedByDefault) {
  PoseGraphOptions options = withBias(graphOptions());
  options.separation_bias_apply = false;
  ASSERT_FALSE(options.separation_bias_widen);
  ASSERT_TRUE(options.separation_bias_widen_with_fixes);
  PoseGraphOptions off = options;
  off.separation_bias_widen_with_fixes = false;
  auto run = [](const synthetic::Mission& mission, const PoseGraphOptions& o, bool fixes, uint64_t seed) {
    const SlidingWindowPoseGraph graph = solvedWithUsbl(mission, o, fixes, seed * 31);
    return std::make_pair(synthetic::translationRmse(estimates(graph), mission.nodes), graph.separationBias());
  };
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    const synthetic::Mission truthful = synthetic::makeLawnmowerMission(goodInsMissionOptions(seed));
    const synthetic::Mission biased = shortened(truthful, 1.5);
    const auto [ate_truthful, bias_truthful] = run(truthful, options, true, seed);
    const auto [ate_truthful_off, unused_off] = run(truthful, off, true, seed);
    EXPECT_FALSE(bias_truthful.significant) << "seed " << seed;
    EXPECT_EQ(ate_truthful, ate_truthful_off) << "seed " << seed << ": truthful closures, nothing widened";
    const auto [ate_widened, bias] = run(biased, options, true, seed);
    const auto [ate_trusted, bias_off] = run(biased, off, true, seed);
    const auto [ate_no_fixes, bias_no_fixes] = run(biased, options, false, seed);
    const auto [ate_no_fixes_off, unused] = run(biased, off, false, seed);
    std::printf("seed %llu: closures 1.5 m short, USBL at every other node: widened %.3f m, trusted %.3f m (bias %.2f +- "
                "%.2f); without fixes %.3f / %.3f m\n",
                static_cast<unsigned long long>(seed), ate_widened, ate_trusted, bias.tested_m, bias.sigma_m,
                ate_no_fixes, ate_no_fixes_off);
    EXPECT_TRUE(bias.significant) << "seed " << seed;
    EXPECT_GT(bias.tested_m, 0.0) << "seed " << seed;
    EXPECT_LT(ate_widened, 0.75 * ate_trusted) << "seed " << seed;
    EXPECT_EQ(ate_no_fixes, ate_no_fixes_off) << "seed " << seed << ": no fixes, nothing widened";
  }
}

// Closures along one line (B ahead of A on the same track) or across it are not opposite-side pairs:
// they take no bias. Cross lines (B's heading 90 deg off) neither.
TEST(SeparationBias, OnlyParallelPairsOffToTheSideTakeIt) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(goodInsMissionOptions(1));
  synthetic::Mission turned = mission;
  for (synthetic::Closure& c : turned.closures) {
    // Rotate B's frame by 90 deg about down: B crosses A's line.
    c.closure.T_a_b.rotation = c.closure.T_a_b.rotation * sss::core::quaternionFromEuler(0.0, 0.0, M_PI / 2.0);
  }
  PoseGraphOptions options = withBias(graphOptions());
  options.gate_chi2 = 1e12;  // the turned closures disagree with DR; only the bookkeeping is tested
  options.pcm_chi2 = 1e12;
  options.robust_loss = "none";
  const Solved crossing = smooth(turned, options);
  EXPECT_EQ(crossing.bias.closures, 0);
  EXPECT_EQ(crossing.bias.estimate_m, 0.0);
}

// The applied bias survives a checkpoint (window updates after a restore use it); a version 2
// checkpoint, written before the bias existed, restores with none.
TEST(SeparationBias, SurvivesACheckpointAndOlderCheckpointsRestoreWithout) {
  const synthetic::Mission biased = shortened(synthetic::makeLawnmowerMission(goodInsMissionOptions(2)), 1.5);
  const PoseGraphOptions options = withBias(graphOptions());
  SlidingWindowPoseGraph graph(options);
  feed(graph, biased, 0, biased.nodes.size());
  ASSERT_TRUE(graph.fullSmoothing().ok);
  ASSERT_TRUE(graph.separationBias().applied);
  ASSERT_TRUE(graph.separationBias().significant);
  const std::string text = graph.checkpointText();
  SlidingWindowPoseGraph restored(options);
  ASSERT_TRUE(restored.restoreCheckpointText(text).ok);
  EXPECT_EQ(restored.separationBias().estimate_m, graph.separationBias().estimate_m);
  EXPECT_EQ(restored.separationBias().tested_m, graph.separationBias().tested_m);
  EXPECT_EQ(restored.separationBias().sigma_m, graph.separationBias().sigma_m);
  EXPECT_EQ(restored.separationBias().closures, graph.separationBias().closures);
  EXPECT_TRUE(restored.separationBias().applied);
  EXPECT_TRUE(restored.separationBias().significant);

  // The same state as version 2 wrote it: no separation_bias record (nor version 4's fixes record
  // and version 5's calibration record).
  std::string version_2 = text;
  const std::string header = "sss-pose-graph-checkpoint 7";
  ASSERT_EQ(version_2.rfind(header, 0), 0u) << version_2.substr(0, 40);
  version_2.replace(0, header.size(), "sss-pose-graph-checkpoint 2");
  const size_t record = version_2.find("\nseparation_bias ");
  ASSERT_NE(record, std::string::npos);
  version_2.erase(record, version_2.find('\n', record + 1) - record);
  for (const char* newer : {"\nfixes ", "\ncalibration ", "\nanchor "}) {
    const size_t newer_record = version_2.find(newer);
    ASSERT_NE(newer_record, std::string::npos) << newer;
    version_2.erase(newer_record, version_2.find('\n', newer_record + 1) - newer_record);
  }
  SlidingWindowPoseGraph older(options);
  const Status status = older.restoreCheckpointText(version_2);
  ASSERT_TRUE(status.ok) << status.message;
  EXPECT_EQ(older.separationBias().estimate_m, 0.0);
  EXPECT_FALSE(older.separationBias().applied);
  EXPECT_EQ(older.nodes().size(), graph.nodes().size());
}

TEST(SeparationBias, BadOptionsAreNamed) {
  PoseGraphOptions options;
  options.separation_bias_sigma_m = -1.0;
  std::vector<std::string> problems = validatePoseGraphOptions(options);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("separation_bias_sigma_m"), std::string::npos);
  options = PoseGraphOptions();
  options.separation_bias_min_lateral_m = -5.0;
  problems = validatePoseGraphOptions(options);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("separation_bias_min_lateral_m"), std::string::npos);
  options = PoseGraphOptions();
  options.separation_bias_significance = -1.0;
  problems = validatePoseGraphOptions(options);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("separation_bias_significance"), std::string::npos);
}

}  // namespace
}  // namespace sss::optimiser
