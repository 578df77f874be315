// Ground-truth geometry: pixel -> seabed and seabed -> ping/sample agree with each other and with
// the rendered image (a bright object appears where the geometry says).
#include "tools/sim/ground_truth_geometry.hpp"

#include "tests/sim/sim_test_scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace sss::sim {
namespace {

using namespace sss::sim::test;

TEST(GroundTruthGeometry, SampleOnFlatBedLiesAtSlantRangeInTheFanPlane) {
  const Seabed bed(boulderScene());
  const SonarOptions options;
  const GroundTruthGeometry geometry(&bed, options);
  const double sample = 3000.0;  // 45 m slant range
  const std::optional<SeabedHit> hit = geometry.sampleToSeabed(levelPoseAt(-20.0), Side::kPort, sample);
  ASSERT_TRUE(hit.has_value());
  const double range = sample * options.sampleSpacingM();
  EXPECT_NEAR(hit->position_ned_m.x(), -20.0, 1e-9);
  EXPECT_NEAR(hit->position_ned_m.y(), -std::sqrt(range * range - kAltitudeM * kAltitudeM), 1e-3);
  EXPECT_NEAR(hit->position_ned_m.z(), kBedDepthM, 1e-6);
  // Water column has no seabed point.
  EXPECT_FALSE(geometry.sampleToSeabed(levelPoseAt(-20.0), Side::kPort, 100.0).has_value());
}

TEST(GroundTruthGeometry, ObservationOfASeabedPointRoundTrips) {
  const Seabed bed(boulderScene());
  const SonarOptions options;
  const GroundTruthGeometry geometry(&bed, options);
  const std::vector<sss::core::Pose> poses = passOverObject();
  const Eigen::Vector3d point(-3.3, -30.0, kBedDepthM);
  const std::vector<PingObservation> seen = geometry.observationsOf(point, poses);
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].side, Side::kPort);
  EXPECT_NEAR(seen[0].ping_index, (10.0 - 3.3) / 0.5, 1e-9);
  EXPECT_TRUE(seen[0].visible);
  const sss::core::Pose at = levelPoseAt(-3.3);
  const std::optional<SeabedHit> back = geometry.sampleToSeabed(at, seen[0].side, seen[0].sample);
  ASSERT_TRUE(back.has_value());
  EXPECT_LT((back->position_ned_m - point).norm(), 1e-3);
}

TEST(GroundTruthGeometry, BrightObjectAppearsWhereTheGeometryPredicts) {
  const Seabed bed(boulderScene());
  const SonarOptions options;
  const SonarModel sonar(options, &bed);
  const GroundTruthGeometry geometry(&bed, options);
  const std::vector<sss::core::Pose> poses = passOverObject();
  // The brightest part of the boulder is the face turned to the sonar, at ground range
  // 40 - r cos(a) where the face is perpendicular to the ray. Take the ray cast's own point on
  // the front face half-way up as the landmark.
  const double face_east = kObjectEastM - kObjectRadiusM * std::sqrt(1.0 - 0.5 * 0.5);
  const Eigen::Vector3d landmark(0.0, face_east, bed.depthM(0.0, face_east));
  ASSERT_LT(landmark.z(), kBedDepthM - 0.5);  // on the object, not the bed
  const std::vector<PingObservation> seen = geometry.observationsOf(landmark, poses);
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].side, Side::kStarboard);
  EXPECT_TRUE(seen[0].visible);
  EXPECT_EQ(seen[0].nearest_ping, 20u);

  const PingSamples ping = sonar.render(poses[seen[0].nearest_ping], 20);
  const auto predicted = static_cast<int>(std::lround(seen[0].sample));
  // The rendered image is bright at the predicted sample: the local mean over +-3 samples is
  // several times the open-bed level at that range on the port side (no object there).
  const double at_object = mean(ping.starboard, predicted - 3, predicted + 4);
  const double open_bed = mean(ping.port, predicted - 60, predicted + 60);
  EXPECT_GT(at_object, 2.0 * open_bed);
  // And the expected (speckle-free) image peaks within a couple of samples of the prediction
  // over the face: search +-1 m of range.
  const std::vector<float> expected = sonar.expectedIntensity(poses[seen[0].nearest_ping], Side::kStarboard);
  const int window = static_cast<int>(1.0 / options.sampleSpacingM());
  const auto peak = std::max_element(expected.begin() + predicted - window, expected.begin() + predicted + window);
  const int peak_sample = static_cast<int>(peak - expected.begin());
  // The landmark sits where the face is nearly normal to the ray: the brightest facet (1.5 cm/sample).
  EXPECT_LE(std::abs(peak_sample - predicted), 2) << "peak " << peak_sample << " predicted " << predicted;
  // Without the object (a ping 20 m south) the same sample is the plain bed, several times darker.
  const std::vector<float> open = sonar.expectedIntensity(levelPoseAt(-20.0), Side::kStarboard);
  EXPECT_GT(*peak, 3.0 * open[peak_sample]);
}

TEST(GroundTruthGeometry, PointInTheShadowIsNotVisible) {
  const Seabed bed(boulderScene());
  const SonarOptions options;
  const GroundTruthGeometry geometry(&bed, options);
  // 42.5 m east is behind the boulder (shadow to 43.6 m) as seen from the track at east 0.
  const Eigen::Vector3d hidden(0.0, 42.5, kBedDepthM);
  const std::vector<PingObservation> seen = geometry.observationsOf(hidden, passOverObject());
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_FALSE(seen[0].visible);
}

}  // namespace
}  // namespace sss::sim
