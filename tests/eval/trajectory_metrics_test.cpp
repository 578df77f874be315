// Trajectory metrics: Umeyama recovers a known rigid transform, ATE of a constant offset, the
// gauge-free ATE (rotation and scale about the start removed, translation kept), RPE of a scale
// drift, association by time, and survey-line segmentation of simulated surveys.
#include "tools/eval/trajectory_metrics.hpp"

#include "tests/eval/eval_test_paths.hpp"
#include "tools/sim/seabed.hpp"
#include "tools/sim/trajectory.hpp"

#include <gtest/gtest.h>

#include <random>

namespace sss::eval {
namespace {

using sss::core::Pose;

TEST(ErrorStatistics, MatchesHandComputedValues) {
  const ErrorStatistics stats = errorStatistics({3.0, 1.0, 4.0, 2.0, std::nan("")});
  EXPECT_EQ(stats.count, 4u);  // NaN left out
  EXPECT_DOUBLE_EQ(stats.mean, 2.5);
  EXPECT_DOUBLE_EQ(stats.median, 2.5);
  EXPECT_DOUBLE_EQ(stats.max, 4.0);
  EXPECT_DOUBLE_EQ(stats.rmse, std::sqrt(30.0 / 4.0));
  EXPECT_DOUBLE_EQ(errorStatistics({5.0, 1.0, 3.0}).median, 3.0);
  EXPECT_TRUE(std::isnan(errorStatistics({}).rmse));
}

TEST(Umeyama, RecoversKnownRigidTransformExactly) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> metres(-200.0, 200.0), angle(-M_PI, M_PI);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose T(sss::core::quaternionFromEuler(angle(rng), 0.5 * angle(rng), angle(rng)),
                 Eigen::Vector3d(metres(rng), metres(rng), metres(rng)));
    std::vector<Eigen::Vector3d> source, target;
    for (int i = 0; i < 50; ++i) {
      source.emplace_back(metres(rng), metres(rng), 0.1 * metres(rng));
      target.push_back(T * source.back());
    }
    const std::optional<Pose> found = umeyamaAlignment(source, target);
    ASSERT_TRUE(found);
    EXPECT_LT(found->rotation.angularDistance(T.rotation), 1e-9);
    EXPECT_LT((found->translation - T.translation).norm(), 1e-9);
  }
}

TEST(Umeyama, HandlesDegenerateInputs) {
  EXPECT_FALSE(umeyamaAlignment({}, {}));
  EXPECT_FALSE(umeyamaAlignment({Eigen::Vector3d::Zero()}, {}));
  // One point: pure translation.
  const std::optional<Pose> one = umeyamaAlignment({Eigen::Vector3d(1, 2, 3)}, {Eigen::Vector3d(4, 6, 8)});
  ASSERT_TRUE(one);
  EXPECT_LT(one->rotation.angularDistance(Eigen::Quaterniond::Identity()), 1e-12);
  EXPECT_LT((one->translation - Eigen::Vector3d(3, 4, 5)).norm(), 1e-12);
  // Collinear points: any rotation about the line is optimal; the residual must be zero.
  const Pose T(sss::core::quaternionFromEuler(0.1, 0.2, 1.0), Eigen::Vector3d(5, -3, 2));
  std::vector<Eigen::Vector3d> source, target;
  for (int i = 0; i < 10; ++i) {
    source.emplace_back(i, 0.0, 0.0);
    target.push_back(T * source.back());
  }
  const std::optional<Pose> line = umeyamaAlignment(source, target);
  ASSERT_TRUE(line);
  for (size_t i = 0; i < source.size(); ++i) EXPECT_LT((*line * source[i] - target[i]).norm(), 1e-9);
}

