// Absolute position fixes in the pose graph (SlidingWindowPoseGraph::addFix): GNSS at the start and
// the end of a drifting lawnmower, USBL with outliers, a fix between nodes, checkpoints and refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <random>

#include "pipeline/optimiser/pose_graph.hpp"
#include "tools/fixtures/synthetic_mission.hpp"
#include "tests/optimiser/pose_graph_test_helpers.hpp"

namespace sss::optimiser {
namespace {

using namespace test_helpers;

double error(const SlidingWindowPoseGraph& graph, const synthetic::Mission& mission, size_t node) {
  return (graph.nodes()[node].T_world_body.translation - mission.nodes[node].truth.translation).head<2>().norm();
}

// Feeds the mission node by node with its closures (when asked) and the fixes due at each node.
void feedWithFixes(SlidingWindowPoseGraph& graph, const synthetic::Mission& mission, bool closures,
                   const std::vector<std::pair<size_t, AbsoluteFix>>& fixes) {
  for (size_t i = 0; i < mission.nodes.size(); ++i) {
    const synthetic::Node& n = mission.nodes[i];
    ASSERT_TRUE(graph.addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m).ok);
    for (const synthetic::Closure& c : mission.closures) {
      if (closures && c.newer_node == static_cast<int>(i)) {
        ASSERT_TRUE(graph.addLoopClosure(c.closure).ok);
      }
    }
    for (const auto& [node, fix] : fixes) {
      if (node == i) {
        ASSERT_TRUE(graph.addFix(fix).ok);
      }
    }
    ASSERT_TRUE(graph.optimize().ok);
  }
  ASSERT_TRUE(graph.fullSmoothing().ok);
}

// GNSS (1 m) at the dive and at the surfacing: the end, where DR drifted furthest, comes back to
// within the fix's accuracy, and over the seeds the survey is better than with closures alone (on
// one mission the fixes' own noise may outweigh what they add to a start already known exactly).
TEST(PositionFixGraph, GnssAtStartAndEndBoundsTheDrift) {
  double sum_closures = 0.0, sum_fixes = 0.0;
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(seed));
    const size_t last = mission.nodes.size() - 1;
    std::mt19937_64 random(seed * 77);
    const std::vector<std::pair<size_t, AbsoluteFix>> fixes = {{0, fixAt(mission.nodes[0], 1.0, random)},
                                                               {last, fixAt(mission.nodes[last], 1.0, random)}};
    SlidingWindowPoseGraph closures_only(graphOptions());
    feedWithFixes(closures_only, mission, true, {});
    SlidingWindowPoseGraph with_fixes(graphOptions());
    feedWithFixes(with_fixes, mission, true, fixes);
    SlidingWindowPoseGraph fixes_only(graphOptions());
    feedWithFixes(fixes_only, mission, false, fixes);

    const double ate_dr = synthetic::translationRmse(synthetic::drPoses(mission), mission.nodes);
    const double ate_closures = synthetic::translationRmse(estimates(closures_only), mission.nodes);
    const double ate_fixes = synthetic::translationRmse(estimates(with_fixes), mission.nodes);
    const double ate_dr_fixed = synthetic::translationRmse(estimates(fixes_only), mission.nodes);
    std::printf("seed %llu: ATE DR %.2f, DR + fixes %.2f, closures %.2f, closures + fixes %.2f m; end %.2f -> %.2f m\n",
                static_cast<unsigned long long>(seed), ate_dr, ate_dr_fixed, ate_closures, ate_fixes,
                (mission.nodes[last].dr.translation - mission.nodes[last].truth.translation).head<2>().norm(),
                error(with_fixes, mission, last));
    EXPECT_EQ(with_fixes.fixCounters().accepted, 2u);
    EXPECT_LT(error(with_fixes, mission, last), 3.0);  // 1 m per axis: 3 sigma of the 2-D error
    sum_closures += ate_closures;
    sum_fixes += ate_fixes;
    EXPECT_LT(ate_dr_fixed, 0.4 * ate_dr);
    for (const FixRecord& r : with_fixes.fixes()) {
      EXPECT_EQ(r.status, FixStatus::kAccepted);
      EXPECT_LT(r.residual_ne_m.norm(), 3.0);
    }
    EXPECT_EQ(with_fixes.correctionAt(mission.nodes[last].utime_us).status, CorrectionStatus::kCorrected);
    EXPECT_EQ(fixes_only.correctionAt(mission.nodes[last].utime_us).status, CorrectionStatus::kCorrected);
  }
  EXPECT_LT(sum_fixes, sum_closures);
}

