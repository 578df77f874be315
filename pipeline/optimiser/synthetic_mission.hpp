// Synthetic lawnmower missions of subframe-centre nodes with ground truth, drifting DR and loop
// closures between adjacent lines (a chosen fraction false), for the pose-graph tests and benchmark.
#pragma once

#include <cstdint>
#include <vector>

#include "pipeline/core/pose.hpp"
#include "pipeline/optimiser/pose_graph.hpp"

namespace sss::optimiser::synthetic {

struct MissionOptions {
  int num_lines = 5;
  double line_length_m = 400.0;
  double line_spacing_m = 100.0;     // turns are half circles of half this radius
  double subframe_length_m = 100.0;  // one node at each subframe centre along a line (50 s at 2 m/s)
  double speed_m_s = 2.0;
  double depth_m = 40.0;
  double step_m = 1.0;               // DR integration step
  int64_t start_utime_us = 1700000000000000;
  // DR errors. The heading bias is the gyrocompass steaming error, proportional to the north
  // velocity: +bias heading north, -bias heading south. A constant bias would rotate the whole DR
  // track rigidly about its start, which no relative measurement can see. On top of it a bounded,
  // slowly varying heading error (first-order Gauss-Markov over distance): a gyrocompassing INS
  // does not random-walk in heading. Position drifts through scale error and velocity noise.
  double heading_bias_rad = 0.0035;
  double heading_noise_sigma_rad = 0.002;
  double heading_noise_correlation_m = 1000.0;
  double velocity_scale_error = 0.002;
  double position_random_walk_m_per_sqrt_m = 0.01;
  // Closures between nodes of adjacent lines within this along-track distance.
  double closure_max_along_track_m = 50.0;
  double closure_sigma_m = 0.3;          // horizontal, 1 sigma
  double closure_depth_sigma_m = 0.2;
  double closure_attitude_sigma_rad = 0.003;
  double closure_heading_sigma_rad = 0.005;
  // This fraction of the closures (rounded) is replaced by a wrong relative pose: a horizontal
  // offset and a heading offset drawn uniformly from these ranges, random direction and sign.
  double false_fraction = 0.0;
  double false_min_offset_m = 3.0;
  double false_max_offset_m = 10.0;
  double false_min_heading_rad = 0.035;  // 2 deg
  double false_max_heading_rad = 0.17;   // 10 deg
  uint64_t seed = 1;
};

struct Node {
  int64_t subframe_id = 0;
  int64_t utime_us = 0;
  sss::core::Pose truth;  // T_world_body
  sss::core::Pose dr;
  double distance_m = 0.0;  // DR distance travelled since the mission start
  int line = 0;
};

struct Closure {
  LoopClosure closure;  // a = the older node
  bool is_false = false;
  int newer_node = 0;   // index of the node after which the matcher could deliver it
};

struct Mission {
  std::vector<Node> nodes;
  std::vector<Closure> closures;  // ordered by newer_node
};

Mission makeLawnmowerMission(const MissionOptions& options);

// Root mean square of the translation error of poses[i] against nodes[i].truth.
double translationRmse(const std::vector<sss::core::Pose>& poses, const std::vector<Node>& nodes);
std::vector<sss::core::Pose> drPoses(const Mission& mission);

}  // namespace sss::optimiser::synthetic
