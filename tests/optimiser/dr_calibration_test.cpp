// DR sensor calibration in the pose graph (PoseGraphOptions::calibration): DVL scale factor and the
// INS heading error b + a_c cos(psi) + a_s sin(psi), estimated at full smoothing once fixes are
// accepted. The synthetic lawnmower's DR has a known scale error and a steaming error b cos(psi).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "pipeline/optimiser/pose_graph.hpp"
#include "tools/fixtures/synthetic_mission.hpp"
#include "tests/optimiser/pose_graph_test_helpers.hpp"

namespace sss::optimiser {
namespace {

using namespace test_helpers;

// A 2 % scale error and a 0.5 deg steaming error, no other heading error: both are found within
// 2 sigma, the constant bias and a_s (zero in truth) too, and the ATE improves on fixes alone.
TEST(DrCalibration, ScaleAndSteamingErrorAreRecoveredFromFixes) {
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    synthetic::MissionOptions o = missionOptions(seed);
    o.velocity_scale_error = 0.02;
    o.heading_bias_rad = 0.0087;  // 0.5 deg: + heading north, - heading south
    o.heading_noise_sigma_rad = 0.0;
    const synthetic::Mission mission = synthetic::makeLawnmowerMission(o);
    PoseGraphOptions never = graphOptions();
    never.calibration = "never";
    const SlidingWindowPoseGraph fixes_only = solvedWithUsbl(mission, never, true, seed);
    const SlidingWindowPoseGraph calibrated = solvedWithUsbl(mission, graphOptions(), true, seed);
    const DrCalibration& c = calibrated.calibration();
    ASSERT_TRUE(c.estimated);
    EXPECT_FALSE(fixes_only.calibration().estimated);
    const double ate_fixes = synthetic::translationRmse(estimates(fixes_only), mission.nodes);
    const double ate_calibrated = synthetic::translationRmse(estimates(calibrated), mission.nodes);
    std::printf("seed %llu: scale %.5f +- %.5f (0.02), b %.5f +- %.5f (0), a_c %.5f +- %.5f (0.0087), a_s %.5f +- %.5f "
                "(0); ATE fixes %.3f, fixes + calibration %.3f m\n",
                static_cast<unsigned long long>(seed), c.dvl_scale, c.sigma(0), c.heading_bias_rad, c.sigma(1),
                c.heading_cos_rad, c.sigma(2), c.heading_sin_rad, c.sigma(3), ate_fixes, ate_calibrated);
    EXPECT_LT(std::abs(c.dvl_scale - 0.02), 2.0 * c.sigma(0));
    EXPECT_LT(std::abs(c.heading_bias_rad), 2.0 * c.sigma(1));
    EXPECT_LT(std::abs(c.heading_cos_rad - 0.0087), 2.0 * c.sigma(2));
    EXPECT_LT(std::abs(c.heading_sin_rad), 2.0 * c.sigma(3));
    // Ten 1 m fixes 200 m apart observe the scale to ~1.4 m / 200 m / sqrt(8): well below its prior.
    EXPECT_LT(c.sigma(0), 0.6 * never.calibration_scale_sigma) << "fixes observe the scale";
    EXPECT_LT(c.sigma(2), 0.3 * never.calibration_heading_deviation_sigma_rad) << "and the steaming error";
    EXPECT_LT(ate_calibrated, ate_fixes);
  }
}

// Without fixes "auto" leaves the graph as it was (bit-identical), and "always" keeps the sigma of
// what closures cannot see at its prior.
TEST(DrCalibration, WithoutFixesNothingChangesAndUnobservedSigmasStayAtThePrior) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(2));
  PoseGraphOptions never = graphOptions();
  never.calibration = "never";
  const SlidingWindowPoseGraph plain = solvedWithUsbl(mission, never, false, 2);
  const SlidingWindowPoseGraph automatic = solvedWithUsbl(mission, graphOptions(), false, 2);
  EXPECT_FALSE(automatic.calibration().estimated);
  EXPECT_TRUE(std::isnan(automatic.calibration().sigma(0)));
  const auto a = estimates(plain), b = estimates(automatic);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].translation, b[i].translation) << i;
    EXPECT_EQ(a[i].rotation.coeffs(), b[i].rotation.coeffs()) << i;
  }
  PoseGraphOptions always = graphOptions();
  always.calibration = "always";
  const SlidingWindowPoseGraph closures_only = solvedWithUsbl(mission, always, false, 2);
  const DrCalibration& c = closures_only.calibration();
  ASSERT_TRUE(c.estimated);
  std::printf("closures only: sigma scale %.5f, b %.5f, a_c %.5f, a_s %.5f (priors %.4f)\n", c.sigma(0), c.sigma(1),
              c.sigma(2), c.sigma(3), always.calibration_scale_sigma);
  // A constant heading bias rotates the survey about its start: nothing relative sees it.
  EXPECT_GT(c.sigma(1), 0.9 * always.calibration_heading_bias_sigma_rad);
}

