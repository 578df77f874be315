// How many survey lines saw each patch of seabed: the subframes' footprints (port and starboard swath
// edges along each subframe, under the SLAM poses) rasterised on a north/east grid, a count of the
// distinct lines per cell. Gives the area covered and the share seen from two lines or more, which is
// what side-scan SLAM can use (and what a surveyor checks for gaps). Pure C++, no I/O but the writer.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/mission_origin.hpp"
#include "products/geotiff.hpp"

namespace sss::products {

// One subframe's footprint: the swath edges at a few pings along it (same count on both sides).
struct FootprintStrip {
  int line_id = 0;
  std::vector<Eigen::Vector2d> port_ne_m;
  std::vector<Eigen::Vector2d> starboard_ne_m;
};

struct CoverageGrid {
  double resolution_m = 5.0;
  double north_min_m = 0.0, east_min_m = 0.0;  // centre of cell (0, 0)
  int rows = 0, cols = 0;
  std::vector<uint8_t> lines;  // distinct lines per cell, row-major (255 = 255 or more)
  double covered_m2 = 0.0;     // seen at least once
  double seen_twice_m2 = 0.0;  // from two lines or more
  double fractionSeenTwice() const { return covered_m2 > 0.0 ? seen_twice_m2 / covered_m2 : 0.0; }
};

CoverageGrid computeCoverage(const std::vector<FootprintStrip>& strips, double resolution_m);

// coverage.yaml (geo-reference: the heightmap's keys), coverage_lines.u8 (raw uint8, row-major) and
// coverage.png (none black, one line grey, two green, three or more blue), north up.
sss::core::Status writeCoverageFiles(const std::string& yaml_path, const CoverageGrid& grid,
                                     const std::optional<sss::core::MissionOrigin>& origin);

// The grid as an 8-bit GeoTIFF raster, north up; cells no line saw are no data.
FrameRaster coverageRaster(const CoverageGrid& grid);

}  // namespace sss::products
