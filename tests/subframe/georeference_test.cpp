// Geo-referencing on a flat seabed: pixels land within one ground-range bin of the simulator's
// ray-cast seabed point, and a bright object in the canonical image lands where it lies.
#include "pipeline/core/georeference.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "pipeline/subframe/subframe_buffer.hpp"
#include "tests/subframe/subframe_test_mission.hpp"
#include "tools/sim/ground_truth_geometry.hpp"

namespace sss::subframe {
namespace {

constexpr double kBedDepthM = 40.0;

sss::sim::SeabedOptions flatBed() {
  sss::sim::SeabedOptions options;
  options.enable_texture = false;
  options.mean_depth_m = kBedDepthM;
  options.north_min_m = -100.0;
  options.east_min_m = -100.0;
  options.size_north_m = 200.0;
  options.size_east_m = 200.0;
  options.resolution_m = 0.2;
  return options;
}

TEST(Georeference, PixelLandsWithinOneBinOfTheRayCastSeabedPoint) {
  const sss::sim::Seabed seabed(flatBed());
  const sss::sim::SonarOptions sonar;
  const sss::sim::GroundTruthGeometry truth(&seabed, sonar);
  SubframeGeometry geometry;
  geometry.bins_per_side = 1250;
  geometry.bin_size_m = 0.06;
  double max_error_m = 0.0;
  int checked = 0;
  for (double roll : {0.0, 0.05, -0.08}) {
    for (double pitch : {0.0, 0.03, -0.05}) {
      for (double heading : {0.0, 0.7, -2.5}) {
        const sss::core::Pose T_world_body(sss::core::quaternionFromEuler(roll, pitch, heading),
                                           Eigen::Vector3d(3.0, -2.0, kBedDepthM - 18.0));
        const double h = kBedDepthM - T_world_body.translation.z();
        for (int column : {0, 300, 800, 1200, 1300, 1700, 2200, 2499}) {
          const double g = std::abs(geometry.signedGroundRangeM(column));
          if (g < 5.0) continue;
          const auto pixel = georeferencePixel(geometry, T_world_body, h, column);
          ASSERT_TRUE(pixel.has_value());
          const double slant_m = std::hypot(g, h);
          const auto side = column < geometry.bins_per_side ? sss::sim::Side::kPort : sss::sim::Side::kStarboard;
          const auto hit = truth.sampleToSeabed(T_world_body, side, slant_m / sonar.sampleSpacingM());
          if (!hit) continue;  // beyond the 75 m range
          const double error = (pixel->head<2>() - hit->position_ned_m.head<2>()).norm();
          max_error_m = std::max(max_error_m, error);
          EXPECT_LT(error, geometry.bin_size_m) << "roll " << roll << " pitch " << pitch << " column " << column;
          EXPECT_NEAR(pixel->z(), kBedDepthM, 1e-6);
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 150);
  std::printf("geo-reference vs ray cast: %d pixels, max horizontal error %.4f m (bin 0.06 m)\n", checked, max_error_m);
}

TEST(Georeference, ABrightObjectInTheCanonicalImageLandsWhereItLies) {
  sss::sim::SimOptions options = test::shortLawnmower(1, 100.0);
  options.seabed.enable_texture = false;
  options.seabed.mean_depth_m = kBedDepthM;
  options.trajectory.roll_amplitude_rad = 0.0;
  options.trajectory.pitch_amplitude_rad = 0.0;
  options.trajectory.altitude_wobble_m = 0.0;
  const Eigen::Vector2d object(50.0, 40.0);  // north, east: 40 m to starboard of the northbound line
  options.seabed.objects.push_back({object.x(), object.y(), 0.25, 0.25, 1.5});
  const auto mission = test::makeTestMission(options);

  SubframeBuffer buffer({});
  std::vector<Subframe> subframes;
  test::feedInOrder(buffer, mission->true_nav, mission->pings, subframes);
  ASSERT_FALSE(subframes.empty());
  // The brightest starboard pixel of the mission (the object's face towards the sonar).
  const Subframe* best = nullptr;
  int best_row = 0, best_col = 0;
  float best_value = 0.0f;
  for (const Subframe& s : subframes) {
    for (int r = 0; r < s.rows(); ++r) {
      for (int c = s.geometry.bins_per_side; c < s.cols(); ++c) {
        const size_t i = static_cast<size_t>(r) * s.cols() + c;
        if (s.mask[i] == kMaskValid && s.image[i] > best_value) {
          best_value = s.image[i];
          best = &s;
          best_row = r;
          best_col = c;
        }
      }
    }
  }
  ASSERT_NE(best, nullptr);
  std::vector<sss::core::Pose> true_poses;
  for (const SubframePing& p : best->pings) true_poses.push_back(mission->mission->truthAtPing(p.ping_number).T_world_body);
  const auto where = georeferencePixel(*best, true_poses, best_row, best_col);
  ASSERT_TRUE(where.has_value());
  const double across_m = where->y() - object.y();
  const double along_m = where->x() - object.x();
  std::printf("bright object: peak %.1f x mean, geo-referenced at (%.2f, %.2f), error across %.3f m, along %.3f m\n",
              best_value, where->x(), where->y(), across_m, along_m);
  // Across track: the face towards the sonar is up to one radius (0.25 m) nearer than the centre,
  // plus one bin; along track: one ping spacing (0.5 m) plus the radius.
  EXPECT_LT(std::abs(across_m), 0.25 + 0.06);
  EXPECT_LT(std::abs(along_m), 0.5 + 0.25);
}

}  // namespace
}  // namespace sss::subframe