TEST(Ate, ConstantOffsetIsTheOffsetRawAndZeroAligned) {
  const Trajectory truth = test::lawnmower(3, 200.0, 60.0);
  Trajectory estimate = truth;
  const Eigen::Vector3d offset(3.0, -4.0, 12.0);
  for (StampedPose& p : estimate) p.T_world_body.translation += offset;
  const TrajectoryEvaluation result = evaluateTrajectory(truth, estimate, segmentSurveyLines(truth));
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_EQ(result.association.exact, truth.size());
  EXPECT_NEAR(result.ate.position_m.rmse, 13.0, 1e-9);
  EXPECT_NEAR(result.ate.position_m.mean, 13.0, 1e-9);
  EXPECT_NEAR(result.ate.position_m.max, 13.0, 1e-9);
  EXPECT_NEAR(result.ate.horizontal_m.rmse, 5.0, 1e-9);
  EXPECT_NEAR(result.ate.horizontal_m.median, 5.0, 1e-9);
  EXPECT_NEAR(result.ate.vertical_m.rmse, 12.0, 1e-9);
  EXPECT_NEAR(result.ate.rotation_deg.max, 0.0, 1e-6);
  EXPECT_LT(result.ate.aligned_position_m.max, 1e-9);
  EXPECT_LT(result.ate.aligned_horizontal_m.max, 1e-9);
  EXPECT_LT((result.ate.T_truth_estimate.translation + offset).norm(), 1e-9);
  EXPECT_LT(result.ate.alignment_rotation_deg, 1e-7);
  // Every line sees the same offset; the error series too, split along/across track.
  ASSERT_EQ(result.lines.size(), 3u);
  for (const LineError& line : result.lines) EXPECT_NEAR(line.horizontal_m.rmse, 5.0, 1e-9);
  for (const ErrorSample& s : result.series) EXPECT_NEAR(std::hypot(s.along_track_m, s.across_track_m), 5.0, 1e-9);
  // On a northbound line, +3 north is ahead and -4 east is to port.
  EXPECT_NEAR(result.series[10].along_track_m, 3.0, 1e-9);
  EXPECT_NEAR(result.series[10].across_track_m, -4.0, 1e-9);
  // RPE is blind to a constant offset.
  for (const RpeResult& rpe : result.rpe) EXPECT_LT(rpe.translation_m.max, 1e-9);
}

TEST(Ate, RotatedAndShiftedEstimateAlignsToZero) {
  const Trajectory truth = test::lawnmower(3, 200.0, 60.0);
  const Pose T(sss::core::quaternionFromEuler(0.0, 0.0, 0.05), Eigen::Vector3d(10.0, -5.0, 1.0));
  Trajectory estimate = truth;
  for (StampedPose& p : estimate) p.T_world_body = T * p.T_world_body;
  const TrajectoryEvaluation result = evaluateTrajectory(truth, estimate, {});
  ASSERT_TRUE(result.ok);
  EXPECT_GT(result.ate.horizontal_m.rmse, 5.0);
  EXPECT_LT(result.ate.aligned_position_m.max, 1e-8);
  EXPECT_NEAR(result.ate.alignment_heading_deg, -0.05 * 180.0 / M_PI, 1e-7);  // undoes the rotation
  EXPECT_NEAR(result.ate.rotation_deg.mean, 0.05 * 180.0 / M_PI, 1e-7);
}

// Poses at the given north/east positions, one per second, heading north, 30 m deep.
Trajectory atPositions(const std::vector<Eigen::Vector2d>& north_east_m) {
  Trajectory poses;
  for (size_t i = 0; i < north_east_m.size(); ++i) {
    poses.push_back({test::kStartUtimeUs + static_cast<int64_t>(i) * 1000000,
                     Pose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(north_east_m[i].x(), north_east_m[i].y(), 30.0))});
  }
  return poses;
}