// A systematic drift (0.3 deg heading bias, 0.4 % DVL scale) over a long survey with GNSS only at
// the dive and at the surfacing: the window's covariance grows with the square root of the distance
// and alone would gate the good end fixes out (measured on a randomised mission: 20 m off after
// 5 km, chi-square 30-67, SLAM 11.5 m against DR's 8.8 m). The gate adds the drift the calibration's
// priors allow since the last tied-down node: every fix is accepted and the end comes back.
TEST(PositionFixGraph, EndFixesAfterALongSystematicDriftAreNotGatedOut) {
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    synthetic::MissionOptions o = missionOptions(seed);
    o.num_lines = 8;
    o.line_length_m = 800.0;
    o.heading_bias_rad = 0.005;
    o.velocity_scale_error = 0.004;
    const synthetic::Mission mission = synthetic::makeLawnmowerMission(o);
    const size_t last = mission.nodes.size() - 1;
    std::mt19937_64 random(seed * 101);
    const std::vector<std::pair<size_t, AbsoluteFix>> fixes = {{0, fixAt(mission.nodes[0], 1.5, random)},
                                                               {1, fixAt(mission.nodes[1], 1.5, random)},
                                                               {last - 1, fixAt(mission.nodes[last - 1], 1.5, random)},
                                                               {last, fixAt(mission.nodes[last], 1.5, random)}};
    SlidingWindowPoseGraph graph(graphOptions());
    feedWithFixes(graph, mission, false, fixes);
    const double end_dr_m = (mission.nodes[last].dr.translation - mission.nodes[last].truth.translation).head<2>().norm();
    std::printf("seed %llu: DR end %.1f m off, after the fixes %.2f m; accepted %llu, rejected %llu\n",
                static_cast<unsigned long long>(seed), end_dr_m, error(graph, mission, last),
                static_cast<unsigned long long>(graph.fixCounters().accepted),
                static_cast<unsigned long long>(graph.fixCounters().rejected_gate));
    EXPECT_GT(end_dr_m, 15.0) << "seed " << seed << ": the drift this test is about";
    EXPECT_EQ(graph.fixCounters().accepted, 4u) << "seed " << seed;
    EXPECT_LT(error(graph, mission, last), 4.5) << "seed " << seed;
  }
}

// USBL (1 m) at every node with one in five 15-40 m off: the gate refuses every outlier, keeps
// nearly every good fix, and the estimate follows the good ones.
TEST(PositionFixGraph, UsblOutliersAreRejectedByTheGate) {
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(seed));
    std::mt19937_64 random(seed * 991);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::vector<std::pair<size_t, AbsoluteFix>> fixes;
    std::vector<bool> outlier;
    for (size_t i = 0; i < mission.nodes.size(); ++i) {
      AbsoluteFix fix = fixAt(mission.nodes[i], 1.0, random, "usbl");
      const bool bad = i % 5 == 2;
      if (bad) {
        const double distance_m = 15.0 + 25.0 * uniform(random), angle = 2.0 * M_PI * uniform(random);
        fix.position_ne_m += distance_m * Eigen::Vector2d(std::cos(angle), std::sin(angle));
      }
      fixes.push_back({i, fix});
      outlier.push_back(bad);
    }
    SlidingWindowPoseGraph graph(graphOptions());
    feedWithFixes(graph, mission, true, fixes);
    const std::vector<FixRecord> records = graph.fixes();
    ASSERT_EQ(records.size(), fixes.size());
    int good_accepted = 0, good = 0;
    for (size_t i = 0; i < records.size(); ++i) {
      if (outlier[i]) {
        EXPECT_EQ(records[i].status, FixStatus::kRejected) << "outlier " << i << " chi2 " << records[i].innovation_chi2;
      } else {
        ++good;
        good_accepted += records[i].status == FixStatus::kAccepted;
      }
    }
    const double ate = synthetic::translationRmse(estimates(graph), mission.nodes);
    std::printf("seed %llu: USBL good fixes accepted %d of %d, outliers rejected %llu; ATE %.2f m\n",
                static_cast<unsigned long long>(seed), good_accepted, good,
                static_cast<unsigned long long>(graph.fixCounters().rejected_gate), ate);
    EXPECT_GE(good_accepted, good - 1);
    EXPECT_LT(ate, 1.0);  // sixteen 1 m fixes and the closures
  }
}