// "heading": without fixes the closures of reversed lines find the steaming error a_c, and the scale
// is left alone (0, sigma NaN): what they say of it comes through the turns' length, where the
// matcher's separation bias looks the same.
TEST(DrCalibration, HeadingModeFindsTheSteamingErrorFromClosuresAlone) {
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    synthetic::MissionOptions o = missionOptions(seed);
    o.heading_bias_rad = 0.0087;
    o.heading_noise_sigma_rad = 0.0;
    const synthetic::Mission mission = synthetic::makeLawnmowerMission(o);
    PoseGraphOptions heading = graphOptions();
    heading.calibration = "heading";
    const SlidingWindowPoseGraph graph = solvedWithUsbl(mission, heading, false, seed);
    const DrCalibration& c = graph.calibration();
    std::printf("seed %llu: a_c %.5f +- %.5f (0.0087), a_s %.5f +- %.5f (0), scale %.5f +- %.5f\n",
                static_cast<unsigned long long>(seed), c.heading_cos_rad, c.sigma(2), c.heading_sin_rad, c.sigma(3),
                c.dvl_scale, c.sigma(0));
    ASSERT_TRUE(c.estimated);
    EXPECT_FALSE(c.scale_estimated);
    EXPECT_EQ(c.dvl_scale, 0.0);
    EXPECT_TRUE(std::isnan(c.sigma(0)));
    EXPECT_LT(std::abs(c.heading_cos_rad - 0.0087), 2.0 * c.sigma(2));
    EXPECT_LT(c.sigma(2), 0.5 * heading.calibration_heading_deviation_sigma_rad) << "closures observe a_c";
    EXPECT_GT(c.sigma(1), 0.9 * heading.calibration_heading_bias_sigma_rad) << "but not the constant bias";
  }
}

// On the vehicle the calibration is re-estimated while the mission runs (calibration_period_s): the
// window's estimate is calibrated before the end, as well as a post-processing run would be; with
// period 0 nothing is estimated until the end-of-mission smoothing.
TEST(DrCalibration, IsReEstimatedWhileTheMissionRuns) {
  synthetic::MissionOptions o = missionOptions(5);
  o.velocity_scale_error = 0.02;
  o.heading_bias_rad = 0.0087;
  o.heading_noise_sigma_rad = 0.0;
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(o);
  const double mission_s = 1e-6 * static_cast<double>(mission.nodes.back().utime_us - mission.nodes.front().utime_us);
  for (double period_s : {0.0, 300.0}) {
    PoseGraphOptions options = graphOptions();
    options.calibration_period_s = period_s;
    std::mt19937_64 random(5);
    SlidingWindowPoseGraph graph(options);
    for (size_t i = 0; i < mission.nodes.size(); ++i) {
      const synthetic::Node& n = mission.nodes[i];
      ASSERT_TRUE(graph.addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m).ok);
      for (const synthetic::Closure& c : mission.closures)
        if (c.newer_node == static_cast<int>(i)) {
          ASSERT_TRUE(graph.addLoopClosure(c.closure).ok);
        }
      if (i % 2 == 0) {
        ASSERT_TRUE(graph.addFix(fixAt(n, 1.0, random, "usbl")).ok);
      }
      ASSERT_TRUE(graph.optimize().ok);
      // A full smoothing in place of an update still leaves the window bounded.
      const auto nodes = graph.nodes();
      const auto active = std::count_if(nodes.begin(), nodes.end(), [](const NodeState& s) { return !s.marginalised; });
      ASSERT_LE(active, options.window_size) << "node " << i;
    }
    const DrCalibration& c = graph.calibration();
    std::printf("period %.0f s of a %.0f s mission: %llu full smoothings, scale %.5f +- %.5f (0.02), a_c %.5f +- %.5f "
                "(0.0087)\n",
                period_s, mission_s, static_cast<unsigned long long>(graph.counters().full_smoothings), c.dvl_scale,
                c.sigma(0), c.heading_cos_rad, c.sigma(2));
    if (period_s == 0.0) {
      EXPECT_FALSE(c.estimated);
      EXPECT_EQ(graph.counters().full_smoothings, 0u);
      continue;
    }
    ASSERT_TRUE(c.estimated);
    // The first smoothing comes with the first accepted fix, then one per period of mission time.
    const auto periods = static_cast<uint64_t>(std::floor(mission_s / period_s));
    EXPECT_GE(graph.counters().full_smoothings, periods);
    EXPECT_LE(graph.counters().full_smoothings, periods + 1);
    EXPECT_LT(std::abs(c.dvl_scale - 0.02), 2.0 * c.sigma(0));
    EXPECT_LT(std::abs(c.heading_cos_rad - 0.0087), 2.0 * c.sigma(2));
    EXPECT_LT(c.sigma(2), 0.3 * options.calibration_heading_deviation_sigma_rad);
  }
}