TEST(GaugeFreeAte, RotationAndScaleAboutTheStartAreRemovedExactly) {
  // The truth is the estimate turned 2 deg clockwise and scaled by 0.995 about the estimate's first
  // position (not the origin): what a heading bias and a DVL scale factor do to dead reckoning.
  Trajectory estimate = test::lawnmower(3, 200.0, 60.0);
  for (StampedPose& p : estimate) p.T_world_body.translation += Eigen::Vector3d(120.0, -80.0, 0.0);
  const double rotation_deg = 2.0, scale = 0.995;
  const Eigen::Vector3d start = estimate.front().T_world_body.translation;
  const Eigen::Quaterniond turn = sss::core::quaternionFromEuler(0.0, 0.0, rotation_deg * M_PI / 180.0);
  Trajectory truth = estimate;
  for (StampedPose& p : truth) {
    Eigen::Vector3d d = p.T_world_body.translation - start;
    const double depth_m = p.T_world_body.translation.z();
    d = scale * (turn * d);
    p.T_world_body.translation = start + d;
    p.T_world_body.translation.z() = depth_m;
  }
  const TrajectoryEvaluation result = evaluateTrajectory(truth, estimate, segmentSurveyLines(truth));
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_GT(result.ate.horizontal_m.rmse, 3.0);  // 2 deg over ~250 m from the start
  EXPECT_LT(result.ate.gauge_free_horizontal_m.max, 1e-9);
  EXPECT_EQ(result.ate.gauge_free_horizontal_m.count, estimate.size());
  EXPECT_NEAR(result.ate.gauge_free_scale, scale, 1e-12);
  EXPECT_NEAR(result.ate.gauge_free_rotation_deg, rotation_deg, 1e-9);  // clockwise positive, as a heading
  // All of the raw error is the gauge's.
  EXPECT_NEAR(result.ate.gauge_horizontal_m.rmse, result.ate.horizontal_m.rmse, 1e-9);
  for (const ErrorSample& s : result.series) EXPECT_LT(s.gauge_free_horizontal_m, 1e-9);

  // A heading that reads high turns the estimate clockwise: the fit turns it back (negative).
  const TrajectoryEvaluation swapped = evaluateTrajectory(estimate, truth, {});
  ASSERT_TRUE(swapped.ok);
  EXPECT_NEAR(swapped.ate.gauge_free_rotation_deg, -rotation_deg, 1e-9);
  EXPECT_NEAR(swapped.ate.gauge_free_scale, 1.0 / scale, 1e-12);
  EXPECT_LT(swapped.ate.gauge_free_horizontal_m.max, 1e-9);
}

TEST(GaugeFreeAte, MatchesAHandComputedThreePointCase) {
  // a = est - est_0 = {0, 2, 2i}; b = truth - est_0 = {1, 3 + i, 2i} (north + i east):
  // z = (2 (3 + i) + (-2i)(2i)) / 8 = 1.25 + 0.25i; residuals b - z a = {1, 0.5 + 0.5i, 0.5 - 0.5i}.
  const Trajectory estimate = atPositions({{0.0, 0.0}, {2.0, 0.0}, {0.0, 2.0}});
  const Trajectory truth = atPositions({{1.0, 0.0}, {3.0, 1.0}, {0.0, 2.0}});
  const TrajectoryEvaluation result = evaluateTrajectory(truth, estimate, {});
  ASSERT_TRUE(result.ok) << result.error;
  const AteResult& ate = result.ate;
  EXPECT_NEAR(ate.gauge_free_scale, std::sqrt(1.25 * 1.25 + 0.25 * 0.25), 1e-12);
  EXPECT_NEAR(ate.gauge_free_rotation_deg, std::atan2(0.25, 1.25) * 180.0 / M_PI, 1e-12);  // 11.31 deg
  EXPECT_NEAR(ate.gauge_free_horizontal_m.rmse, std::sqrt(2.0 / 3.0), 1e-12);
  EXPECT_NEAR(ate.gauge_free_horizontal_m.mean, (1.0 + 2.0 * std::sqrt(0.5)) / 3.0, 1e-12);
  EXPECT_NEAR(ate.gauge_free_horizontal_m.max, 1.0, 1e-12);
  ASSERT_EQ(result.series.size(), 3u);
  EXPECT_NEAR(result.series[1].gauge_free_horizontal_m, std::sqrt(0.5), 1e-12);
  // |z - 1| |a| = {0, sqrt(0.5), sqrt(0.5)}; raw^2 = gauge^2 + gauge-free^2 (1 = 1/3 + 2/3).
  EXPECT_NEAR(ate.gauge_horizontal_m.rmse, std::sqrt(1.0 / 3.0), 1e-12);
  EXPECT_NEAR(ate.horizontal_m.rmse, 1.0, 1e-12);

  // Degenerate: an estimate that never leaves its start has no rotation or scale to fit.
  const TrajectoryEvaluation still = evaluateTrajectory(truth, atPositions({{0.0, 0.0}, {0.0, 0.0}, {0.0, 0.0}}), {});
  ASSERT_TRUE(still.ok);
  EXPECT_DOUBLE_EQ(still.ate.gauge_free_scale, 1.0);
  EXPECT_DOUBLE_EQ(still.ate.gauge_free_rotation_deg, 0.0);
  EXPECT_NEAR(still.ate.gauge_free_horizontal_m.rmse, still.ate.horizontal_m.rmse, 1e-12);
  EXPECT_NEAR(still.ate.gauge_free_horizontal_m.max, std::sqrt(10.0), 1e-12);
}

