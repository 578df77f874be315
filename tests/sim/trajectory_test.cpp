// Trajectory: lawnmower, loop and cross geometry, speed, terrain-following altitude, continuous pose.
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


TEST(Trajectory, LawnmowerPlanIsUnchanged) {
  // The plan every earlier mission was made with: lines joined by semicircles (the cross pattern
  // must not move it).
  TrajectoryOptions options;
  options.lines = 3;
  options.line_length_m = 200.0;
  options.line_spacing_m = 60.0;
  const std::vector<PathSegment> segments = planSurvey(options);
  ASSERT_EQ(segments.size(), 5u);
  struct Expected {
    bool is_line;
    int line;
    double start_distance_m, north_m, east_m, heading_rad, length_m, sign;
  };
  const double turn = M_PI * 30.0;
  const Expected expected[] = {
      {true, 0, 0.0, 0.0, 0.0, 0.0, 200.0, 1.0},
      {false, -1, 200.0, 200.0, 0.0, 0.0, turn, 1.0},
      {true, 1, 200.0 + turn, 200.0, 60.0, M_PI, 200.0, 1.0},
      {false, -1, 400.0 + turn, 0.0, 60.0, M_PI, turn, -1.0},
      {true, 2, 400.0 + 2.0 * turn, 0.0, 120.0, 0.0, 200.0, 1.0},
  };
  for (size_t k = 0; k < segments.size(); ++k) {
    const PathSegment& s = segments[k];
    const Expected& e = expected[k];
    EXPECT_EQ(s.is_line, e.is_line) << k;
    EXPECT_EQ(s.line_index, e.line) << k;
    EXPECT_NEAR(s.start_distance_m, e.start_distance_m, 1e-9) << k;
    EXPECT_NEAR(s.start.x(), e.north_m, 1e-9) << k;
    EXPECT_NEAR(s.start.y(), e.east_m, 1e-9) << k;
    EXPECT_NEAR(std::abs(sss::core::wrapAngle(s.start_heading_rad - e.heading_rad)), 0.0, 1e-12) << k;
    EXPECT_NEAR(s.length_m, e.length_m, 1e-9) << k;
    if (!s.is_line) {
      EXPECT_NEAR(s.turn_radius_m, 30.0, 1e-9) << k;
      EXPECT_EQ(s.turn_sign, e.sign) << k;
    }
  }
}

// End position and heading of a segment by the same geometry the trajectory samples.
void segmentEnd(const PathSegment& s, Eigen::Vector2d& position, double& heading_rad) {
  if (s.is_line) {
    heading_rad = s.start_heading_rad;
    position = s.start + s.length_m * Eigen::Vector2d(std::cos(heading_rad), std::sin(heading_rad));
    return;
  }
  const auto starboard = [](double h) { return Eigen::Vector2d(-std::sin(h), std::cos(h)); };
  const Eigen::Vector2d centre = s.start + s.turn_sign * s.turn_radius_m * starboard(s.start_heading_rad);
  heading_rad = s.start_heading_rad + s.turn_sign * s.length_m / s.turn_radius_m;
  position = centre - s.turn_sign * s.turn_radius_m * starboard(heading_rad);
}

TEST(Trajectory, CrossPatternIsContinuousWithPerpendicularLinesAcrossTheBlock) {
  for (const int lines : {2, 3, 4}) {
    TrajectoryOptions options;
    options.pattern = "cross";
    options.lines = lines;
    options.line_length_m = 300.0;
    options.line_spacing_m = 70.0;
    options.line_heading_deg = 30.0;
    const std::vector<PathSegment> segments = planSurvey(options);
    const double h0 = 30.0 * M_PI / 180.0;
    const Eigen::Vector2d along(std::cos(h0), std::sin(h0)), lateral(-std::sin(h0), std::cos(h0));
    // Joints: each segment starts where the previous ends, at its heading, at its distance.
    for (size_t k = 1; k < segments.size(); ++k) {
      Eigen::Vector2d end;
      double heading = 0.0;
      segmentEnd(segments[k - 1], end, heading);
      EXPECT_LT((end - segments[k].start).norm(), 1e-6) << lines << " lines, segment " << k;
      EXPECT_LT(std::abs(sss::core::wrapAngle(heading - segments[k].start_heading_rad)), 1e-9) << k;
      EXPECT_NEAR(segments[k].start_distance_m, segments[k - 1].start_distance_m + segments[k - 1].length_m, 1e-9);
      EXPECT_GT(segments[k].length_m, 0.0);
      if (!segments[k].is_line) {
        EXPECT_GE(segments[k].turn_radius_m, 20.0 - 1e-9);
      }
    }
    std::vector<const PathSegment*> cross;
    for (const PathSegment& s : segments) {
      if (s.line_index >= lines) cross.push_back(&s);
    }
    ASSERT_EQ(cross.size(), 2u) << lines;
    for (size_t j = 0; j < cross.size(); ++j) {
      const PathSegment& c = *cross[j];
      EXPECT_EQ(c.line_index, lines + static_cast<int>(j));
      // Perpendicular to the lawnmower, alternating directions.
      EXPECT_NEAR(std::abs(sss::core::wrapAngle(c.start_heading_rad - h0)), 0.5 * M_PI, 1e-9);
      if (j > 0) {
        EXPECT_NEAR(std::abs(sss::core::wrapAngle(c.start_heading_rad - cross[j - 1]->start_heading_rad)), M_PI, 1e-9);
      }
      // Inside the block along track (at 1/3 or 2/3 of it), across all lines with a spacing to spare.
      const double along_m = c.start.dot(along);
      EXPECT_TRUE(std::abs(along_m - 100.0) < 1e-6 || std::abs(along_m - 200.0) < 1e-6) << along_m;
      Eigen::Vector2d end;
      double heading = 0.0;
      segmentEnd(c, end, heading);
      EXPECT_NEAR(std::min(c.start.dot(lateral), end.dot(lateral)), -70.0, 1e-6);
      EXPECT_NEAR(std::max(c.start.dot(lateral), end.dot(lateral)), (lines - 1) * 70.0 + 70.0, 1e-6);
    }
    EXPECT_NE(cross[0]->start.dot(along), cross[1]->start.dot(along));

    // The sampled pose is continuous too, and connections are not survey lines.
    const Seabed bed = flatBed();
    const Trajectory trajectory(options, &bed);
    TrajectorySample previous = trajectory.sample(0.0);
    const double dt = 0.25;
    for (double t = dt; t <= trajectory.durationS(); t += dt) {
      const TrajectorySample sample = trajectory.sample(t);
      const double step = (sample.T_world_body.translation - previous.T_world_body.translation).head<2>().norm();
      EXPECT_NEAR(step, 2.0 * dt, 1e-3) << t;
      const double dheading = sss::core::wrapAngle(sss::core::eulerFromQuaternion(sample.T_world_body.rotation).heading_rad -
                                                   sss::core::eulerFromQuaternion(previous.T_world_body.rotation).heading_rad);
      EXPECT_LT(std::abs(dheading), 2.0 * dt / 20.0 + 0.002) << t;  // 20 m turns at 2 m/s + yaw wobble
      previous = sample;
    }
    for (const PathSegment& s : segments) {
      const double middle_s = (s.start_distance_m + 0.5 * s.length_m) / options.speed_m_s;
      EXPECT_EQ(trajectory.sample(middle_s).line_index, s.line_index) << middle_s;
    }
    // The seabed of a cross mission must cover the crossing lines' ends.
    const Eigen::Vector4d extent = Trajectory::planExtent(options);
    for (const PathSegment* c : cross) {
      Eigen::Vector2d end;
      double heading = 0.0;
      segmentEnd(*c, end, heading);
      for (const Eigen::Vector2d& p : {c->start, end}) {
        EXPECT_GE(p.x(), extent[0] - 1e-6);
        EXPECT_GE(p.y(), extent[1] - 1e-6);
        EXPECT_LE(p.x(), extent[2] + 1e-6);
        EXPECT_LE(p.y(), extent[3] + 1e-6);
      }
    }
  }
}

