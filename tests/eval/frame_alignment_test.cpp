// Results written in one mission frame, compared in another: exact positions through WGS-84, the
// axes' rotation (meridian convergence), a round trip, and the readers doing it from the headers.
#include "tools/eval/frame_alignment.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "pipeline/core/geodesy.hpp"
#include "tools/eval/heightmap_metrics.hpp"
#include "tests/support/status_assertions.hpp"

namespace sss::eval {
namespace {

constexpr sss::core::MissionOrigin kA{60.0, 10.0};
constexpr sss::core::MissionOrigin kB{60.05, 10.2};  // 5.6 km north, 11.1 km east of A

TEST(FrameAlignment, PositionsGoThroughGeodesyAndHeadingsTurnByTheMeridianConvergence) {
  Trajectory poses(2);
  poses[0].utime_us = 1;
  poses[1].utime_us = 2;
  poses[1].T_world_body.translation = Eigen::Vector3d(120.0, -40.0, 35.0);
  poses[1].T_world_body.rotation = sss::core::quaternionFromEuler(0.01, -0.02, 0.5);
  Trajectory moved = poses;
  reexpressTrajectory(moved, kA, kB);
  const sss::core::LocalTangentPlane a(kA.latitude_deg, kA.longitude_deg), b(kB.latitude_deg, kB.longitude_deg);
  for (size_t i = 0; i < poses.size(); ++i) {
    const Eigen::Vector3d expected = b.toNed(a.toGeodetic(poses[i].T_world_body.translation));
    EXPECT_LT((moved[i].T_world_body.translation - expected).norm(), 1e-6);
  }
  // A's origin lies ~5.6 km south and ~11.1 km west of B's.
  EXPECT_NEAR(moved[0].T_world_body.translation.x(), -5560.0, 20.0);
  EXPECT_NEAR(moved[0].T_world_body.translation.y(), -11150.0, 30.0);
  // North at A points 0.2 deg x sin(60 deg) = 0.173 deg east of north at B, which lies east of A:
  // the meridians converge towards the pole (headings grow clockwise).
  const double heading_a = sss::core::eulerFromQuaternion(poses[1].T_world_body.rotation).heading_rad;
  const double heading_b = sss::core::eulerFromQuaternion(moved[1].T_world_body.rotation).heading_rad;
  EXPECT_NEAR((heading_b - heading_a) * 180.0 / M_PI, 0.2 * std::sin(60.0 * M_PI / 180.0), 0.005);
  // And back.
  reexpressTrajectory(moved, kB, kA);
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_LT((moved[i].T_world_body.translation - poses[i].T_world_body.translation).norm(), 1e-6);
    EXPECT_LT(moved[i].T_world_body.rotation.angularDistance(poses[i].T_world_body.rotation), 1e-7);
  }
}

TEST(FrameAlignment, ReadersReexpressFilesWhoseHeaderNamesAnotherOrigin) {
  const std::string dir = (std::filesystem::temp_directory_path() / "sss_frame_alignment_test").string();
  std::filesystem::create_directories(dir);
  Trajectory poses(1);
  poses[0].utime_us = 1'000'000;
  poses[0].T_world_body.translation = Eigen::Vector3d(10.0, 20.0, 30.0);
  std::string error;
  ASSERT_OK(writeTum(dir + "/a.tum", poses, "in A", kA));
  const TumReadResult same = readTum(dir + "/a.tum");
  ASSERT_TRUE(same.ok && same.origin);
  EXPECT_DOUBLE_EQ(same.origin->latitude_deg, kA.latitude_deg);
  EXPECT_FALSE(same.reexpressed);
  TumReadOptions to_b;
  to_b.target_origin = kB;
  const TumReadResult in_b = readTum(dir + "/a.tum", to_b);
  ASSERT_TRUE(in_b.ok);
  EXPECT_TRUE(in_b.reexpressed);
  EXPECT_NEAR(in_b.poses[0].T_world_body.translation.x(), -5560.0 + 10.0, 20.0);
  // A file that names no origin is taken as it is.
  ASSERT_OK(writeTum(dir + "/plain.tum", poses));
  const TumReadResult plain = readTum(dir + "/plain.tum", to_b);
  EXPECT_FALSE(plain.origin);
  EXPECT_FALSE(plain.reexpressed);

  // A heightmap: the grid shifts, the depth follows the other plane's curvature (~12 m deeper at
  // 12.4 km: d^2 / 2R).
  HeightmapRaster raster;
  raster.rows = 3;
  raster.cols = 4;
  raster.resolution_m = 2.0;
  raster.depth_m.assign(12, 30.0f);
  raster.origin = kA;
  ASSERT_OK(writeHeightmap(dir + "/map.yaml", raster));
  HeightmapRaster read;
  HeightmapReadOptions heightmap_to_b;
  heightmap_to_b.target_origin = kB;
  ASSERT_OK(readHeightmap(dir + "/map.yaml", read, heightmap_to_b));
  ASSERT_TRUE(read.origin);
  EXPECT_DOUBLE_EQ(read.origin->latitude_deg, kB.latitude_deg);
  const sss::core::LocalTangentPlane a(kA.latitude_deg, kA.longitude_deg), b(kB.latitude_deg, kB.longitude_deg);
  const Eigen::Vector3d corner = b.toNed(a.toGeodetic(Eigen::Vector3d(0.0, 0.0, 30.0)));
  EXPECT_NEAR(read.north_min_m, corner.x(), 0.1);
  EXPECT_NEAR(read.east_min_m, corner.y(), 0.1);
  EXPECT_NEAR(read.at(0, 0), corner.z(), 1e-3);
  EXPECT_GT(read.at(0, 0) - 30.0, 9.0);  // A's surface lies below B's tangent plane
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sss::eval
