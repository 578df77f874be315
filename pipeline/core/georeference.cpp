// Flat-seabed geo-referencing of canonical pixels. See georeference.hpp.
#include "pipeline/core/georeference.hpp"

#include <cmath>

namespace sss::core {

std::optional<Eigen::Vector3d> georeferenceGroundRange(const Pose& T_world_sonar, double altitude_m,
                                                       double signed_ground_range_m) {
  const Eigen::Vector3d origin = T_world_sonar.translation;
  const Eigen::Vector3d normal = T_world_sonar.rotation * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d down = Eigen::Vector3d::UnitZ();
  // v: horizontal direction of the fan plane's seabed line, pointing to starboard.
  Eigen::Vector3d v = down.cross(normal);
  if (v.norm() < 1e-9) return std::nullopt;
  v.normalize();
  if (v.dot(T_world_sonar.rotation * Eigen::Vector3d::UnitY()) < 0.0) v = -v;
  // w: horizontal, perpendicular to v (roughly forward). The seabed line is origin + h*down +
  // t*w + s*v with normal . (h*down + t*w) = 0.
  const Eigen::Vector3d w = v.cross(down);
  const double nw = normal.dot(w);
  if (std::abs(nw) < 1e-9) return std::nullopt;
  const double h = altitude_m;
  const double t = -h * normal.z() / nw;
  const double g = signed_ground_range_m;
  const double s2 = g * g - t * t;
  if (s2 < 0.0) return std::nullopt;
  const double s = std::copysign(std::sqrt(s2), g);
  return Eigen::Vector3d(origin + h * down + t * w + s * v);
}

std::optional<Eigen::Vector3d> georeferencePixel(const SubframeGeometry& geometry, const Pose& T_world_body,
                                                 double altitude_m, double column) {
  return georeferenceGroundRange(T_world_body * geometry.T_body_sonar, altitude_m, geometry.signedGroundRangeM(column));
}

std::optional<Eigen::Vector3d> georeferencePixel(const Subframe& subframe,
                                                 const std::vector<Pose>& T_world_body, int row,
                                                 double column) {
  if (row < 0 || row >= subframe.rows() || row >= static_cast<int>(T_world_body.size())) return std::nullopt;
  return georeferencePixel(subframe.geometry, T_world_body[row], subframe.pings[row].altitude_m, column);
}

std::vector<Pose> drPoses(const Subframe& subframe) {
  std::vector<Pose> poses;
  poses.reserve(subframe.pings.size());
  for (const SubframePing& p : subframe.pings) poses.push_back(p.T_world_body);
  return poses;
}

}  // namespace sss::core