// Surfacing for GNSS fixes: a lead-in at the surface and a dive before the first line, the mirror
// after the last; "lines" also comes up half way through each turn. The survey lines themselves are
// flown at altitude as without surfacing, and the velocity follows the dive and the climb.
TEST(Trajectory, SurfacesForGnssFixesOutsideTheSurveyLines) {
  const Seabed bed = flatBed();
  TrajectoryOptions plain;
  plain.lines = 3;
  plain.line_length_m = 200.0;
  plain.line_spacing_m = 60.0;
  const Trajectory without(plain, &bed);
  for (const char* mode : {"start", "start-end", "lines"}) {
    SCOPED_TRACE(mode);
    TrajectoryOptions options = plain;
    options.surface = mode;
    const Trajectory trajectory(options, &bed);
    const double lead_m = options.surface_hold_m + options.surface_ramp_m;
    const bool at_end = std::string(mode) != "start";
    EXPECT_NEAR(trajectory.lengthM(), without.lengthM() + (at_end ? 2.0 : 1.0) * lead_m, 1e-6);
    EXPECT_NEAR(trajectory.sample(0.0).T_world_body.translation.z(), options.surface_depth_m, 1e-9);
    EXPECT_NEAR(trajectory.sample(10.0).T_world_body.translation.z(), options.surface_depth_m, 1e-9);  // 20 m held
    if (at_end) {
      EXPECT_NEAR(trajectory.sample(trajectory.durationS()).T_world_body.translation.z(), options.surface_depth_m, 1e-9);
    }
    // Survey lines at altitude, where they were.
    for (double d = 5.0; d < 200.0; d += 20.0) {
      const TrajectorySample on_line = trajectory.sample((lead_m + d) / options.speed_m_s);
      const TrajectorySample reference = without.sample(d / plain.speed_m_s);
      EXPECT_EQ(on_line.line_index, 0);
      EXPECT_NEAR(on_line.altitude_m, 18.0, 0.31) << d;
      EXPECT_LT((on_line.T_world_body.translation - reference.T_world_body.translation).head<2>().norm(), 1e-6) << d;
    }
    // The dive: smooth, and the velocity is the motion of the pose.
    for (double t = 1.0; t < lead_m / options.speed_m_s; t += 3.1) {
      const TrajectorySample a = trajectory.sample(t), b = trajectory.sample(t + 0.1), c = trajectory.sample(t + 0.05);
      const Eigen::Vector3d finite = (b.T_world_body.translation - a.T_world_body.translation) / 0.1;
      EXPECT_LT((c.velocity_world_m_s - finite).norm(), 0.01) << t;
    }
    // "lines": at the surface half way through the first turn.
    const double turn_middle_m = lead_m + 200.0 + 0.5 * M_PI * 30.0;
    const double turn_depth = trajectory.sample(turn_middle_m / options.speed_m_s).T_world_body.translation.z();
    if (std::string(mode) == "lines") {
      EXPECT_NEAR(turn_depth, options.surface_depth_m, 1e-9);
    } else {
      EXPECT_GT(turn_depth, 20.0);
    }
  }
  TrajectoryOptions bad = plain;
  bad.surface = "sometimes";
  EXPECT_THROW(Trajectory(bad, &bed), std::invalid_argument);
}

}  // namespace
}  // namespace sss::sim