// A fix half way between two nodes ties to the nearer one through DR and pulls the survey to it.
TEST(PositionFixGraph, FixBetweenNodesTiesToTheNearestThroughDr) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(3));
  const size_t last = mission.nodes.size() - 1;
  const synthetic::Node& a = mission.nodes[last - 1];
  const synthetic::Node& b = mission.nodes[last];
  AbsoluteFix fix;
  fix.utime_us = a.utime_us + (b.utime_us - a.utime_us) * 7 / 10;  // nearer b
  fix.position_ne_m = (0.3 * a.truth.translation + 0.7 * b.truth.translation).head<2>();
  fix.covariance_m2 = 0.25 * Eigen::Matrix2d::Identity();
  fix.dr_position_m = 0.3 * a.dr.translation + 0.7 * b.dr.translation;  // same line: straight
  fix.dr_distance_m = 0.3 * a.distance_m + 0.7 * b.distance_m;
  SlidingWindowPoseGraph graph(graphOptions());
  feedWithFixes(graph, mission, false, {{last - 1, fix}});
  const std::vector<FixRecord> records = graph.fixes();
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].subframe_id, b.subframe_id);
  EXPECT_EQ(records[0].status, FixStatus::kAccepted);
  EXPECT_LT(records[0].residual_ne_m.norm(), 0.5);
  EXPECT_LT(error(graph, mission, last), 1.0);
}

// The fixes and their decisions survive a checkpoint; the restored graph goes on identically.
TEST(PositionFixGraph, CheckpointCarriesTheFixes) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(2));
  std::mt19937_64 random(5);
  SlidingWindowPoseGraph graph(graphOptions());
  const size_t half = mission.nodes.size() / 2;
  for (size_t i = 0; i < half; ++i) {
    const synthetic::Node& n = mission.nodes[i];
    ASSERT_TRUE(graph.addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m).ok);
    ASSERT_TRUE(graph.addFix(fixAt(n, 1.0, random, i % 2 ? "usbl" : "gnss")).ok);
    ASSERT_TRUE(graph.optimize().ok);
  }
  AbsoluteFix waiting = fixAt(mission.nodes[half], 1.0, random);  // no node at its time yet
  ASSERT_TRUE(graph.addFix(waiting).ok);
  const std::string path = (std::filesystem::temp_directory_path() / "position_fix_graph_checkpoint.txt").string();
  ASSERT_TRUE(graph.saveCheckpoint(path).ok);
  SlidingWindowPoseGraph restored(graphOptions());
  ASSERT_TRUE(restored.loadCheckpoint(path).ok);
  std::filesystem::remove(path);
  ASSERT_EQ(restored.fixes().size(), graph.fixes().size());
  EXPECT_EQ(restored.fixCounters().accepted, graph.fixCounters().accepted);
  for (size_t i = 0; i < graph.fixes().size(); ++i) {
    EXPECT_EQ(restored.fixes()[i].status, graph.fixes()[i].status);
    EXPECT_EQ(restored.fixes()[i].subframe_id, graph.fixes()[i].subframe_id);
    EXPECT_EQ(restored.fixes()[i].fix.source, graph.fixes()[i].fix.source);
  }
  EXPECT_EQ(restored.fixes().back().subframe_id, -1);

  // Version 3 (before fixes and calibration) restores without either.
  SlidingWindowPoseGraph no_fixes(graphOptions());
  {
    SlidingWindowPoseGraph plain(graphOptions());
    for (size_t i = 0; i < half; ++i) {
      const synthetic::Node& n = mission.nodes[i];
      ASSERT_TRUE(plain.addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m).ok);
      ASSERT_TRUE(plain.optimize().ok);
    }
    std::string version_3 = plain.checkpointText();
    const std::string header = "sss-pose-graph-checkpoint 7";
    ASSERT_EQ(version_3.rfind(header, 0), 0u);
    version_3.replace(0, header.size(), "sss-pose-graph-checkpoint 3");
    for (const char* newer : {"\nfixes ", "\ncalibration ", "\nanchor "}) {
      const size_t record = version_3.find(newer);
      ASSERT_NE(record, std::string::npos) << newer;
      version_3.erase(record, version_3.find('\n', record + 1) - record);
    }
    const Status status = no_fixes.restoreCheckpointText(version_3);
    ASSERT_TRUE(status.ok) << status.message;
    EXPECT_TRUE(no_fixes.fixes().empty());
    EXPECT_EQ(no_fixes.nodes().size(), half);
  }
  for (SlidingWindowPoseGraph* g : {&graph, &restored}) {
    for (size_t i = half; i < mission.nodes.size(); ++i) {
      const synthetic::Node& n = mission.nodes[i];
      ASSERT_TRUE(g->addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m).ok);
      ASSERT_TRUE(g->optimize().ok);
    }
    ASSERT_TRUE(g->fullSmoothing().ok);
  }
  const auto a = estimates(graph), b = estimates(restored);
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].translation, b[i].translation) << i;
}