// A smoothing during the mission leaves a fix newer than the newest node for the next node (the
// nearest in time); only the end of the mission ties it to the last one.
TEST(DrCalibration, ASmoothingDuringTheMissionLeavesNewerFixesForTheNextNode) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(6));
  PoseGraphOptions options = graphOptions();
  options.calibration = "heading";  // wanted from the first node: the first update is a smoothing
  SlidingWindowPoseGraph graph(options);
  std::mt19937_64 random(6);
  const synthetic::Node& first = mission.nodes[0];
  const synthetic::Node& second = mission.nodes[1];
  ASSERT_TRUE(graph.addNode(first.subframe_id, first.utime_us, first.dr, first.distance_m).ok);
  ASSERT_TRUE(graph.addFix(fixAt(second, 1.0, random)).ok);
  ASSERT_TRUE(graph.optimize().ok);
  ASSERT_EQ(graph.counters().full_smoothings, 1u);
  ASSERT_EQ(graph.fixes().size(), 1u);
  EXPECT_EQ(graph.fixes()[0].status, FixStatus::kPending);
  EXPECT_EQ(graph.fixes()[0].subframe_id, -1);
  ASSERT_TRUE(graph.addNode(second.subframe_id, second.utime_us, second.dr, second.distance_m).ok);
  ASSERT_TRUE(graph.optimize().ok);
  EXPECT_EQ(graph.fixes()[0].subframe_id, second.subframe_id);
}

// The calibration survives a checkpoint, and a restored graph goes on exactly as the original.
TEST(DrCalibration, SurvivesACheckpoint) {
  synthetic::MissionOptions o = missionOptions(3);
  o.velocity_scale_error = 0.01;
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(o);
  SlidingWindowPoseGraph graph = solvedWithUsbl(mission, graphOptions(), true, 3);
  ASSERT_TRUE(graph.calibration().estimated);
  SlidingWindowPoseGraph restored(graphOptions());
  const Status status = restored.restoreCheckpointText(graph.checkpointText());
  ASSERT_TRUE(status.ok) << status.message;
  EXPECT_TRUE(restored.calibration().estimated);
  EXPECT_EQ(restored.calibration().dvl_scale, graph.calibration().dvl_scale);
  EXPECT_EQ(restored.calibration().heading_cos_rad, graph.calibration().heading_cos_rad);
  EXPECT_EQ(restored.calibration().sigma, graph.calibration().sigma);
  ASSERT_TRUE(graph.optimize().ok);
  ASSERT_TRUE(restored.optimize().ok);
  const auto a = estimates(graph), b = estimates(restored);
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].translation, b[i].translation) << i;

  // A version 5 file has no time of the last calibration nor the scale flag (version 6's last two
  // fields of the record): the next update re-estimates it.
  std::string version_5 = graph.checkpointText();
  const std::string header = "sss-pose-graph-checkpoint 7";
  ASSERT_EQ(version_5.rfind(header, 0), 0u) << version_5.substr(0, 40);
  version_5.replace(0, header.size(), "sss-pose-graph-checkpoint 5");
  const size_t anchor_record = version_5.find("\nanchor ");  // version 7's
  ASSERT_NE(anchor_record, std::string::npos);
  version_5.erase(anchor_record, version_5.find('\n', anchor_record + 1) - anchor_record);
  const size_t record = version_5.find("\ncalibration ");
  ASSERT_NE(record, std::string::npos);
  const size_t end = version_5.find('\n', record + 1);
  const size_t last_two_fields = version_5.rfind(' ', version_5.rfind(' ', end) - 1);
  version_5.erase(last_two_fields, end - last_two_fields);
  SlidingWindowPoseGraph older(graphOptions());
  const Status older_status = older.restoreCheckpointText(version_5);
  ASSERT_TRUE(older_status.ok) << older_status.message;
  EXPECT_EQ(older.calibration().dvl_scale, graph.calibration().dvl_scale);
  const uint64_t smoothings = older.counters().full_smoothings;
  ASSERT_TRUE(older.optimize().ok);
  EXPECT_EQ(older.counters().full_smoothings, smoothings + 1);
}

TEST(DrCalibration, BadOptionsAreNamed) {
  PoseGraphOptions options;
  options.calibration = "sometimes";
  options.calibration_scale_sigma = 0.0;
  const std::vector<std::string> problems = validatePoseGraphOptions(options);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("calibration must be one of auto, heading, always, never"), std::string::npos) << problems[0];
  EXPECT_NE(problems[1].find("calibration_scale_sigma"), std::string::npos) << problems[1];
}

}  // namespace
}  // namespace sss::optimiser
