// Landmark consistency: a seabed point seen from two survey lines geo-references to one place with
// the true poses; a pose error on one line shows up as that error; pitch keeps the ground range;
// correspondences generated from the truth give ~0 for the truth and a line's offset for that line.
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

TEST(LandmarkConsistency, SignedGroundRangeInvertsTheGeoreference) {
  const Pose T_world_sonar(sss::core::quaternionFromEuler(0.05, -0.08, 2.0), Eigen::Vector3d(10.0, -4.0, kVehicleDepthM));
  Trajectory pitched = {{test::kStartUtimeUs, T_world_sonar}};
  for (double g : {-60.0, -12.5, 12.5, 60.0}) {
    const std::optional<Eigen::Vector3d> point = georeferenceObservation(pitched, {test::kStartUtimeUs, g}, flatSeabed());
    ASSERT_TRUE(point);
    EXPECT_NEAR(signedGroundRangeM(T_world_sonar, *point), g, 1e-9);
  }
}

// Two 200 m lines 60 m apart (north, then south), 0.5 m between poses, moved 0.25 m north so no
// pose falls on a grid row (the first/last row of a line is then not a tie).
class TrueCorrespondencesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    truth_ = test::lawnmower(2, 200.0, 60.0);
    for (StampedPose& p : truth_) p.T_world_body.translation.x() += 0.25;
    lines_ = segmentSurveyLines(truth_);
    // 7.5-52.5 m: between the lines only the points 10..50 m east of line 0 are in both swaths (no
    // point sits on a swath edge).
    options_.min_ground_range_m = 7.5;
    options_.max_ground_range_m = 52.5;
  }

  // Grid rows (5 m) the fan of both lines passes over: line 0 north of its first pose up to its
  // last, line 1 from its last pose up to south of its first.
  size_t expectedPairs() const {
    const double low = std::max(truth_[lines_[0].first_pose].T_world_body.translation.x(),
                                truth_[lines_[1].last_pose].T_world_body.translation.x());
    const double high = std::min(truth_[lines_[0].last_pose].T_world_body.translation.x(),
                                 truth_[lines_[1].first_pose].T_world_body.translation.x());
    const size_t rows = static_cast<size_t>(std::floor(high / 5.0) - std::ceil(low / 5.0) + 1);
    return rows * 9;  // east 10, 15, ..., 50
  }

  Trajectory truth_;
  std::vector<SurveyLine> lines_;
  TrueCorrespondenceOptions options_;
};

TEST_F(TrueCorrespondencesTest, TheTruthIsConsistentAndEveryPairSpansBothLines) {
  ASSERT_EQ(lines_.size(), 2u);
  const TrueCorrespondences generated = generateTrueCorrespondences(truth_, lines_, options_, flatSeabed());
  EXPECT_GT(expectedPairs(), 300u);  // the lines are found nearly whole
  EXPECT_EQ(generated.pairs.size(), expectedPairs());
  EXPECT_EQ(generated.candidate_pairs, generated.pairs.size());
  EXPECT_EQ(generated.seabed_points, generated.pairs.size());  // two lines: one pair per point
  for (const LandmarkCorrespondence& c : generated.pairs) {
    // Both to starboard (east of the northbound line, west of the southbound one), 60 m apart.
    ASSERT_GE(c.a.ground_range_m, 10.0 - 1e-6);
    ASSERT_LE(c.a.ground_range_m, 50.0 + 1e-6);
    ASSERT_NEAR(c.a.ground_range_m + c.b.ground_range_m, 60.0, 1e-6);
    ASSERT_LE(c.a.utime_us, truth_[lines_[0].last_pose].utime_us);
    ASSERT_GE(c.b.utime_us, truth_[lines_[1].first_pose].utime_us);
  }
  const LandmarkConsistencyResult truth = landmarkConsistency(truth_, generated.pairs, flatSeabed());
  EXPECT_EQ(truth.horizontal_m.count, generated.pairs.size());
  EXPECT_EQ(truth.skipped, 0u);
  // The pair's time is rounded to 1 us: at 2 m/s the fan is then within 1 um of the point.
  EXPECT_LT(truth.horizontal_m.max, 1e-5);
}

TEST_F(TrueCorrespondencesTest, ALateralOffsetOfOneLineIsTheError) {
  const TrueCorrespondences generated = generateTrueCorrespondences(truth_, lines_, options_, flatSeabed());
  Trajectory shifted = truth_;
  for (size_t i = lines_[1].first_pose; i <= lines_[1].last_pose; ++i) shifted[i].T_world_body.translation.y() += 1.5;
  const LandmarkConsistencyResult result = landmarkConsistency(shifted, generated.pairs, flatSeabed());
  EXPECT_EQ(result.horizontal_m.count, generated.pairs.size());
  EXPECT_NEAR(result.horizontal_m.mean, 1.5, 1e-5);
  EXPECT_NEAR(result.horizontal_m.max, 1.5, 1e-5);
  EXPECT_GT(result.horizontal_m.count, 300u);
  // A shift of the whole survey moves both sightings alike: no error.
  Trajectory moved = truth_;
  for (StampedPose& p : moved) p.T_world_body.translation += Eigen::Vector3d(3.0, -2.0, 0.0);
  EXPECT_LT(landmarkConsistency(moved, generated.pairs, flatSeabed()).horizontal_m.max, 1e-5);
}

TEST_F(TrueCorrespondencesTest, MorePairsThanTheCapAreThinnedEvenly) {
  const TrueCorrespondences all = generateTrueCorrespondences(truth_, lines_, options_, flatSeabed());
  options_.max_correspondences = 10;
  const TrueCorrespondences capped = generateTrueCorrespondences(truth_, lines_, options_, flatSeabed());
  ASSERT_EQ(capped.pairs.size(), 10u);
  EXPECT_EQ(capped.candidate_pairs, all.pairs.size());
  for (size_t k = 0; k < 10; ++k) {
    const LandmarkCorrespondence& expected = all.pairs[k * all.pairs.size() / 10];
    EXPECT_EQ(capped.pairs[k].a.utime_us, expected.a.utime_us);
    EXPECT_EQ(capped.pairs[k].b.utime_us, expected.b.utime_us);
  }
}

}  // namespace
}  // namespace sss::eval
