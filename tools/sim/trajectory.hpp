// Simulated AUV path: lawnmower, loop or lawnmower + crossing survey lines joined by turns, flown at
// constant speed and altitude over the seabed with small roll/pitch motion; the ground-truth pose at any time.
#pragma once

#include "pipeline/core/pose.hpp"
#include "tools/sim/seabed.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace sss::sim {

struct TrajectoryOptions {
  std::string pattern = "lawnmower";  // "lawnmower", "loop" or "cross"
  int lines = 5;
  // "cross": after the lawnmower, this many lines perpendicular to it across the block (evenly
  // spaced along it, alternating directions), joined by turn-straight-turn paths of this radius.
  int cross_lines = 2;
  double cross_turn_radius_m = 20.0;
  double line_length_m = 400.0;
  double line_spacing_m = 70.0;  // 75 m range: adjacent lines overlap ~50% of a 150 m swath pair
  double line_heading_deg = 0.0; // heading of the first line, clockwise from north
  double speed_m_s = 2.0;
  double altitude_m = 18.0;
  double roll_amplitude_rad = 0.012;   // ~0.7 deg wave/control wobble
  double roll_period_s = 14.0;
  double pitch_amplitude_rad = 0.008;
  double pitch_period_s = 22.0;
  double yaw_amplitude_rad = 0.004;    // heading hunting of the autopilot around the line
  double yaw_period_s = 40.0;
  double altitude_wobble_m = 0.3;      // terrain following is not perfect
  // Slow altitude changes along the path (commanded steps, a sluggish terrain follower): smooth
  // noise of this amplitude over this path length; 0 keeps the altitude constant.
  double altitude_variation_m = 0.0;
  double altitude_variation_length_m = 300.0;
  double max_turn_bank_rad = 0.08;     // roll into turns
  // Surfacing for GNSS fixes (set from the mission's fix options): "none"; "start": a lead-in at the
  // surface before the first line, then the dive; "start-end": also a climb and a lead-out at the
  // surface after the last line; "lines": also up to the surface half way through every turn
  // between lawnmower lines. The lead-in and lead-out run straight along the first and last lines.
  std::string surface = "none";
  double surface_hold_m = 40.0;   // path at the surface (20 s at 2 m/s)
  double surface_ramp_m = 80.0;   // path to dive from the surface to the flying depth, or to climb
  double surface_depth_m = 0.3;   // the hull awash: the GNSS antenna on its mast is out of the water
  uint64_t seed = 1;
};

// One straight or one arc of the path, parameterised by distance along the path.
struct PathSegment {
  bool is_line = true;          // straight: a survey line, or part of a connection (line_index -1)
  int line_index = -1;          // survey line number for survey lines, -1 for connections
  double start_distance_m = 0.0;
  double length_m = 0.0;
  Eigen::Vector2d start = Eigen::Vector2d::Zero();  // north, east
  double start_heading_rad = 0.0;
  double turn_radius_m = 0.0;   // turns only
  double turn_sign = 1.0;       // +1 clockwise (starboard turn), -1 anticlockwise
};

struct TrajectorySample {
  double time_s = 0.0;
  sss::core::Pose T_world_body;
  Eigen::Vector3d velocity_world_m_s = Eigen::Vector3d::Zero();
  double altitude_m = 0.0;  // true altitude above the seabed directly below
  int line_index = -1;      // -1 while turning
};

class Trajectory {
 public:
  Trajectory(const TrajectoryOptions& options, const Seabed* seabed);

  double durationS() const { return total_length_m_ / options_.speed_m_s; }
  double lengthM() const { return total_length_m_; }
  TrajectorySample sample(double time_s) const;
  const std::vector<PathSegment>& segments() const { return segments_; }
  const TrajectoryOptions& options() const { return options_; }

  // The horizontal footprint of the path (north/east min and max) before any swath margin.
  static Eigen::Vector4d planExtent(const TrajectoryOptions& options);

 private:
  void planarState(double distance_m, Eigen::Vector2d& position, double& heading_rad, double& curvature, int& line) const;

  // Where the vehicle is at the surface: [from, to] of path distance, and the ramp to the flying depth
  // on either side. submergedWeight() is 0 inside, 1 a ramp away, smooth in between.
  struct SurfaceWindow {
    double from_m, to_m, ramp_m;
  };
  double submergedWeight(double distance_m) const;

  TrajectoryOptions options_;
  std::vector<SurfaceWindow> surface_windows_;
  const Seabed* seabed_;
  std::vector<PathSegment> segments_;
  double total_length_m_ = 0.0;
  double phase_roll_ = 0.0;
  double phase_pitch_ = 0.0;
  double phase_yaw_ = 0.0;
  double phase_altitude_ = 0.0;
};

std::vector<PathSegment> planSurvey(const TrajectoryOptions& options);

}  // namespace sss::sim