TEST(GaugeFreeAte, KeepsATranslationOffset) {
  // North 100 m, back through the start to 100 m south and back: positions symmetric about the
  // start, so an offset has no rotation or scale part and stays whole in every sample.
  std::vector<Eigen::Vector2d> path;
  for (int k = 0; k <= 200; ++k) path.emplace_back(0.5 * k, 0.0);
  for (int k = 199; k >= -200; --k) path.emplace_back(0.5 * k, 0.0);
  for (int k = -199; k <= 0; ++k) path.emplace_back(0.5 * k, 0.0);
  const Trajectory truth = atPositions(path);
  Trajectory estimate = truth;
  const Eigen::Vector3d offset(3.0, -4.0, 0.0);
  for (StampedPose& p : estimate) p.T_world_body.translation += offset;
  const TrajectoryEvaluation result = evaluateTrajectory(truth, estimate, {});
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_NEAR(result.ate.gauge_free_scale, 1.0, 1e-12);
  EXPECT_NEAR(result.ate.gauge_free_rotation_deg, 0.0, 1e-9);
  EXPECT_NEAR(result.ate.gauge_free_horizontal_m.rmse, 5.0, 1e-9);
  EXPECT_NEAR(result.ate.gauge_free_horizontal_m.mean, 5.0, 1e-9);
  EXPECT_LT(result.ate.aligned_horizontal_m.max, 1e-9);  // which the SE(3) alignment does remove

  // On any path the start keeps the whole offset, and most of it stays elsewhere.
  const Trajectory lawnmower = test::lawnmower(3, 200.0, 60.0);
  Trajectory shifted = lawnmower;
  for (StampedPose& p : shifted) p.T_world_body.translation += offset;
  const TrajectoryEvaluation on_lawnmower = evaluateTrajectory(lawnmower, shifted, {});
  ASSERT_TRUE(on_lawnmower.ok);
  EXPECT_NEAR(on_lawnmower.series.front().gauge_free_horizontal_m, 5.0, 1e-9);
  EXPECT_GT(on_lawnmower.ate.gauge_free_horizontal_m.rmse, 2.5);
}

TEST(Rpe, ScaleDriftGivesItsPercentage) {
  // A 1 % odometry scale error on a straight line: every window of d metres ends d/100 m long.
  const Trajectory truth = test::straightLine(300.0, 2.0, 4.0);
  Trajectory estimate = truth;
  for (StampedPose& p : estimate) p.T_world_body.translation.x() *= 1.01;
  TrajectoryEvaluationOptions options;
  options.rpe.windows_m = {10.0, 50.0, 100.0, 1000.0};
  const TrajectoryEvaluation result = evaluateTrajectory(truth, estimate, {}, options);
  ASSERT_TRUE(result.ok);
  ASSERT_EQ(result.rpe.size(), 4u);
  for (size_t k = 0; k < 3; ++k) {
    const RpeResult& rpe = result.rpe[k];
    EXPECT_GT(rpe.translation_percent.count, 0u);
    EXPECT_NEAR(rpe.translation_percent.mean, 1.0, 1e-9) << rpe.window_m;
    EXPECT_NEAR(rpe.translation_percent.max, 1.0, 1e-9) << rpe.window_m;
    EXPECT_NEAR(rpe.translation_m.mean, 0.01 * rpe.window_m, 1e-9) << rpe.window_m;
    EXPECT_LT(rpe.rotation_deg.max, 1e-9);
  }
  // Pairs per window: starts whose window still ends on the 300 m line (0.5 m steps).
  EXPECT_EQ(result.rpe[1].translation_percent.count, static_cast<size_t>((300.0 - 50.0) / 0.5 + 1));
  // A window longer than the trajectory has no pairs: NaN statistics, not a crash.
  EXPECT_EQ(result.rpe[3].translation_percent.count, 0u);
  EXPECT_TRUE(std::isnan(result.rpe[3].translation_percent.mean));
  // The ATE grows linearly: the end is 3 m off.
  EXPECT_NEAR(result.ate.position_m.max, 3.0, 1e-9);
}

