// Quasi-dense bathymetry from loop-closure correspondences (paper Sec. "Bathymetric
// Reconstruction"): every inlier correspondence of a closure is one seabed point seen by two pings.
// With the two sonar poses (optimised or DR) the point is re-triangulated from both slant ranges
// and both fan planes (4 equations, 3 unknowns, Gauss-Newton), kept only when its range and plane
// residuals are small, and the points are gridded into a heightmap. No middleware.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/config.hpp"
#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/core/status.hpp"

namespace sss::optimiser {

struct BathymetryOptions {
  // A point is kept when both its slant-range residuals and both its distances to the fan planes
  // stay below these after the fit (the paper's range and plane residual filter). A wrong
  // correspondence or wrong poses make the four equations disagree.
  double max_range_residual_m = 0.15;
  double max_plane_residual_m = 0.5;
  // The two rays must not be nearly parallel in the across-track plane: the angle between the two
  // sonar-to-point directions below this gives a depth that the range noise dominates.
  double min_intersection_angle_rad = 0.17;  // 10 deg
  int max_points_per_closure = 3000;         // evenly thinned beyond this (memory on long missions)
  int max_iterations = 10;
  // Heightmap: cells of this size, depth = median of the points in the cell, cells with fewer
  // points than min_points_per_cell have no data.
  double heightmap_resolution_m = 2.0;
  int min_points_per_cell = 3;
};

void readBathymetryOptions(sss::core::ConfigSection& section, BathymetryOptions& options);
std::vector<std::string> validateBathymetryOptions(const BathymetryOptions& options);

// One correspondence to triangulate: the two sonar poses at their pings and the two slant ranges.
struct SonarObservation {
  sss::core::Pose T_world_sonar;
  double slant_range_m = 0.0;
};

struct SeabedPoint {
  Eigen::Vector3d position_ned_m = Eigen::Vector3d::Zero();
  float range_residual_m = 0.0f;  // largest |range - |p - sonar|| of the two
  float plane_residual_m = 0.0f;  // largest distance to the two fan planes
  int64_t subframe_id_a = 0;
  int64_t subframe_id_b = 0;
};

// Fits the seabed point seen by both observations, starting from initial_ned_m. nullopt when the
// fit does not converge, the geometry is degenerate, or a residual exceeds the options' limits.
std::optional<SeabedPoint> triangulateSeabedPoint(const SonarObservation& a, const SonarObservation& b,
                                                  const Eigen::Vector3d& initial_ned_m,
                                                  const BathymetryOptions& options);

// Gridded depth in the simulator's seabed format: cell (row, col) at north = north_min_m + row *
// resolution_m, east = east_min_m + col * resolution_m (rows grow northwards); NaN = no data.
struct HeightmapGrid {
  int rows = 0;
  int cols = 0;
  double resolution_m = 1.0;
  double north_min_m = 0.0;
  double east_min_m = 0.0;
  std::vector<float> depth_m;
  std::vector<uint16_t> points;  // points per cell
};

// Median depth of the points per cell; an empty grid when there are no points.
HeightmapGrid gridSeabedPoints(const std::vector<SeabedPoint>& points, const BathymetryOptions& options);

// Writes PREFIX.yaml + PREFIX_depth.f32 (readable by sss-eval's readHeightmap), PREFIX.png
// (colour-coded depth, north up, with a scale) and returns false with a message on failure.
// origin, when known, names the frame (YAML keys origin_latitude_deg / origin_longitude_deg).
sss::core::Status writeHeightmapFiles(const std::string& yaml_path, const HeightmapGrid& grid,
                                      const std::string& description,
                                      const std::optional<sss::core::MissionOrigin>& origin = std::nullopt);

// Binary little-endian PLY: x = north, y = east, z = down (metres, local NED), plus the residuals.
// origin, when known, goes into a header comment ("comment origin_latitude_deg .. origin_longitude_deg ..").
sss::core::Status writeSeabedPly(const std::string& path, const std::vector<SeabedPoint>& points,
                                 const std::optional<sss::core::MissionOrigin>& origin = std::nullopt);

}  // namespace sss::optimiser
