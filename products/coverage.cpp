// Coverage raster, see coverage.hpp.
#include "products/coverage.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace sss::products {

using sss::core::Status;

namespace {

// Inside a convex quadrilateral given in order (either winding).
bool insideConvex(const Eigen::Vector2d& p, const Eigen::Vector2d (&q)[4]) {
  int sign = 0;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d a = q[i], b = q[(i + 1) % 4];
    const double cross = (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
    const int s = cross > 0.0 ? 1 : (cross < 0.0 ? -1 : 0);
    if (s == 0) continue;
    if (sign == 0) sign = s;
    else if (s != sign) return false;
  }
  return true;
}

}  // namespace

CoverageGrid computeCoverage(const std::vector<FootprintStrip>& strips, double resolution_m) {
  CoverageGrid grid;
  grid.resolution_m = resolution_m;
  double n_min = 1e300, n_max = -1e300, e_min = 1e300, e_max = -1e300;
  for (const FootprintStrip& s : strips)
    for (const auto* side : {&s.port_ne_m, &s.starboard_ne_m})
      for (const Eigen::Vector2d& p : *side) {
        n_min = std::min(n_min, p.x());
        n_max = std::max(n_max, p.x());
        e_min = std::min(e_min, p.y());
        e_max = std::max(e_max, p.y());
      }
  if (!(resolution_m > 0.0) || n_min > n_max) return grid;
  grid.north_min_m = std::floor(n_min / resolution_m) * resolution_m;
  grid.east_min_m = std::floor(e_min / resolution_m) * resolution_m;
  grid.rows = static_cast<int>(std::ceil((n_max - grid.north_min_m) / resolution_m)) + 1;
  grid.cols = static_cast<int>(std::ceil((e_max - grid.east_min_m) / resolution_m)) + 1;
  if (static_cast<double>(grid.rows) * grid.cols > 2e8) {  // a mission tens of km across at 5 m: coarsen
    return computeCoverage(strips, resolution_m * 2.0);
  }
  grid.lines.assign(static_cast<size_t>(grid.rows) * grid.cols, 0);
  std::vector<int> last_line(grid.lines.size(), INT32_MIN);  // a line counts once per cell
  for (const FootprintStrip& s : strips) {
    const size_t n = std::min(s.port_ne_m.size(), s.starboard_ne_m.size());
    for (size_t k = 0; k + 1 < n; ++k) {
      const Eigen::Vector2d quad[4] = {s.port_ne_m[k], s.port_ne_m[k + 1], s.starboard_ne_m[k + 1], s.starboard_ne_m[k]};
      double qn0 = 1e300, qn1 = -1e300, qe0 = 1e300, qe1 = -1e300;
      for (const auto& p : quad) {
        qn0 = std::min(qn0, p.x());
        qn1 = std::max(qn1, p.x());
        qe0 = std::min(qe0, p.y());
        qe1 = std::max(qe1, p.y());
      }
      const int r0 = std::max(0, static_cast<int>(std::floor((qn0 - grid.north_min_m) / resolution_m)));
      const int r1 = std::min(grid.rows - 1, static_cast<int>(std::ceil((qn1 - grid.north_min_m) / resolution_m)));
      const int c0 = std::max(0, static_cast<int>(std::floor((qe0 - grid.east_min_m) / resolution_m)));
      const int c1 = std::min(grid.cols - 1, static_cast<int>(std::ceil((qe1 - grid.east_min_m) / resolution_m)));
      for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c) {
          const Eigen::Vector2d centre(grid.north_min_m + r * resolution_m, grid.east_min_m + c * resolution_m);
          if (!insideConvex(centre, quad)) continue;
          const size_t i = static_cast<size_t>(r) * grid.cols + c;
          if (last_line[i] == s.line_id) continue;
          last_line[i] = s.line_id;
          if (grid.lines[i] < 255) ++grid.lines[i];
        }
    }
  }
  const double cell_m2 = resolution_m * resolution_m;
  for (uint8_t count : grid.lines) {
    if (count >= 1) grid.covered_m2 += cell_m2;
    if (count >= 2) grid.seen_twice_m2 += cell_m2;
  }
  return grid;
}

Status writeCoverageFiles(const std::string& yaml_path, const CoverageGrid& grid,
                          const std::optional<sss::core::MissionOrigin>& origin) {
  if (grid.rows < 1 || grid.cols < 1) {
    return Status::error("coverage " + yaml_path + " has no cells (no subframe)");
  }
  std::string prefix = yaml_path;
  if (prefix.size() > 5 && prefix.compare(prefix.size() - 5, 5, ".yaml") == 0) prefix.resize(prefix.size() - 5);
  const std::string raw_path = prefix + "_lines.u8";
  std::ofstream raw(raw_path, std::ios::binary);
  raw.write(reinterpret_cast<const char*>(grid.lines.data()), static_cast<std::streamsize>(grid.lines.size()));
  if (!raw) {
    return Status::error("cannot write " + raw_path);
  }
  std::ostringstream yaml;
  yaml.precision(12);
  yaml << "# sss-process: how many survey lines saw each cell (SLAM poses, canonical swath)\n"
       << "# Raw uint8, row-major, 0 = not seen. Cell (row, col) lies at north = north_min_m + row *\n"
       << "# resolution_m, east = east_min_m + col * resolution_m (local NED).\n"
       << "rows: " << grid.rows << "\ncols: " << grid.cols << "\nresolution_m: " << grid.resolution_m
       << "\nnorth_min_m: " << grid.north_min_m << "\neast_min_m: " << grid.east_min_m
       << "\nlines_file: " << std::filesystem::path(raw_path).filename().string()
       << "\ncovered_m2: " << grid.covered_m2 << "\nseen_twice_m2: " << grid.seen_twice_m2
       << "\nfraction_seen_twice: " << grid.fractionSeenTwice() << "\n";
  if (origin) yaml << sss::core::originYamlKeys(*origin);
  std::ofstream out(prefix + ".yaml");
  out << yaml.str();
  if (!out) {
    return Status::error("cannot write " + prefix + ".yaml");
  }
  // North up: image row 0 is the northernmost grid row.
  cv::Mat image(grid.rows, grid.cols, CV_8UC3);
  for (int r = 0; r < grid.rows; ++r)
    for (int c = 0; c < grid.cols; ++c) {
      const uint8_t n = grid.lines[static_cast<size_t>(r) * grid.cols + c];
      const cv::Vec3b colour = n == 0 ? cv::Vec3b(0, 0, 0) : n == 1 ? cv::Vec3b(128, 128, 128)
                               : n == 2 ? cv::Vec3b(60, 180, 60) : cv::Vec3b(220, 120, 40);  // BGR
      image.at<cv::Vec3b>(grid.rows - 1 - r, c) = colour;
    }
  if (!cv::imwrite(prefix + ".png", image)) {
    return Status::error("cannot write " + prefix + ".png");
  }
  return Status::success();
}

FrameRaster coverageRaster(const CoverageGrid& grid) {
  FrameRaster raster =
      rasterOverCentredGrid(grid.rows, grid.cols, grid.resolution_m, grid.north_min_m, grid.east_min_m);
  raster.type = RasterType::kByte;
  raster.categorical = true;
  raster.description = "sss-process: survey lines that saw each cell (SLAM poses)";
  for (int row = 0; row < grid.rows; ++row) {
    for (int col = 0; col < grid.cols; ++col) {
      const uint8_t lines = grid.lines[static_cast<size_t>(row) * grid.cols + col];
      if (lines > 0) raster.values[northUpIndex(raster, row, col)] = lines;
    }
  }
  return raster;
}

}  // namespace sss::products
