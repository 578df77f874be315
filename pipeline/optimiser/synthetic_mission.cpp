// Synthetic lawnmower missions for the pose-graph tests and benchmark, see synthetic_mission.hpp.
#include "pipeline/optimiser/synthetic_mission.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

namespace sss::optimiser::synthetic {

using sss::core::Pose;

namespace {

Pose poseAt(double north_m, double east_m, double depth_m, double heading_rad) {
  return Pose(sss::core::quaternionFromEuler(0.0, 0.0, heading_rad), Eigen::Vector3d(north_m, east_m, depth_m));
}

}  // namespace

Mission makeLawnmowerMission(const MissionOptions& o) {
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  Mission mission;

  // Truth and DR integrated together in steps: straight lines (curvature 0) joined by half-circle
  // turns, starboard after northbound lines and port after southbound ones.
  double north = 0.0, east = 0.0, heading = 0.0;                // truth
  double dr_north = 0.0, dr_east = 0.0, heading_noise = 0.0;    // DR
  double path_m = 0.0, dr_distance_m = 0.0;
  auto drHeading = [&]() { return heading + o.heading_bias_rad * std::cos(heading) + heading_noise; };
  auto step = [&](double ds, double curvature) {
    const double heading_mid = heading + 0.5 * curvature * ds;
    const double dr_heading_before = drHeading();
    north += ds * std::cos(heading_mid);
    east += ds * std::sin(heading_mid);
    heading += curvature * ds;
    const double keep = std::exp(-ds / o.heading_noise_correlation_m);
    heading_noise = keep * heading_noise + o.heading_noise_sigma_rad * std::sqrt(1.0 - keep * keep) * unit(rng);
    const double dr_heading_mid = 0.5 * (dr_heading_before + drHeading());
    const double dr_ds = (1.0 + o.velocity_scale_error) * ds;
    dr_north += dr_ds * std::cos(dr_heading_mid) + o.position_random_walk_m_per_sqrt_m * std::sqrt(ds) * unit(rng);
    dr_east += dr_ds * std::sin(dr_heading_mid) + o.position_random_walk_m_per_sqrt_m * std::sqrt(ds) * unit(rng);
    path_m += ds;
    dr_distance_m += dr_ds;
  };

  const int nodes_per_line = static_cast<int>(std::floor(o.line_length_m / o.subframe_length_m + 1e-9));
  const int steps_per_line = static_cast<int>(std::lround(o.line_length_m / o.step_m));
  const double radius = 0.5 * o.line_spacing_m;
  const int steps_per_turn = std::max(1, static_cast<int>(std::lround(M_PI * radius / o.step_m)));
  int64_t next_id = 1;
  for (int line = 0; line < o.num_lines; ++line) {
    std::vector<int> node_steps;
    for (int j = 0; j < nodes_per_line; ++j)
      node_steps.push_back(static_cast<int>(std::lround((j + 0.5) * o.subframe_length_m / o.step_m)));
    for (int s = 1; s <= steps_per_line; ++s) {
      step(o.line_length_m / steps_per_line, 0.0);
      if (std::find(node_steps.begin(), node_steps.end(), s) == node_steps.end()) continue;
      Node node;
      node.subframe_id = next_id++;
      node.utime_us = o.start_utime_us + static_cast<int64_t>(std::llround(1e6 * path_m / o.speed_m_s));
      node.truth = poseAt(north, east, o.depth_m, heading);
      node.dr = poseAt(dr_north, dr_east, o.depth_m, drHeading());
      node.distance_m = dr_distance_m;
      node.line = line;
      mission.nodes.push_back(node);
    }
    if (line + 1 == o.num_lines) break;
    const double turn_length = M_PI * radius;
    const double curvature = (line % 2 == 0 ? 1.0 : -1.0) / radius;  // starboard, then port
    for (int s = 0; s < steps_per_turn; ++s) step(turn_length / steps_per_turn, curvature);
    heading = line % 2 == 0 ? M_PI : 0.0;  // remove the rounding of the turn
  }

  // Closures between nodes of adjacent lines that overlap along track.
  sss::core::Vector6d sigma;
  sigma << o.closure_sigma_m, o.closure_sigma_m, o.closure_depth_sigma_m, o.closure_attitude_sigma_rad,
      o.closure_attitude_sigma_rad, o.closure_heading_sigma_rad;
  const sss::core::Matrix6d covariance = sigma.cwiseAbs2().asDiagonal();
  for (size_t j = 0; j < mission.nodes.size(); ++j) {
    for (size_t i = 0; i < j; ++i) {
      const Node& a = mission.nodes[i];
      const Node& b = mission.nodes[j];
      if (b.line != a.line + 1) continue;
      if (std::abs(a.truth.translation.x() - b.truth.translation.x()) > o.closure_max_along_track_m) continue;
      sss::core::Vector6d noise;
      for (int k = 0; k < 6; ++k) noise(k) = sigma(k) * unit(rng);
      Closure c;
      c.closure.subframe_id_a = a.subframe_id;
      c.closure.subframe_id_b = b.subframe_id;
      c.closure.T_a_b = sss::core::boxPlus(sss::core::between(a.truth, b.truth), noise);
      c.closure.covariance = covariance;
      c.closure.num_inliers = 200;
      c.newer_node = static_cast<int>(j);
      mission.closures.push_back(c);
    }
  }
  const int num_false = static_cast<int>(std::lround(o.false_fraction * mission.closures.size()));
  std::vector<int> order(mission.closures.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  for (int k = 0; k < num_false; ++k) {
    Closure& c = mission.closures[order[k]];
    const double offset_m = o.false_min_offset_m + (o.false_max_offset_m - o.false_min_offset_m) * uniform(rng);
    const double direction = 2.0 * M_PI * uniform(rng);
    const double heading_offset = (uniform(rng) < 0.5 ? -1.0 : 1.0) *
                                  (o.false_min_heading_rad + (o.false_max_heading_rad - o.false_min_heading_rad) * uniform(rng));
    sss::core::Vector6d offset;
    offset << offset_m * std::cos(direction), offset_m * std::sin(direction), 0.0, 0.0, 0.0, heading_offset;
    c.closure.T_a_b = sss::core::boxPlus(c.closure.T_a_b, offset);
    c.is_false = true;
  }
  return mission;
}

double translationRmse(const std::vector<Pose>& poses, const std::vector<Node>& nodes) {
  const size_t n = std::min(poses.size(), nodes.size());
  if (n == 0) return 0.0;
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) sum += (poses[i].translation - nodes[i].truth.translation).squaredNorm();
  return std::sqrt(sum / static_cast<double>(n));
}

std::vector<Pose> drPoses(const Mission& mission) {
  std::vector<Pose> out;
  for (const Node& n : mission.nodes) out.push_back(n.dr);
  return out;
}

}  // namespace sss::optimiser::synthetic
