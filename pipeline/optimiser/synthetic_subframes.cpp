// Synthetic subframes and matcher closures on a lawnmower, see synthetic_subframes.hpp.
#include "pipeline/optimiser/synthetic_subframes.hpp"

#include <cmath>
#include <map>
#include <random>

namespace sss::optimiser::synthetic {

using sss::core::Pose;

namespace {

constexpr double kSpeedMPerS = 2.0;  // as MissionOptions::speed_m_s by default

Pose alongTrack(const Pose& centre, double offset_m) {
  return centre * Pose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(offset_m, 0.0, 0.0));
}

}  // namespace

std::vector<sss::core::Subframe> makeSubframes(const Mission& mission, const SubframeOptions& options,
                                                   std::vector<std::vector<Pose>>* truth_pings) {
  std::vector<sss::core::Subframe> out;
  if (truth_pings) truth_pings->clear();
  const int centre = options.pings_per_subframe / 2;
  for (const Node& node : mission.nodes) {
    sss::core::Subframe subframe;
    subframe.id = node.subframe_id;
    subframe.line_id = node.line;
    subframe.centre_ping_index = centre;
    subframe.geometry.T_body_sonar = options.T_body_sonar;
    std::vector<Pose> truth;
    for (int i = 0; i < options.pings_per_subframe; ++i) {
      const double offset_m = (i - centre) * options.ping_spacing_m;
      sss::core::SubframePing ping;
      ping.utime_us = node.utime_us + static_cast<int64_t>(std::llround(1e6 * offset_m / kSpeedMPerS));
      ping.ping_number = node.subframe_id * options.pings_per_subframe + i;
      ping.T_world_body = alongTrack(node.dr, offset_m);
      ping.altitude_m = options.altitude_m;
      ping.distance_travelled_m = node.distance_m + offset_m;
      subframe.pings.push_back(ping);
      truth.push_back(alongTrack(node.truth, offset_m));
    }
    out.push_back(std::move(subframe));
    if (truth_pings) truth_pings->push_back(std::move(truth));
  }
  return out;
}

sss::core::LoopClosure makeMatcherClosure(const Mission& mission, size_t index,
                                             const std::vector<std::vector<Pose>>& truth_pings,
                                             const SubframeOptions& options, int association_round) {
  const Closure& source = mission.closures[index];
  std::map<int64_t, size_t> node_of;
  for (size_t i = 0; i < mission.nodes.size(); ++i) node_of[mission.nodes[i].subframe_id] = i;
  const size_t a = node_of.at(source.closure.subframe_id_a), b = node_of.at(source.closure.subframe_id_b);

  sss::core::LoopClosure closure;
  closure.subframe_id_a = source.closure.subframe_id_a;
  closure.subframe_id_b = source.closure.subframe_id_b;
  closure.centre_utime_a_us = mission.nodes[a].utime_us;
  closure.centre_utime_b_us = mission.nodes[b].utime_us;
  closure.T_a_b = source.closure.T_a_b;
  closure.covariance = source.closure.covariance;
  closure.association_round = association_round;
  closure.num_inliers = source.closure.num_inliers;
  closure.num_matches = 2 * closure.num_inliers;
  closure.total_cost = 1.0;
  closure.mean_zncc = 0.6f;

  const int n = options.pings_per_subframe, centre = n / 2;
  const Pose centre_a = truth_pings[a][centre];
  const Pose sonar_b_centre = truth_pings[b][centre] * options.T_body_sonar;
  std::mt19937_64 rng(1000 + 7919 * index + static_cast<uint64_t>(association_round));
  std::uniform_int_distribution<int> ping(0, n - 1);
  std::uniform_real_distribution<double> across(0.3, 0.7);
  for (int attempt = 0; attempt < 20 * options.correspondences_per_closure &&
                        static_cast<int>(closure.correspondences.size()) < options.correspondences_per_closure;
       ++attempt) {
    const int ping_a = ping(rng);
    const Pose sonar_a = truth_pings[a][ping_a] * options.T_body_sonar;
    // A seabed point in A's fan plane, part of the way across to B's line.
    const double lateral_m = (sonar_a.inverse() * sonar_b_centre.translation).y();
    const Eigen::Vector3d point = sonar_a * Eigen::Vector3d(0.0, across(rng) * lateral_m, options.altitude_m);
    const double along_b_m = (sonar_b_centre.inverse() * point).x();
    const int ping_b = centre + static_cast<int>(std::lround(along_b_m / options.ping_spacing_m));
    if (ping_b < 0 || ping_b >= n) continue;
    const Pose sonar_b = truth_pings[b][ping_b] * options.T_body_sonar;
    sss::core::ClosureCorrespondence c;
    c.ping_index_a = ping_a;
    c.ping_index_b = ping_b;
    c.column_a = 1000 + static_cast<int>(std::lround((sonar_a.inverse() * point).y() / 0.5));
    c.column_b = 1000 + static_cast<int>(std::lround((sonar_b.inverse() * point).y() / 0.5));
    c.slant_range_a_m = static_cast<float>((point - sonar_a.translation).norm());
    c.slant_range_b_m = static_cast<float>((point - sonar_b.translation).norm());
    c.landmark_a_m = (centre_a.inverse() * point).cast<float>();
    closure.correspondences.push_back(c);
  }
  return closure;
}

}  // namespace sss::optimiser::synthetic
