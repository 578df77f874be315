// FixAligner: fixes placed in the mission frame with the DR state at their time, GNSS only at the
// surface, waiting for the navigation, late and frameless fixes counted, undated fixes dated.
#include <gtest/gtest.h>

#include "drivers/ins/fix_aligner.hpp"

namespace sss::ins {
namespace {

const sss::core::MissionOrigin kOrigin{59.35, 18.07};
constexpr int64_t kT0 = 1780300800000000;  // 2026-06-01T08:00:00Z

// A fix at time t (s after kT0) at north/east of the origin.
PositionFix fixAt(double t_s, double north_m, double east_m, FixSource source) {
  const sss::core::LocalTangentPlane plane(kOrigin.latitude_deg, kOrigin.longitude_deg);
  const sss::core::GeodeticPosition geo = plane.toGeodetic(Eigen::Vector3d(north_m, east_m, 0.0));
  PositionFix fix;
  fix.utime_us = kT0 + static_cast<int64_t>(t_s * 1e6);
  fix.seconds_of_day = 8 * 3600.0 + t_s;
  fix.dated = true;
  fix.latitude_deg = geo.latitude_deg;
  fix.longitude_deg = geo.longitude_deg;
  fix.sigma_north_m = 0.5;
  fix.sigma_east_m = 0.8;
  fix.source = source;
  return fix;
}

TEST(FixAligner, TiesAFixToTheDrStateAtItsTimeInTheMissionFrame) {
  FixAligner aligner;
  aligner.addNav(kT0, Eigen::Vector3d(0, 0, 20), 0.0, kOrigin);
  aligner.addFix(fixAt(5.0, 104.0, 51.0, FixSource::kUsbl));  // the navigation has not got there yet
  EXPECT_TRUE(aligner.take().empty());
  aligner.addNav(kT0 + 10000000, Eigen::Vector3d(20, 0, 30), 20.0, kOrigin);
  const std::vector<AlignedFix> aligned = aligner.take();
  ASSERT_EQ(aligned.size(), 1u);
  EXPECT_NEAR(aligned[0].position_ne_m.x(), 104.0, 1e-6);
  EXPECT_NEAR(aligned[0].position_ne_m.y(), 51.0, 1e-6);
  EXPECT_NEAR(aligned[0].covariance_m2(0, 0), 0.25, 1e-12);
  EXPECT_NEAR(aligned[0].covariance_m2(1, 1), 0.64, 1e-12);
  EXPECT_NEAR((aligned[0].dr_position_m - Eigen::Vector3d(10, 0, 25)).norm(), 0.0, 1e-9);
  EXPECT_NEAR(aligned[0].dr_distance_m, 10.0, 1e-9);
  EXPECT_NEAR(aligned[0].depth_m, 25.0, 1e-9);
  EXPECT_EQ(aligner.counters().aligned, 1u);
}

TEST(FixAligner, GnssCountsOnlyAtTheSurface) {
  FixAligner aligner;
  aligner.addNav(kT0, Eigen::Vector3d(0, 0, 0.3), 0.0, kOrigin);
  aligner.addNav(kT0 + 10000000, Eigen::Vector3d(20, 0, 0.3), 20.0, kOrigin);
  aligner.addNav(kT0 + 20000000, Eigen::Vector3d(40, 0, 25.0), 40.0, kOrigin);
  aligner.addFix(fixAt(5.0, 10.0, 0.0, FixSource::kGnss));   // at the surface
  aligner.addFix(fixAt(19.0, 38.0, 0.0, FixSource::kGnss));  // 22.5 m down: stale
  aligner.addFix(fixAt(19.0, 38.0, 0.0, FixSource::kUsbl));  // USBL works under water
  const std::vector<AlignedFix> aligned = aligner.take();
  ASSERT_EQ(aligned.size(), 2u);
  EXPECT_EQ(aligned[0].fix.source, FixSource::kGnss);
  EXPECT_EQ(aligned[1].fix.source, FixSource::kUsbl);
  EXPECT_EQ(aligner.counters().below_surface, 1u);
}

TEST(FixAligner, LateFramelessAndOutOfSpanFixesAreCountedAndDropped) {
  FixAlignerOptions options;
  options.max_latency_s = 60.0;
  FixAligner aligner(options);
  // No geographic frame yet (a projected file, or before the first position).
  aligner.addNav(kT0, Eigen::Vector3d(0, 0, 20), 0.0, std::nullopt);
  aligner.addFix(fixAt(0.0, 0.0, 0.0, FixSource::kUsbl));
  EXPECT_TRUE(aligner.take().empty());
  EXPECT_EQ(aligner.counters().no_frame, 1u);

  FixAligner framed(options);
  for (int s = 0; s <= 200; s += 10) framed.addNav(kT0 + s * 1000000LL, Eigen::Vector3d(2.0 * s, 0, 20), 2.0 * s, kOrigin);
  framed.addFix(fixAt(30.0, 60.0, 0.0, FixSource::kUsbl));    // 170 s late: its navigation is gone
  framed.addFix(fixAt(150.0, 300.0, 0.0, FixSource::kUsbl));  // 50 s late: still held
  framed.addFix(fixAt(205.0, 410.0, 0.0, FixSource::kUsbl));  // ahead of the navigation: waits
  std::vector<AlignedFix> aligned = framed.take();
  ASSERT_EQ(aligned.size(), 1u);
  EXPECT_NEAR(aligned[0].dr_position_m.x(), 300.0, 1e-9);
  EXPECT_EQ(framed.counters().outside_navigation, 1u);
  // End of input: 5 s after the last sample is more than max_extrapolation_s (2 s).
  aligned = framed.take(true);
  EXPECT_TRUE(aligned.empty());
  EXPECT_EQ(framed.counters().outside_navigation, 2u);
}

TEST(FixAligner, UndatedFixesTakeTheNavigationsDay) {
  FixAligner aligner;
  PositionFix fix = fixAt(3.0, 6.0, 0.0, FixSource::kUsbl);
  fix.dated = false;
  fix.utime_us = 0;
  aligner.addFix(fix);  // before any navigation: dated by the first sample
  aligner.addNav(kT0, Eigen::Vector3d(0, 0, 20), 0.0, kOrigin);
  aligner.addNav(kT0 + 10000000, Eigen::Vector3d(20, 0, 20), 20.0, kOrigin);
  const std::vector<AlignedFix> aligned = aligner.take();
  ASSERT_EQ(aligned.size(), 1u);
  EXPECT_EQ(aligned[0].fix.utime_us, kT0 + 3000000);
  EXPECT_NEAR(aligned[0].dr_position_m.x(), 6.0, 1e-9);
}

}  // namespace
}  // namespace sss::ins
