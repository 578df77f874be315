// Geo-referencing of canonical image pixels on the flat-seabed model (paper Sec. "Geo-referenced
// Image", after King et al. 2012): local NED position of any pixel for a given set of ping poses.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "pipeline/core/pose.hpp"
#include "pipeline/core/subframe_types.hpp"

namespace sss::core {

// The seabed point of a ground-range pixel of one ping. The point lies in the sonar's fan plane
// (perpendicular to the sonar x axis, the paper's Sec. on the canonical transform), on the horizontal seabed at depth = sonar depth
// + altitude_m, at the pixel's canonical ground range g = sqrt(r^2 - h^2) from the sonar. With
// pitch the fan plane meets that seabed off the nadir point; the along-track offset t of that
// line is part of g (g^2 = t^2 + s^2, s the across-track distance). nullopt when the column lies
// inside that offset (no such point) or the sonar x axis is vertical.
std::optional<Eigen::Vector3d> georeferencePixel(const SubframeGeometry& geometry, const Pose& T_world_body,
                                                 double altitude_m, double column);

// The same for a sonar pose and a signed ground range (+ starboard, - port) instead of a column.
std::optional<Eigen::Vector3d> georeferenceGroundRange(const Pose& T_world_sonar, double altitude_m,
                                                       double signed_ground_range_m);

// Pixel (row, column) of a subframe with the given per-ping body poses (DR, optimised, or ground
// truth; one per row). Altitudes are the subframe's.
std::optional<Eigen::Vector3d> georeferencePixel(const Subframe& subframe,
                                                 const std::vector<Pose>& T_world_body, int row,
                                                 double column);

// The subframe's own DR poses, one per row.
std::vector<Pose> drPoses(const Subframe& subframe);

}  // namespace sss::core
