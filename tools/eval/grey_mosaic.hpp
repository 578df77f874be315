// The simulator's 8-bit grey mosaic (the true-pose mosaic under the report's trajectory map).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/core/status.hpp"

namespace sss::eval {

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
