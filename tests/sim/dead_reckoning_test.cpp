// Dead reckoning: starts at the truth, drifts 0.1-0.5 % of distance by default, scales with
// drift_scale, and the paper's heading noise grows the error in proportion to its std.
#include "tools/sim/dead_reckoning.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace sss::sim {
namespace {

struct StraightLine {
  Seabed bed;
  Trajectory trajectory;
  StraightLine()
      : bed([] {
          SeabedOptions options;
          options.enable_texture = false;
          options.north_min_m = -50.0;
          options.east_min_m = -50.0;
          options.size_north_m = 1100.0;
          options.size_east_m = 100.0;
          options.resolution_m = 1.0;
          return options;
        }()),
        trajectory(
            [] {
              TrajectoryOptions options;
              options.lines = 1;
              options.line_length_m = 1000.0;
              return options;
            }(),
            &bed) {}
};

double finalError(const DeadReckoning& dr, const Trajectory& trajectory, double time_s) {
  return (dr.poseAt(time_s).translation - trajectory.sample(time_s).T_world_body.translation).head<2>().norm();
}

TEST(DeadReckoning, StartsAtTheTruePose) {
  const StraightLine line;
  DeadReckoningOptions options;
  const DeadReckoning dr(options, line.trajectory, 10.0);
  const sss::core::Pose truth = line.trajectory.sample(0.0).T_world_body;
  EXPECT_LT((dr.poseAt(0.0).translation - truth.translation).norm(), 1e-12);
  EXPECT_LT(dr.poseAt(0.0).rotation.angularDistance(truth.rotation), 1e-12);
}

TEST(DeadReckoning, DefaultDriftIsTenthToHalfPercentOfDistanceOverSeeds) {
  const StraightLine line;
  const double duration = line.trajectory.durationS();
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    DeadReckoningOptions options;
    options.seed = seed;
    const DeadReckoning dr(options, line.trajectory, duration);
    const double ratio = finalError(dr, line.trajectory, duration) / dr.distanceTravelledM();
    // Straight line: error ~ hypot(scale factor, heading error at the line's heading).
    const double heading_error = dr.headingErrorRad(
        sss::core::eulerFromQuaternion(line.trajectory.sample(0.5 * duration).T_world_body.rotation).heading_rad);
    EXPECT_GT(ratio, 0.001) << "seed " << seed;
    EXPECT_LT(ratio, 0.005) << "seed " << seed;
    EXPECT_NEAR(ratio, std::hypot(dr.velocityScaleFactor(), heading_error), 0.0006) << "seed " << seed;
  }
}

TEST(DeadReckoning, LawnmowerDriftDoesNotCancelOnReversedLines) {
  // The default 5-line survey: constant scale factor and bias errors reverse with the lines, the
  // heading-dependent error does not (unless its random phase puts its zero on the line
  // heading). Over seeds, the worst error stays below 0.5 % of the distance flown, never
  // vanishes, and averages at least 0.1 %.
  SeabedOptions bed_options;
  bed_options.enable_texture = false;
  bed_options.north_min_m = -100.0;
  bed_options.east_min_m = -100.0;
  bed_options.size_north_m = 600.0;
  bed_options.size_east_m = 500.0;
  bed_options.resolution_m = 1.0;
  const Seabed bed(bed_options);
  const Trajectory trajectory(TrajectoryOptions{}, &bed);
  const double duration = trajectory.durationS();
  double sum_ratio = 0.0;
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    DeadReckoningOptions options;
    options.seed = seed;
    const DeadReckoning dr(options, trajectory, duration);
    double worst = 0.0;
    for (double t = 0.0; t <= duration; t += 5.0) worst = std::max(worst, finalError(dr, trajectory, t));
    const double ratio = worst / dr.distanceTravelledM();
    EXPECT_GT(ratio, 0.0002) << "seed " << seed;
    EXPECT_LT(ratio, 0.005) << "seed " << seed;
    sum_ratio += ratio;
  }
  EXPECT_GT(sum_ratio / 8.0, 0.001) << "mean worst error / distance";
}

