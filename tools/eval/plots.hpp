// What is still drawn or read with OpenCV for the evaluation: the heightmap error map PNG (the
// report's charts are drawn by report_figures.py, see figure_script.hpp) and the 8-bit mosaics.
#pragma once

#include "tools/eval/heightmap_metrics.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace sss::eval {

struct ErrorMapPngOptions {
  // Colour scale +-limit_m; <= 0 picks the 99th percentile of |error| rounded up to 1, 2 or 5 x 10^k.
  double limit_m = 0.0;
  int max_size_px = 1400;  // larger rasters are block-averaged down to this
};

// North up; blue = estimate shallower, white = 0, red = estimate deeper, grey = no data; a colour
// bar with its scale in metres below. used_limit_m (optional) receives the scale used.
sss::core::Status writeErrorMapPng(const std::string& path, const HeightmapRaster& error_map, const std::string& title,
                                   const ErrorMapPngOptions& options = {}, double* used_limit_m = nullptr);

// Round up to 1, 2 or 5 x 10^k.
double niceCeil(double value);

// An 8-bit grey mosaic in the simulator's mosaic.yaml layout: pixel (row, col) lies at north =
// north_max_m - (row + 0.5) * resolution_m, east = east_min_m + (col + 0.5) * resolution_m; 0 = no data.
struct GreyMosaic {
  int rows = 0;
  int cols = 0;
  double resolution_m = 1.0;
  double north_max_m = 0.0;
  double east_min_m = 0.0;
  std::vector<uint8_t> pixels;  // row-major, row 0 northmost
};

// Reads X.yaml (keys resolution_m, north_max_m, east_min_m, rows, cols) and the 8-bit grey X.png
// beside it. Fails with a message naming the file on any problem (missing key, size mismatch).
sss::core::Status readMosaic(const std::string& yaml_path, GreyMosaic& mosaic);

}  // namespace sss::eval
