// Landmark consistency: a seabed point seen from two survey lines geo-references to one place with
// the true poses; a pose error on one line shows up as that error; pitch keeps the ground range.
#include "tools/eval/landmark_consistency.hpp"

#include "tests/eval/eval_test_paths.hpp"

#include <gtest/gtest.h>

namespace sss::eval {
namespace {

using sss::core::Pose;

constexpr double kSeabedDepthM = 50.0;
constexpr double kVehicleDepthM = 32.0;  // 18 m altitude

// Two 200 m lines 60 m apart at 1 m/s, 1 Hz: northbound at east 0 (t = 0..200 s), then
// southbound at east 60 (t = 300..500 s).
Trajectory twoLines(double second_line_east_error_m = 0.0) {
  Trajectory poses;
  for (int i = 0; i <= 200; ++i) {
    poses.push_back({test::kStartUtimeUs + i * 1000000LL,
                     Pose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(i, 0.0, kVehicleDepthM))});
  }
  for (int i = 0; i <= 200; ++i) {
    poses.push_back({test::kStartUtimeUs + (300 + i) * 1000000LL,
                     Pose(sss::core::quaternionFromEuler(0.0, 0.0, M_PI),
                          Eigen::Vector3d(200.0 - i, 60.0 + second_line_east_error_m, kVehicleDepthM))});
  }
  return poses;
}

// Seabed points between the lines, seen to starboard from both (the southbound line's starboard
// is west).
std::vector<LandmarkCorrespondence> correspondences() {
  std::vector<LandmarkCorrespondence> pairs;
  for (int k = 0; k < 10; ++k) {
    const double north = 20.0 + 15.0 * k;
    const double east = 15.0 + 3.0 * k;
    LandmarkCorrespondence c;
    c.a = {test::kStartUtimeUs + static_cast<int64_t>(north * 1e6), east};
    c.b = {test::kStartUtimeUs + static_cast<int64_t>((300.0 + 200.0 - north) * 1e6), 60.0 - east};
    pairs.push_back(c);
  }
  return pairs;
}

LandmarkConsistencyOptions flatSeabed() {
  LandmarkConsistencyOptions options;
  options.seabed_depth_m = kSeabedDepthM;
  return options;
}

TEST(LandmarkConsistency, TruePosesGiveZeroError) {
  const LandmarkConsistencyResult result = landmarkConsistency(twoLines(), correspondences(), flatSeabed());
  EXPECT_EQ(result.horizontal_m.count, 10u);
  EXPECT_EQ(result.skipped, 0u);
  EXPECT_LT(result.horizontal_m.max, 1e-9);
  const std::optional<Eigen::Vector3d> point =
      georeferenceObservation(twoLines(), correspondences()[0].a, flatSeabed());
  ASSERT_TRUE(point);
  EXPECT_LT((*point - Eigen::Vector3d(20.0, 15.0, kSeabedDepthM)).norm(), 1e-9);
}

TEST(LandmarkConsistency, ALineOffsetShowsAsThatDistance) {
  const LandmarkConsistencyResult result = landmarkConsistency(twoLines(1.5), correspondences(), flatSeabed());
  EXPECT_EQ(result.horizontal_m.count, 10u);
  EXPECT_NEAR(result.horizontal_m.mean, 1.5, 1e-9);
  EXPECT_NEAR(result.horizontal_m.median, 1.5, 1e-9);
  EXPECT_NEAR(result.horizontal_m.rmse, 1.5, 1e-9);
}

TEST(LandmarkConsistency, PitchKeepsTheGroundRangeFromNadir) {
  // The fan plane tilts along track; the point still lies |g| from the point below the sonar.
  Trajectory pitched;
  for (int i = 0; i <= 2; ++i) {
    pitched.push_back({test::kStartUtimeUs + i * 1000000LL,
                       Pose(sss::core::quaternionFromEuler(0.02, 0.1, 0.3), Eigen::Vector3d(i, 0.0, kVehicleDepthM))});
  }
  const std::optional<Eigen::Vector3d> point =
      georeferenceObservation(pitched, {test::kStartUtimeUs + 1000000, -40.0}, flatSeabed());
  ASSERT_TRUE(point);
  EXPECT_NEAR(point->z(), kSeabedDepthM, 1e-9);
  EXPECT_NEAR((point->head<2>() - Eigen::Vector2d(1.0, 0.0)).norm(), 40.0, 1e-9);
  // Port: the point is on the port side of the heading.
  const Eigen::Vector2d starboard(-std::sin(0.3), std::cos(0.3));
  EXPECT_LT((point->head<2>() - Eigen::Vector2d(1.0, 0.0)).dot(starboard), 0.0);
  // A ground range shorter than the pitch offset of the fan line (18 m * tan(0.1) ~ 1.8 m) has no point.
  EXPECT_FALSE(georeferenceObservation(pitched, {test::kStartUtimeUs + 1000000, 1.0}, flatSeabed()));
}

TEST(LandmarkConsistency, ObservationsOutsideTheTrajectoryOrBelowTheSeabedAreSkipped) {
  std::vector<LandmarkCorrespondence> pairs = correspondences();
  pairs[0].a.utime_us = test::kStartUtimeUs - 5000000;  // before the trajectory
  pairs[1].b.utime_us = test::kStartUtimeUs + 250 * 1000000LL;  // in the gap between the lines
  const LandmarkConsistencyResult result = landmarkConsistency(twoLines(), pairs, flatSeabed());
  EXPECT_EQ(result.skipped, 2u);
  EXPECT_EQ(result.horizontal_m.count, 8u);
  EXPECT_TRUE(std::isnan(result.distances_m[0]));
  LandmarkConsistencyOptions shallow = flatSeabed();
  shallow.seabed_depth_m = 10.0;  // above the vehicle
  EXPECT_EQ(landmarkConsistency(twoLines(), correspondences(), shallow).skipped, 10u);
}

}  // namespace
}  // namespace sss::eval