TEST(DeadReckoning, DriftScaleMultipliesTheError) {
  const StraightLine line;
  const double duration = line.trajectory.durationS();
  DeadReckoningOptions options;
  options.seed = 4;
  const DeadReckoning base(options, line.trajectory, duration);
  options.drift_scale = 3.0;
  const DeadReckoning scaled(options, line.trajectory, duration);
  const double ratio = finalError(scaled, line.trajectory, duration) / finalError(base, line.trajectory, duration);
  // Linear in the error constants; the random walk and white noise add a few percent.
  EXPECT_NEAR(ratio, 3.0, 0.3);
}

// The INS reports its class, not the errors it drew: its position sigma grows by
// reported_drift_fraction x drift_scale per metre, and over many seeds that is the rms error per
// axis per metre the drawn scale factors and heading errors give (so a graph that takes the INS's
// word is neither too stiff nor too loose on average).
TEST(DeadReckoning, ReportedAccuracyIsTheRmsOfTheDrawnErrors) {
  const StraightLine line;
  const double duration = line.trajectory.durationS();
  for (const double drift_scale : {1.0, 3.0}) {
    double sum_squared = 0.0;
    const int seeds = 40;
    double reported_growth = 0.0;
    for (int seed = 1; seed <= seeds; ++seed) {
      DeadReckoningOptions options;
      options.seed = static_cast<uint64_t>(seed);
      options.drift_scale = drift_scale;
      const DeadReckoning dr(options, line.trajectory, duration);
      const double ratio = finalError(dr, line.trajectory, duration) / dr.distanceTravelledM();
      sum_squared += 0.5 * ratio * ratio;  // per axis
      const auto& samples = dr.samples();
      reported_growth = (samples.back().position_std_m - samples.front().position_std_m) / dr.distanceTravelledM();
      EXPECT_DOUBLE_EQ(samples.front().position_std_m, options.reported_start_std_m);
    }
    const double rms_per_axis = std::sqrt(sum_squared / seeds);
    std::printf("drift_scale %.0f: rms error per axis %.5f of the distance, reported %.5f\n", drift_scale, rms_per_axis,
                reported_growth);
    EXPECT_NEAR(reported_growth, drift_scale * DeadReckoningOptions{}.reported_drift_fraction, 1e-6);
    EXPECT_GT(rms_per_axis, 0.7 * reported_growth);
    EXPECT_LT(rms_per_axis, 1.3 * reported_growth);
  }
}

TEST(DeadReckoning, HeadingNoiseErrorGrowsWithItsStd) {
  const StraightLine line;
  const double duration = line.trajectory.durationS();  // 500 s: 2000 increments of 0.25 s
  double sum_sq[2] = {0.0, 0.0};
  const double stds[2] = {0.02, 0.04};
  const int seeds = 12;
  for (int k = 0; k < 2; ++k) {
    for (int seed = 1; seed <= seeds; ++seed) {
      DeadReckoningOptions options;
      options.seed = static_cast<uint64_t>(seed);
      options.drift_scale = 0.0;  // isolate the study noise
      options.heading_noise_rad = stds[k];
      const DeadReckoning dr(options, line.trajectory, duration);
      // Cross-track (east) error: linear in the noise; along-track loses only ~S^2/2 per step.
      const double e = dr.poseAt(duration).translation.y() - line.trajectory.sample(duration).T_world_body.translation.y();
      sum_sq[k] += e * e;
    }
  }
  const double rms_low = std::sqrt(sum_sq[0] / seeds);
  const double rms_high = std::sqrt(sum_sq[1] / seeds);
  // White heading noise per 0.5 m increment: cross-track random walk of std 0.5 * S * sqrt(2000).
  const double predicted_low = 0.5 * 0.02 * std::sqrt(2000.0);
  EXPECT_GT(rms_low, 0.5 * predicted_low);
  EXPECT_LT(rms_low, 1.6 * predicted_low);
  // Same noise stream, twice the std: twice the error (small-angle linearity).
  EXPECT_NEAR(rms_high / rms_low, 2.0, 0.05);
}

}  // namespace
}  // namespace sss::sim