// The INS knew where the survey started only to a few metres (its reported accuracy), and DR's
// start is 5 m off the truth. With the anchor at first_node_sigma_m (0.1 m) the fixes cannot move
// the start: the first one is gated out and the survey stays shifted. With the anchor at the INS's
// reported 4 m the fixes bring the whole survey back. Without fixes the anchor changes nothing but
// the reported covariance.
TEST(PositionFixGraph, FirstNodeAnchorFollowsTheInsAccuracy) {
  synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(3));
  const Eigen::Vector3d start_error_m(4.0, -3.0, 0.0);
  for (synthetic::Node& n : mission.nodes) n.dr.translation += start_error_m;
  const size_t last = mission.nodes.size() - 1;
  std::mt19937_64 random(99);
  const std::vector<std::pair<size_t, AbsoluteFix>> fixes = {{0, fixAt(mission.nodes[0], 1.0, random)},
                                                             {last, fixAt(mission.nodes[last], 1.0, random)}};
  SlidingWindowPoseGraph tight(graphOptions());
  feedWithFixes(tight, mission, true, fixes);
  SlidingWindowPoseGraph widened(graphOptions());
  ASSERT_TRUE(widened.setFirstNodeHorizontalSigma(4.0, 4.0).ok);  // before the first node
  feedWithFixes(widened, mission, true, fixes);
  const double ate_tight = synthetic::translationRmse(estimates(tight), mission.nodes);
  const double ate_widened = synthetic::translationRmse(estimates(widened), mission.nodes);
  std::printf("DR start 5 m off: first node error %.2f m (anchor 0.1 m) vs %.2f m (INS 4 m); ATE %.2f vs %.2f m; "
              "fixes accepted %llu vs %llu\n",
              error(tight, mission, 0), error(widened, mission, 0), ate_tight, ate_widened,
              static_cast<unsigned long long>(tight.fixCounters().accepted),
              static_cast<unsigned long long>(widened.fixCounters().accepted));
  EXPECT_GT(error(tight, mission, 0), 4.5);
  EXPECT_LT(error(widened, mission, 0), 2.0);
  EXPECT_EQ(widened.fixCounters().accepted, 2u);
  EXPECT_LT(ate_widened, 0.5 * ate_tight);
  EXPECT_EQ(widened.firstNodeInsSigma(), Eigen::Vector2d(4.0, 4.0));

  // first_node_sigma_from_ins off: the INS's report is kept but the anchor stays first_node_sigma_m.
  PoseGraphOptions distrusting = graphOptions();
  distrusting.first_node_sigma_from_ins = false;
  SlidingWindowPoseGraph ignored(distrusting);
  ASSERT_TRUE(ignored.setFirstNodeHorizontalSigma(4.0, 4.0).ok);
  feedWithFixes(ignored, mission, true, fixes);
  EXPECT_NEAR(error(ignored, mission, 0), error(tight, mission, 0), 1e-3);

  // Without fixes the anchor only places the survey: the same estimate, a wider first-node sigma.
  SlidingWindowPoseGraph plain(graphOptions()), plain_widened(graphOptions());
  ASSERT_TRUE(plain_widened.setFirstNodeHorizontalSigma(4.0, 3.0).ok);
  feedWithFixes(plain, mission, true, {});
  feedWithFixes(plain_widened, mission, true, {});
  const auto a = estimates(plain), b = estimates(plain_widened);
  for (size_t i = 0; i < a.size(); ++i) EXPECT_LT((a[i].translation - b[i].translation).norm(), 1e-3) << i;
  const int64_t first_id = mission.nodes[0].subframe_id;
  EXPECT_NEAR(std::sqrt((*plain.covariance(first_id))(0, 0)), 0.1, 0.01);
  EXPECT_NEAR(std::sqrt((*plain_widened.covariance(first_id))(0, 0)), 4.0, 0.1);
  EXPECT_NEAR(std::sqrt((*plain_widened.covariance(first_id))(1, 1)), 3.0, 0.1);

  // Kept by the checkpoint; refused once the first node has left the window, or when not a sigma.
  SlidingWindowPoseGraph restored(graphOptions());
  ASSERT_TRUE(restored.restoreCheckpointText(plain_widened.checkpointText()).ok);
  EXPECT_EQ(restored.firstNodeInsSigma(), Eigen::Vector2d(4.0, 3.0));
  const Status late = plain.setFirstNodeHorizontalSigma(2.0, 2.0);
  EXPECT_FALSE(late.ok);
  EXPECT_NE(late.message.find("marginalised"), std::string::npos) << late.message;
  SlidingWindowPoseGraph fresh(graphOptions());
  EXPECT_FALSE(fresh.setFirstNodeHorizontalSigma(-1.0, 2.0).ok);
  EXPECT_FALSE(fresh.setFirstNodeHorizontalSigma(std::nan(""), 2.0).ok);
  EXPECT_EQ(fresh.firstNodeInsSigma(), Eigen::Vector2d::Zero());
}

