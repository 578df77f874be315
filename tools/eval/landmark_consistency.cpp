// Landmark consistency error on the flat-seabed model. See landmark_consistency.hpp.
#include "tools/eval/landmark_consistency.hpp"

#include "pipeline/subframe/georeference.hpp"

#include <cmath>
#include <limits>

namespace sss::eval {

std::optional<Eigen::Vector3d> georeferenceObservation(const Trajectory& trajectory, const SonarObservation& observation,
                                                       const LandmarkConsistencyOptions& options) {
  const std::optional<sss::core::Pose> T_world_body =
      poseAtTime(trajectory, observation.utime_us, options.max_interpolation_gap_s);
  if (!T_world_body) return std::nullopt;
  const sss::core::Pose T_world_sonar = *T_world_body * options.T_body_sonar;
  const double altitude_m = options.seabed_depth_m - T_world_sonar.translation.z();
  if (!(altitude_m > 0.0)) return std::nullopt;
  // The same flat-seabed geometry as the pipeline's geo-reference.
  return sss::subframe::georeferenceGroundRange(T_world_sonar, altitude_m, observation.ground_range_m);
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
