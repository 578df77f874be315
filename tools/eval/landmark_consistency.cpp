// Landmark consistency error on the flat-seabed model. See landmark_consistency.hpp.
#include "tools/eval/landmark_consistency.hpp"

#include <cmath>
#include <limits>

namespace sss::eval {

std::optional<Eigen::Vector3d> georeferenceObservation(const Trajectory& trajectory, const SonarObservation& observation,
                                                       const LandmarkConsistencyOptions& options) {
  const std::optional<sss::core::Pose> T_world_body =
      poseAtTime(trajectory, observation.utime_us, options.max_interpolation_gap_s);
  if (!T_world_body) return std::nullopt;
  const sss::core::Pose T_world_sonar = *T_world_body * options.T_body_sonar;
  const Eigen::Vector3d origin = T_world_sonar.translation;
  const double altitude_m = options.seabed_depth_m - origin.z();
  if (!(altitude_m > 0.0)) return std::nullopt;
  const Eigen::Vector3d normal = T_world_sonar.rotation * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d down = Eigen::Vector3d::UnitZ();
  // v: horizontal direction of the fan plane's seabed line, to starboard; w: horizontal, forward.
  Eigen::Vector3d v = down.cross(normal);
  if (v.norm() < 1e-9) return std::nullopt;
  v.normalize();
  if (v.dot(T_world_sonar.rotation * Eigen::Vector3d::UnitY()) < 0.0) v = -v;
  const Eigen::Vector3d w = v.cross(down);
  const double nw = normal.dot(w);
  if (std::abs(nw) < 1e-9) return std::nullopt;
  // The seabed line is origin + h*down + t*w + s*v with normal . (h*down + t*w) = 0.
  const double t = -altitude_m * normal.z() / nw;
  const double g = observation.ground_range_m;
  const double s2 = g * g - t * t;
  if (s2 < 0.0) return std::nullopt;
  const double s = std::copysign(std::sqrt(s2), g);
  return Eigen::Vector3d(origin + altitude_m * down + t * w + s * v);
}

LandmarkConsistencyResult landmarkConsistency(const Trajectory& trajectory,
                                              const std::vector<LandmarkCorrespondence>& correspondences,
                                              const LandmarkConsistencyOptions& options) {
  LandmarkConsistencyResult result;
  result.distances_m.reserve(correspondences.size());
  for (const LandmarkCorrespondence& c : correspondences) {
    const std::optional<Eigen::Vector3d> a = georeferenceObservation(trajectory, c.a, options);
    const std::optional<Eigen::Vector3d> b = georeferenceObservation(trajectory, c.b, options);
    if (!a || !b) {
      result.distances_m.push_back(std::numeric_limits<double>::quiet_NaN());
      ++result.skipped;
      continue;
    }
    result.distances_m.push_back((*a - *b).head<2>().norm());
  }
  result.horizontal_m = errorStatistics(result.distances_m);  // NaN entries are left out
  return result;
}

}  // namespace sss::eval
