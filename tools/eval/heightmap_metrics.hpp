// Heightmaps in the simulator's seabed format (YAML header + raw float32 raster, NaN = no data):
// reading, writing, and the depth error of an estimated map against the true seabed (the error
// map's PNG is drawn by report_figures.py, see figure_script.hpp).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/mission_origin.hpp"
#include "tools/eval/trajectory_metrics.hpp"
#include "pipeline/core/status.hpp"

namespace sss::eval {

// Cell (row, col) holds the depth at north = north_min_m + row * resolution_m, east =
// east_min_m + col * resolution_m (local NED, depth positive down); rows grow northwards; the
// raster is row-major. The value refers to that point (the cell centre), NaN where there is no data.
struct HeightmapRaster {
  int rows = 0;
  int cols = 0;
  double resolution_m = 1.0;
  double north_min_m = 0.0;
  double east_min_m = 0.0;
  std::vector<float> depth_m;     // rows * cols
  std::string description;        // written as the YAML's header comment (optional)
  std::string units = "metres below the origin (NED z, positive down)";
  // The frame's origin (YAML keys origin_latitude_deg / origin_longitude_deg); nullopt: not said.
  std::optional<sss::core::MissionOrigin> origin;

  float at(int row, int col) const { return depth_m[static_cast<size_t>(row) * cols + col]; }
  float& at(int row, int col) { return depth_m[static_cast<size_t>(row) * cols + col]; }
  double northM(int row) const { return north_min_m + row * resolution_m; }
  double eastM(int col) const { return east_min_m + col * resolution_m; }
  // Bilinear depth at (north, east) from the four surrounding cells; nullopt outside the raster
  // or when any of the four with a non-zero weight has no data.
  std::optional<double> sampleBilinear(double north_m, double east_m) const;
};

struct HeightmapReadOptions {
  int64_t max_cells = 400'000'000;  // 1.6 GB of float32: a header asking for more is corrupt
  // Set: a raster whose header names another origin is re-expressed in this one's frame
  // (frame_alignment.hpp); raster.origin then says the target.
  std::optional<sss::core::MissionOrigin> target_origin;
};

// Reads YAML keys rows, cols, resolution_m, north_min_m, east_min_m, depth_file (relative to the
// YAML's folder unless absolute), and origin_latitude_deg + origin_longitude_deg when present.
// Fails with "FILE:LINE: ..." on any problem.
sss::core::Status readHeightmap(const std::string& yaml_path, HeightmapRaster& raster,
                                const HeightmapReadOptions& options = {});

// Writes PREFIX.yaml and PREFIX_depth.f32 (the simulator's layout). path may be the prefix or
// the YAML path itself ("out/map" or "out/map.yaml"). Fails with a message.
sss::core::Status writeHeightmap(const std::string& path, const HeightmapRaster& raster);

struct HeightmapErrorResult {
  bool ok = false;
  std::string error;
  size_t estimate_cells = 0;       // rows * cols of the estimate
  size_t cells_with_data = 0;      // finite estimate cells
  size_t compared_cells = 0;       // of those, inside the truth with truth data at all 4 neighbours
  double coverage_fraction = 0.0;  // cells_with_data / estimate_cells
  double covered_area_m2 = 0.0;    // cells_with_data * resolution^2
  ErrorStatistics abs_error_m;     // |estimate - truth| over compared cells (MAE = abs_error_m.mean)
  double mean_signed_error_m = std::numeric_limits<double>::quiet_NaN();  // estimate - truth: bias
  HeightmapRaster error_map;       // estimate - truth on the estimate's grid, NaN where not compared
};

// Compares estimate against truth at every estimate cell with data, the truth resampled
// bilinearly at the cell centre.
HeightmapErrorResult compareHeightmaps(const HeightmapRaster& truth, const HeightmapRaster& estimate);

}  // namespace sss::eval