TEST(Rpe, RotatedPathGivesTheChordOfItsRotation) {
  // Estimate rotated by 1 deg about the start: over d metres the lateral error is d*sin(1 deg).
  const Trajectory truth = test::straightLine(200.0);
  const Pose R(sss::core::quaternionFromEuler(0.0, 0.0, M_PI / 180.0), Eigen::Vector3d::Zero());
  Trajectory estimate = truth;
  for (StampedPose& p : estimate) {
    p.T_world_body.translation = R * p.T_world_body.translation;
  }
  const TrajectoryEvaluation result = evaluateTrajectory(truth, estimate, {});
  ASSERT_TRUE(result.ok);
  // Chord 2 sin(0.5 deg) of the window, relative: 1.745 %.
  EXPECT_NEAR(result.rpe[1].translation_percent.mean, 200.0 * std::sin(M_PI / 360.0), 1e-9);
}

TEST(Association, InterpolatesTruthBetweenSamplesAndReportsUnmatched) {
  const Trajectory truth = test::straightLine(100.0, 2.0, 1.0);  // 1 Hz: 0, 2, 4 ... m
  Trajectory estimate;
  for (double t : {-5.0, 0.0, 0.25, 10.5, 50.0, 50.01, 200.0}) {
    estimate.push_back({test::kStartUtimeUs + static_cast<int64_t>(std::llround(t * 1e6)),
                        Pose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(2.0 * t, 0.0, 30.0))});
  }
  const Association association = associate(truth, estimate);
  EXPECT_EQ(association.exact, 2u);         // 0 s and 50 s
  EXPECT_EQ(association.interpolated, 2u);  // 0.25 s and 10.5 s
  EXPECT_EQ(association.nearest, 1u);       // 50.01 s is past the last truth sample (50 s), within 0.02 s
  EXPECT_EQ(association.unmatched, 2u);     // -5 s and 200 s
  ASSERT_EQ(association.pairs.size(), 5u);
  EXPECT_NEAR(association.pairs[2].truth.translation.x(), 21.0, 1e-12);  // interpolated at 10.5 s
  EXPECT_NEAR(association.pairs[4].truth.translation.x(), 100.0, 1e-12);

  AssociationOptions nearest_only;
  nearest_only.interpolate_truth = false;
  nearest_only.max_time_difference_s = 0.3;
  const Association nearest = associate(truth, estimate, nearest_only);
  EXPECT_EQ(nearest.interpolated, 0u);
  EXPECT_EQ(nearest.nearest, 2u);  // 0.25 s -> 0 s and 50.01 s -> 50 s; 10.5 s is 0.5 s away
  EXPECT_EQ(nearest.unmatched, 3u);
}

TEST(Association, NoOverlapInTimeIsAnErrorNotACrash) {
  const Trajectory truth = test::straightLine(50.0);
  Trajectory estimate = truth;
  for (StampedPose& p : estimate) p.utime_us += 3600LL * 1000000;
  const TrajectoryEvaluation result = evaluateTrajectory(truth, estimate, {});
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.error.find("same clock"), std::string::npos) << result.error;
  EXPECT_FALSE(evaluateTrajectory(truth, {}, {}).ok);
}

