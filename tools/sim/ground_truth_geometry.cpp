// Ground-truth geometry by the same ray cast the renderer uses, so a pixel and its seabed point
// agree to the ray-cast step, and the inverse search over fan-plane crossings.
#include "tools/sim/ground_truth_geometry.hpp"

#include <algorithm>
#include <cmath>

namespace sss::sim {

GroundTruthGeometry::GroundTruthGeometry(const Seabed* seabed, const SonarOptions& options)
    : seabed_(seabed), options_(options) {}

std::optional<SeabedHit> GroundTruthGeometry::sampleToSeabed(const sss::core::Pose& T_world_sonar, Side side,
                                                             double sample) const {
  const double range = sample * options_.sampleSpacingM();
  const std::vector<ProfilePoint> profile = castProfile(*seabed_, T_world_sonar, side, options_);
  for (size_t k = 1; k < profile.size(); ++k) {
    const ProfilePoint& a = profile[k - 1];
    const ProfilePoint& b = profile[k];
    if (!a.visible || !b.visible) continue;
    const double lo = std::min(a.slant_range_m, b.slant_range_m);
    const double hi = std::max(a.slant_range_m, b.slant_range_m);
    if (range < lo || range > hi) continue;
    const double alpha = hi - lo < 1e-12 ? 0.5 : (range - a.slant_range_m) / (b.slant_range_m - a.slant_range_m);
    SeabedHit hit;
    hit.position_ned_m = a.position_ned_m + alpha * (b.position_ned_m - a.position_ned_m);
    hit.slant_range_m = range;
    return hit;
  }
  return std::nullopt;
}

std::vector<PingObservation> GroundTruthGeometry::observationsOf(const Eigen::Vector3d& point_ned_m,
                                                                 const std::vector<sss::core::Pose>& ping_poses) const {
  std::vector<PingObservation> observations;
  if (ping_poses.size() < 2) return observations;
  const auto signedDistance = [&](const sss::core::Pose& pose) {
    return (pose.rotation * Eigen::Vector3d::UnitX()).dot(point_ned_m - pose.translation);
  };
  double previous = signedDistance(ping_poses[0]);
  for (size_t i = 1; i < ping_poses.size(); ++i) {
    const double current = signedDistance(ping_poses[i]);
    // The vehicle passes the point when its fan plane sweeps from ahead of it to behind it.
    if (previous >= 0.0 && current < 0.0) {
      const double alpha = previous / (previous - current);
      const sss::core::Pose pose = sss::core::interpolate(ping_poses[i - 1], ping_poses[i], alpha);
      const Eigen::Vector3d offset = point_ned_m - pose.translation;
      const double range = offset.norm();
      if (range <= options_.range_m) {
        PingObservation observation;
        observation.ping_index = static_cast<double>(i - 1) + alpha;
        observation.nearest_ping = alpha < 0.5 ? i - 1 : i;
        const double lateral = (pose.rotation * Eigen::Vector3d::UnitY()).dot(offset);
        observation.side = lateral >= 0.0 ? Side::kStarboard : Side::kPort;
        observation.slant_range_m = range;
        observation.sample = range / options_.sampleSpacingM();
        // Visible when the ray cast's profile point at the same horizontal distance is lit and lies
        // on this point. (Not "the first seabed at this range": with layover, a boulder face and the
        // bed in front of it share a range, and both are seen.)
        const std::vector<ProfilePoint> profile = castProfile(*seabed_, pose, observation.side, options_);
        const FanPlane plane = fanPlane(pose, observation.side);
        const double u = (point_ned_m - plane.origin).dot(plane.outward);
        const auto k = static_cast<size_t>(std::max(0.0, std::round(u / options_.ground_step_m)));
        observation.visible = k < profile.size() && profile[k].visible &&
                              (profile[k].position_ned_m - point_ned_m).norm() < 2.0 * options_.ground_step_m + 0.05;
        observations.push_back(observation);
      }
    }
    previous = current;
  }
  return observations;
}

}  // namespace sss::sim
