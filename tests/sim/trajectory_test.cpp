// Trajectory: lawnmower and loop geometry, speed, terrain-following altitude, continuous pose.
#include "tools/sim/trajectory.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace sss::sim {
namespace {

Seabed flatBed() {
  SeabedOptions options;
  options.enable_texture = false;
  options.north_min_m = -300.0;
  options.east_min_m = -300.0;
  options.size_north_m = 1200.0;
  options.size_east_m = 1200.0;
  options.resolution_m = 2.0;
  options.mean_depth_m = 50.0;
  return Seabed(options);
}

TEST(Trajectory, LawnmowerLinesAlternateAndAreSpacedAsConfigured) {
  const Seabed bed = flatBed();
  TrajectoryOptions options;
  options.lines = 3;
  options.line_length_m = 200.0;
  options.line_spacing_m = 60.0;
  const Trajectory trajectory(options, &bed);
  // 3 lines + 2 semicircles of radius 30 m.
  EXPECT_NEAR(trajectory.lengthM(), 600.0 + 2.0 * M_PI * 30.0, 1e-6);
  const TrajectorySample mid_line0 = trajectory.sample(50.0);
  const TrajectorySample mid_line1 = trajectory.sample((200.0 + M_PI * 30.0 + 100.0) / 2.0);
  EXPECT_EQ(mid_line0.line_index, 0);
  EXPECT_EQ(mid_line1.line_index, 1);
  EXPECT_NEAR(mid_line1.T_world_body.translation.y() - mid_line0.T_world_body.translation.y(), 60.0, 1e-6);
  const double heading0 = sss::core::eulerFromQuaternion(mid_line0.T_world_body.rotation).heading_rad;
  const double heading1 = sss::core::eulerFromQuaternion(mid_line1.T_world_body.rotation).heading_rad;
  EXPECT_NEAR(std::abs(sss::core::wrapAngle(heading1 - heading0)), M_PI, 0.02);
  EXPECT_EQ(trajectory.sample(110.0 + 10.0).line_index, -1);  // in the first turn
}

TEST(Trajectory, FlysAtSpeedAndAltitudeWithSmallAttitude) {
  const Seabed bed = flatBed();
  TrajectoryOptions options;
  options.lines = 2;
  const Trajectory trajectory(options, &bed);
  for (double t = 1.0; t < trajectory.durationS() - 1.0; t += 7.3) {
    const TrajectorySample a = trajectory.sample(t);
    const TrajectorySample b = trajectory.sample(t + 0.1);
    const double speed = (b.T_world_body.translation - a.T_world_body.translation).head<2>().norm() / 0.1;
    EXPECT_NEAR(speed, 2.0, 0.01) << t;
    // The reported velocity (what the DVL and INS see) matches the motion of the pose.
    const TrajectorySample c = trajectory.sample(t + 0.05);
    const Eigen::Vector3d finite = (b.T_world_body.translation - a.T_world_body.translation) / 0.1;
    EXPECT_LT((c.velocity_world_m_s - finite).norm(), 0.01) << t;
    EXPECT_NEAR(a.altitude_m, 18.0, 0.31) << t;  // altitude wobble 0.3 m on a flat bed
    const sss::core::EulerAngles euler = sss::core::eulerFromQuaternion(a.T_world_body.rotation);
    EXPECT_LT(std::abs(euler.pitch_rad), 0.05);
    EXPECT_LT(std::abs(euler.roll_rad), 0.1);  // bank in turns ~4.6 deg + wobble
  }
}

TEST(Trajectory, LoopTurnsAlwaysToStarboard) {
  const Seabed bed = flatBed();
  TrajectoryOptions options;
  options.pattern = "loop";
  options.lines = 4;
  options.line_spacing_m = 60.0;
  const std::vector<PathSegment> segments = planSurvey(options);
  int turns = 0;
  for (const PathSegment& segment : segments) {
    if (segment.is_line) continue;
    ++turns;
    EXPECT_GT(segment.turn_sign, 0.0);
    EXPECT_GE(segment.turn_radius_m, 30.0 - 1e-9);
  }
  EXPECT_EQ(turns, 3);
}

}  // namespace
}  // namespace sss::sim