// The simulator's own planner and vehicle (with its roll/pitch/yaw wobble and terrain following)
// label every sample with its line; the segmentation must find those lines and no others.
void expectSimulatedLinesFound(const std::string& pattern, int lines) {
  sss::sim::SeabedOptions bed;
  bed.enable_texture = false;
  bed.north_min_m = -400.0;
  bed.east_min_m = -400.0;
  bed.size_north_m = 1300.0;
  bed.size_east_m = 1300.0;
  bed.resolution_m = 2.0;
  const sss::sim::Seabed seabed(bed);
  sss::sim::TrajectoryOptions options;
  options.pattern = pattern;
  options.lines = lines;
  options.line_length_m = 300.0;
  const sss::sim::Trajectory path(options, &seabed);
  Trajectory truth;
  std::vector<int> labels;
  for (double t = 0.0; t <= path.durationS(); t += 0.25) {
    const sss::sim::TrajectorySample sample = path.sample(t);
    truth.push_back({test::kStartUtimeUs + static_cast<int64_t>(std::llround(t * 1e6)), sample.T_world_body});
    labels.push_back(sample.line_index);
  }
  const std::vector<SurveyLine> found = segmentSurveyLines(truth);
  ASSERT_EQ(found.size(), static_cast<size_t>(lines)) << pattern;
  for (const SurveyLine& line : found) {
    // Every sample of a found line is on that planned line (turns excluded) ...
    for (size_t i = line.first_pose; i <= line.last_pose; ++i) ASSERT_EQ(labels[i], line.index) << pattern << " " << i;
    // ... and the line covers nearly all of it: the 20 m course window costs at most 10 m per end.
    EXPECT_GT(line.length_m, 300.0 - 20.0) << pattern;
    EXPECT_NEAR(line.heading_deg, line.index % 2 == 0 ? 0.0 : 180.0, 0.5) << pattern;
  }
}

TEST(SurveyLines, FindsEveryLineOfASimulatedLawnmower) { expectSimulatedLinesFound("lawnmower", 5); }

TEST(SurveyLines, FindsEveryLineOfASimulatedLoopSurvey) { expectSimulatedLinesFound("loop", 6); }

TEST(SurveyLines, SplitsASlowCurveAndDropsShortStretches) {
  // 800 m of a 1000 m radius arc (0.057 deg/m, steady) turns 46 deg: cut into pieces of 15 deg
  // plus the 20 m it takes to establish each piece's course.
  Trajectory arc;
  for (int i = 0; i <= 1600; ++i) {
    const double phi = 0.5 * i / 1000.0;
    arc.push_back({test::kStartUtimeUs + i * 250000LL,
                   Pose(sss::core::quaternionFromEuler(0, 0, phi),
                        Eigen::Vector3d(1000.0 * std::sin(phi), 1000.0 - 1000.0 * std::cos(phi), 30.0))});
  }
  const std::vector<SurveyLine> pieces = segmentSurveyLines(arc);
  ASSERT_GE(pieces.size(), 3u);
  for (const SurveyLine& piece : pieces) EXPECT_LE(piece.length_m, 15.0 / 180.0 * M_PI * 1000.0 + 21.0);
  LineSegmentationOptions long_lines;
  long_lines.min_line_length_m = 1000.0;
  EXPECT_TRUE(segmentSurveyLines(test::lawnmower(3, 200.0, 60.0), long_lines).empty());
  EXPECT_TRUE(segmentSurveyLines(Trajectory(1)).empty());
}

TEST(PoseAtTime, InterpolatesWithinGapsOnly) {
  Trajectory trajectory = test::straightLine(20.0, 2.0, 1.0);
  trajectory.back().utime_us += 5000000;  // a 6 s gap before the last sample
  const std::optional<Pose> mid = poseAtTime(trajectory, test::kStartUtimeUs + 1500000, 1.0);
  ASSERT_TRUE(mid);
  EXPECT_NEAR(mid->translation.x(), 3.0, 1e-12);
  EXPECT_FALSE(poseAtTime(trajectory, trajectory.back().utime_us - 1000000, 1.0));
  EXPECT_TRUE(poseAtTime(trajectory, trajectory.back().utime_us, 1.0));
  EXPECT_FALSE(poseAtTime(trajectory, test::kStartUtimeUs - 1, 1.0));
}

}  // namespace
}  // namespace sss::eval
