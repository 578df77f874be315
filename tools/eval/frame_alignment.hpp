// Re-expressing results written in one mission frame (local NED of one origin) in another's.
// A run processed with its own origin (the first fix of its navigation) and a simulator truth in
// the simulator's frame describe the same places in two tangent planes: a shift of up to the
// survey's size, a rotation of the axes by the meridian convergence (~1.5e-4 rad per km) and the
// Earth's curvature in the down axis (~8 cm at 1 km). Positions go through WGS-84 exactly.
#pragma once

#include "pipeline/core/mission_origin.hpp"
#include "tools/eval/trajectory_io.hpp"

namespace sss::eval {

struct HeightmapRaster;

// Within 1e-9 deg (0.1 mm): the same frame.
bool sameOrigin(const sss::core::MissionOrigin& a, const sss::core::MissionOrigin& b);

// One position (north, east, down in m), exactly.
Eigen::Vector3d reexpressPosition(const Eigen::Vector3d& ned_m, const sss::core::MissionOrigin& from,
                                  const sss::core::MissionOrigin& to);

// Every pose's position exactly, its attitude rotated by the rotation between the two frames'
// axes at that position.
void reexpressTrajectory(Trajectory& poses, const sss::core::MissionOrigin& from, const sss::core::MissionOrigin& to);

// The raster's grid is shifted by where its centre lands in the other frame and each depth is
// corrected for the other plane's curvature; the axes' rotation (below 1e-3 rad within 6 km) is
// not applied to the grid: it moves cells by less than a 0.5 m cell within a few km of the centre.
void reexpressHeightmap(HeightmapRaster& raster, const sss::core::MissionOrigin& from, const sss::core::MissionOrigin& to);

}  // namespace sss::eval