// A GNSS receiver at the surface logs a fix a second for the minute before the dive; its error (here 2.0 m north,
// -1.5 m east, 1.5 m per axis as its GST says) is common to the whole minute, as a receiver's
// error changes over minutes. Taken as 60 independent fixes the start would be claimed known to
// 0.19 m while it is 2.5 m off; weighted by their correlation (300 s) the minute is worth about one
// fix and the start's covariance covers its error. The gate still tests every fix against its own
// sigma: a fix 15 m off after the minute is refused although it enters with 1/600 of its
// information. USBL fixes are weighted on their own (independent by default).
TEST(PositionFixGraph, CorrelatedGnssFixesCountAsTheInformationTheyHold) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(1));
  const synthetic::Node& first = mission.nodes[0];
  const Eigen::Vector2d common_error_m(2.0, -1.5);
  std::mt19937_64 random(17);
  std::normal_distribution<double> receiver_noise(0.0, 0.05);
  std::vector<AbsoluteFix> minute;
  for (int second = 0; second < 60; ++second) {
    AbsoluteFix fix = fixAt(first, 1.5, random);
    fix.utime_us = first.utime_us - (59 - second) * 1000000LL;  // the minute before the dive, at the first node's position
    fix.position_ne_m = first.truth.translation.head<2>() + common_error_m +
                        Eigen::Vector2d(receiver_noise(random), receiver_noise(random));
    minute.push_back(fix);
  }
  // The first node with the minute's fixes, three more nodes (after_first_update runs once the
  // second is in the estimate), then full smoothing.
  auto solveWithTheMinute = [&](SlidingWindowPoseGraph& graph, const std::function<void()>& after_first_update) {
    ASSERT_TRUE(graph.setFirstNodeHorizontalSigma(10.0, 10.0).ok);  // the INS barely knew the start
    ASSERT_TRUE(graph.addNode(first.subframe_id, first.utime_us, first.dr, first.distance_m).ok);
    for (const AbsoluteFix& fix : minute) ASSERT_TRUE(graph.addFix(fix).ok);
    for (size_t i = 1; i < 4; ++i) {
      const synthetic::Node& n = mission.nodes[i];
      ASSERT_TRUE(graph.addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m).ok);
      ASSERT_TRUE(graph.optimize().ok);
      if (i == 1) after_first_update();
    }
    ASSERT_TRUE(graph.fullSmoothing().ok);
  };
  auto startNees = [&](double correlation_s, double* sigma_north_m) {
    PoseGraphOptions options = graphOptions();
    options.gnss_fix_correlation_s = correlation_s;
    options.calibration = "never";  // the start's position alone: no DVL scale or heading error to share it with
    SlidingWindowPoseGraph graph(options);
    solveWithTheMinute(graph, [] {});
    EXPECT_EQ(graph.fixCounters().accepted, 60u);
    const Eigen::Matrix2d covariance = graph.covariance(first.subframe_id)->topLeftCorner<2, 2>();
    const Eigen::Vector2d error = (graph.nodes()[0].T_world_body.translation - first.truth.translation).head<2>();
    *sigma_north_m = std::sqrt(covariance(0, 0));
    return error.dot(covariance.ldlt().solve(error));
  };
  double sigma_independent_m = 0.0, sigma_correlated_m = 0.0;
  const double nees_independent = startNees(0.0, &sigma_independent_m);
  const double nees_correlated = startNees(300.0, &sigma_correlated_m);
  std::printf("a minute of 1 Hz GNSS, 2.5 m off in common: start sigma %.2f m, NEES %.1f (independent) vs "
              "%.2f m, NEES %.1f (correlated over 300 s)\n",
              sigma_independent_m, nees_independent, sigma_correlated_m, nees_correlated);
  EXPECT_NEAR(sigma_independent_m, 1.5 / std::sqrt(60.0), 0.02);
  EXPECT_GT(nees_independent, 50.0);
  // One fix plus 59 times (1 - rho) / (1 + rho), rho = exp(-1 / 300): 1.10 fixes' worth.
  const double rho = std::exp(-1.0 / 300.0);
  const double worth = 1.0 + 59.0 * (1.0 - rho) / (1.0 + rho);
  EXPECT_NEAR(sigma_correlated_m, 1.5 / std::sqrt(worth + 1.5 * 1.5 / 100.0), 0.03);
  EXPECT_LT(nees_correlated, 5.99);  // chi-square 2 dof, 95 %

  PoseGraphOptions options = graphOptions();
  SlidingWindowPoseGraph graph(options);
  solveWithTheMinute(graph, [&] {  // the minute is in the estimate: two late fixes of its last second
    AbsoluteFix far = minute.back();
    far.utime_us += 500000;
    far.position_ne_m += Eigen::Vector2d(15.0, 0.0);
    ASSERT_TRUE(graph.addFix(far).ok);
    AbsoluteFix usbl = minute.back();
    usbl.utime_us += 700000;
    usbl.source = "usbl";
    ASSERT_TRUE(graph.addFix(usbl).ok);
  });
  const std::vector<FixRecord> records = graph.fixes();
  ASSERT_EQ(records.size(), 62u);
  EXPECT_DOUBLE_EQ(records[0].information_weight, 1.0);
  for (size_t i = 1; i < 60; ++i) EXPECT_NEAR(records[i].information_weight, (1.0 - rho) / (1.0 + rho), 1e-12) << i;
  const double rho_half = std::exp(-0.5 / 300.0);
  EXPECT_NEAR(records[60].information_weight, (1.0 - rho_half) / (1.0 + rho_half), 1e-12);
  EXPECT_EQ(records[60].status, FixStatus::kRejected) << "chi-square " << records[60].innovation_chi2;
  EXPECT_DOUBLE_EQ(records[61].information_weight, 1.0);  // the first USBL fix: another source
  EXPECT_EQ(records[61].status, FixStatus::kAccepted);

  // A restored graph weighs its fixes as the original did.
  SlidingWindowPoseGraph restored(options);
  ASSERT_TRUE(restored.restoreCheckpointText(graph.checkpointText()).ok);
  ASSERT_EQ(restored.fixes().size(), records.size());
  for (size_t i = 0; i < records.size(); ++i)
    EXPECT_DOUBLE_EQ(restored.fixes()[i].information_weight, records[i].information_weight) << i;

  PoseGraphOptions negative = graphOptions();
  negative.gnss_fix_correlation_s = -1.0;
  EXPECT_FALSE(validatePoseGraphOptions(negative).empty());
}

TEST(PositionFixGraph, BadFixesAreRefusedWithTheReason) {
  SlidingWindowPoseGraph graph(graphOptions());
  AbsoluteFix fix;
  fix.position_ne_m.x() = std::nan("");
  Status status = graph.addFix(fix);
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.message.find("not finite"), std::string::npos) << status.message;
  fix = AbsoluteFix();
  fix.covariance_m2 << 1.0, 2.0, 2.0, 1.0;  // indefinite
  status = graph.addFix(fix);
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.message.find("positive definite"), std::string::npos) << status.message;
  EXPECT_EQ(graph.fixCounters().refused, 2u);
  EXPECT_EQ(graph.fixCounters().received, 2u);
  EXPECT_TRUE(graph.fixes().empty());
}

}  // namespace
}  // namespace sss::optimiser
