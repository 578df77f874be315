// Geodesy: round trips and known distances on WGS-84.
#include "pipeline/core/geodesy.hpp"

#include <gtest/gtest.h>

namespace sss::core {
namespace {

TEST(LocalTangentPlane, OriginMapsToZero) {
  const LocalTangentPlane plane(59.35, 18.07);
  EXPECT_LT(plane.toNed({59.35, 18.07, 0.0}).norm(), 1e-9);
}

TEST(LocalTangentPlane, RoundTripBelowOneMillimetreAtTenKilometres) {
  const LocalTangentPlane plane(59.35, 18.07);
  for (const Eigen::Vector3d& ned : {Eigen::Vector3d(10000, 0, 50), Eigen::Vector3d(0, -10000, 120),
                                    Eigen::Vector3d(7071, 7071, 3), Eigen::Vector3d(-7071, 7071, 1000)}) {
    const GeodeticPosition geo = plane.toGeodetic(ned);
    const Eigen::Vector3d back = plane.toNed(geo);
    EXPECT_LT((back - ned).norm(), 1e-3) << ned.transpose();
    // And the geodetic side, through a 1 mm-equivalent angle (~9e-9 deg of latitude).
    const GeodeticPosition again = plane.toGeodetic(back);
    EXPECT_NEAR(again.latitude_deg, geo.latitude_deg, 1e-8);
    EXPECT_NEAR(again.longitude_deg, geo.longitude_deg, 1e-8);
    EXPECT_NEAR(again.depth_m, geo.depth_m, 1e-3);
  }
}

TEST(LocalTangentPlane, NorthIsNorthAndDepthIsDown) {
  const LocalTangentPlane plane(10.0, -30.0);
  // One minute of latitude near 10 deg N is about 1843 m on WGS-84.
  const Eigen::Vector3d ned = plane.toNed({10.0 + 1.0 / 60.0, -30.0, 25.0});
  EXPECT_NEAR(ned.x(), 1843.0, 2.0);
  EXPECT_NEAR(ned.y(), 0.0, 1e-6);
  // Down includes the curvature drop (~0.27 m over 1.8 km) on top of the depth.
  EXPECT_NEAR(ned.z(), 25.27, 0.02);
  const Eigen::Vector3d east = plane.toNed({10.0, -30.0 + 0.01, 0.0});
  EXPECT_GT(east.y(), 1090.0);
  EXPECT_LT(east.y(), 1100.0);
}

}  // namespace
}  // namespace sss::core
