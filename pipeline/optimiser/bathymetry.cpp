// Seabed points from two slant ranges and two fan planes, their heightmap and files. See bathymetry.hpp.
#include "pipeline/optimiser/bathymetry.hpp"

#include <Eigen/Dense>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

namespace sss::optimiser {

using sss::core::Status;

namespace {
// Residual weights of the fit: slant ranges are known to a few centimetres (bin size), the fan
// plane only to the horizontal beam width times the range (~0.4 m at 50 m for 0.5 deg).
constexpr double kRangeSigmaM = 0.05;
constexpr double kPlaneSigmaM = 0.3;
}  // namespace

void readBathymetryOptions(sss::core::ConfigSection& section, BathymetryOptions& options) {
  using sss::core::greaterThan;
  using sss::core::inRange;
  section.optional("max_range_residual_m", options.max_range_residual_m, {greaterThan(0.0)});
  section.optional("max_plane_residual_m", options.max_plane_residual_m, {greaterThan(0.0)});
  section.optional("min_intersection_angle_rad", options.min_intersection_angle_rad, {inRange(0.0, 1.5)});
  section.optional("max_points_per_closure", options.max_points_per_closure, {inRange(1, 1000000)});
  section.optional("max_iterations", options.max_iterations, {inRange(1, 100)});
  section.optional("heightmap_resolution_m", options.heightmap_resolution_m, {inRange(0.1, 100.0)});
  section.optional("min_points_per_cell", options.min_points_per_cell, {inRange(1, 10000)});
}

std::vector<std::string> validateBathymetryOptions(const BathymetryOptions& options) {
  std::vector<std::string> errors;
  if (!(options.max_range_residual_m > 0.0)) errors.push_back("max_range_residual_m must be positive");
  if (!(options.max_plane_residual_m > 0.0)) errors.push_back("max_plane_residual_m must be positive");
  if (!(options.heightmap_resolution_m > 0.0)) errors.push_back("heightmap_resolution_m must be positive");
  if (options.max_points_per_closure < 1) errors.push_back("max_points_per_closure must be >= 1");
  if (options.max_iterations < 1) errors.push_back("max_iterations must be >= 1");
  if (options.min_points_per_cell < 1) errors.push_back("min_points_per_cell must be >= 1");
  return errors;
}

std::optional<SeabedPoint> triangulateSeabedPoint(const SonarObservation& a, const SonarObservation& b,
                                                  const Eigen::Vector3d& initial_ned_m,
                                                  const BathymetryOptions& options) {
  const SonarObservation* observations[2] = {&a, &b};
  Eigen::Vector3d p = initial_ned_m;
  if (!p.allFinite()) return std::nullopt;
  bool converged = false;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
    for (const SonarObservation* o : observations) {
      const Eigen::Vector3d origin = o->T_world_sonar.translation;
      const Eigen::Vector3d fan_normal = o->T_world_sonar.rotation * Eigen::Vector3d::UnitX();
      const Eigen::Vector3d offset = p - origin;
      const double distance = offset.norm();
      if (!(distance > 1e-3)) return std::nullopt;
      // Range residual and its Jacobian (unit direction), then the plane residual (fan normal).
      const Eigen::Vector3d j_range = offset / distance / kRangeSigmaM;
      const double r_range = (distance - o->slant_range_m) / kRangeSigmaM;
      const Eigen::Vector3d j_plane = fan_normal / kPlaneSigmaM;
      const double r_plane = fan_normal.dot(offset) / kPlaneSigmaM;
      normal += j_range * j_range.transpose() + j_plane * j_plane.transpose();
      gradient += j_range * r_range + j_plane * r_plane;
    }
    const Eigen::LDLT<Eigen::Matrix3d> solver(normal);
    if (solver.info() != Eigen::Success || !(solver.vectorD().minCoeff() > 1e-9)) return std::nullopt;
    const Eigen::Vector3d step = -solver.solve(gradient);
    if (!step.allFinite()) return std::nullopt;
    p += step;
    if (step.norm() < 1e-4) {
      converged = true;
      break;
    }
  }
  if (!converged) return std::nullopt;

  SeabedPoint point;
  point.position_ned_m = p;
  double range_residual = 0.0, plane_residual = 0.0;
  Eigen::Vector3d directions[2];
  for (int i = 0; i < 2; ++i) {
    const SonarObservation* o = observations[i];
    const Eigen::Vector3d offset = p - o->T_world_sonar.translation;
    range_residual = std::max(range_residual, std::abs(offset.norm() - o->slant_range_m));
    plane_residual =
        std::max(plane_residual, std::abs((o->T_world_sonar.rotation * Eigen::Vector3d::UnitX()).dot(offset)));
    directions[i] = offset.normalized();
  }
  const double angle = std::acos(std::clamp(directions[0].dot(directions[1]), -1.0, 1.0));
  if (range_residual > options.max_range_residual_m || plane_residual > options.max_plane_residual_m ||
      angle < options.min_intersection_angle_rad) {
    return std::nullopt;
  }
  point.range_residual_m = static_cast<float>(range_residual);
  point.plane_residual_m = static_cast<float>(plane_residual);
  return point;
}

HeightmapGrid gridSeabedPoints(const std::vector<SeabedPoint>& points, const BathymetryOptions& options) {
  HeightmapGrid grid;
  grid.resolution_m = options.heightmap_resolution_m;
  if (points.empty()) return grid;
  double north_min = std::numeric_limits<double>::infinity(), north_max = -north_min;
  double east_min = north_min, east_max = -north_min;
  for (const SeabedPoint& point : points) {
    north_min = std::min(north_min, point.position_ned_m.x());
    north_max = std::max(north_max, point.position_ned_m.x());
    east_min = std::min(east_min, point.position_ned_m.y());
    east_max = std::max(east_max, point.position_ned_m.y());
  }
  const double res = grid.resolution_m;
  // Cell centres on multiples of the resolution so maps of the same mission line up.
  grid.north_min_m = std::floor(north_min / res) * res;
  grid.east_min_m = std::floor(east_min / res) * res;
  grid.rows = static_cast<int>(std::ceil((north_max - grid.north_min_m) / res)) + 1;
  grid.cols = static_cast<int>(std::ceil((east_max - grid.east_min_m) / res)) + 1;
  std::map<size_t, std::vector<float>> depths_by_cell;
  for (const SeabedPoint& point : points) {
    const int row = static_cast<int>(std::lround((point.position_ned_m.x() - grid.north_min_m) / res));
    const int col = static_cast<int>(std::lround((point.position_ned_m.y() - grid.east_min_m) / res));
    if (row < 0 || col < 0 || row >= grid.rows || col >= grid.cols) continue;
    depths_by_cell[static_cast<size_t>(row) * grid.cols + col].push_back(static_cast<float>(point.position_ned_m.z()));
  }
  const size_t cells = static_cast<size_t>(grid.rows) * grid.cols;
  grid.depth_m.assign(cells, std::numeric_limits<float>::quiet_NaN());
  grid.points.assign(cells, 0);
  for (auto& [cell, depths] : depths_by_cell) {
    grid.points[cell] = static_cast<uint16_t>(std::min<size_t>(depths.size(), 65535));
    if (static_cast<int>(depths.size()) < options.min_points_per_cell) continue;
    auto middle = depths.begin() + static_cast<std::ptrdiff_t>(depths.size() / 2);
    std::nth_element(depths.begin(), middle, depths.end());
    grid.depth_m[cell] = *middle;
  }
  return grid;
}

namespace {

std::string stripYamlExtension(const std::string& path) {
  for (const std::string extension : {".yaml", ".yml"}) {
    if (path.size() > extension.size() && path.compare(path.size() - extension.size(), extension.size(), extension) == 0) {
      return path.substr(0, path.size() - extension.size());
    }
  }
  return path;
}

// Depth as colour (turbo, shallow blue .. deep red), north up, no data dark grey, with a colour
// bar and its depth range written below.
Status writeHeightmapPng(const std::string& path, const HeightmapGrid& grid) {
  float shallow = std::numeric_limits<float>::infinity(), deep = -shallow;
  for (float d : grid.depth_m) {
    if (!std::isfinite(d)) continue;
    shallow = std::min(shallow, d);
    deep = std::max(deep, d);
  }
  if (!std::isfinite(shallow)) {
    shallow = 0.0f;
    deep = 1.0f;
  }
  const float span = std::max(deep - shallow, 1e-3f);
  // Upscale small grids so the picture is readable; at most ~1200 px on the long side.
  const int scale = std::max(1, std::min(8, 1200 / std::max(grid.rows, grid.cols)));
  cv::Mat grey(grid.rows, grid.cols, CV_8UC1);
  cv::Mat valid(grid.rows, grid.cols, CV_8UC1);
  for (int row = 0; row < grid.rows; ++row) {
    for (int col = 0; col < grid.cols; ++col) {
      const float d = grid.depth_m[static_cast<size_t>(row) * grid.cols + col];
      const int image_row = grid.rows - 1 - row;  // north up
      grey.at<uint8_t>(image_row, col) =
          std::isfinite(d) ? static_cast<uint8_t>(std::clamp((d - shallow) / span * 255.0f, 0.0f, 255.0f)) : 0;
      valid.at<uint8_t>(image_row, col) = std::isfinite(d) ? 255 : 0;
    }
  }
  cv::Mat colour;
  cv::applyColorMap(grey, colour, cv::COLORMAP_TURBO);
  colour.setTo(cv::Scalar(60, 60, 60), valid == 0);
  cv::resize(colour, colour, cv::Size(), scale, scale, cv::INTER_NEAREST);
  const int bar_height = 50;
  cv::Mat canvas(colour.rows + bar_height, std::max(colour.cols, 360), CV_8UC3, cv::Scalar(255, 255, 255));
  colour.copyTo(canvas(cv::Rect(0, 0, colour.cols, colour.rows)));
  const int bar_width = canvas.cols - 20;
  for (int x = 0; x < bar_width; ++x) {
    cv::Mat level(1, 1, CV_8UC1, cv::Scalar(x * 255 / std::max(bar_width - 1, 1)));
    cv::Mat level_colour;
    cv::applyColorMap(level, level_colour, cv::COLORMAP_TURBO);
    const cv::Vec3b c = level_colour.at<cv::Vec3b>(0, 0);
    cv::line(canvas, {10 + x, colour.rows + 5}, {10 + x, colour.rows + 20}, cv::Scalar(c[0], c[1], c[2]));
  }
  char label[160];
  std::snprintf(label, sizeof(label), "depth %.1f m (blue) .. %.1f m (red), cells %.1f m, north up", shallow, deep,
                grid.resolution_m);
  cv::putText(canvas, label, {10, colour.rows + 40}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  try {
    if (!cv::imwrite(path, canvas)) {
      return Status::error("cannot write " + path);
    }
  } catch (const cv::Exception& e) {
    return Status::error("cannot write " + path + ": " + e.what());
  }
  return Status::success();
}

}  // namespace

Status writeHeightmapFiles(const std::string& yaml_path, const HeightmapGrid& grid, const std::string& description,
                           const std::optional<sss::core::MissionOrigin>& origin) {
  if (grid.rows < 1 || grid.cols < 1 || grid.depth_m.size() != static_cast<size_t>(grid.rows) * grid.cols) {
    return Status::error("heightmap " + yaml_path + " has no cells (no seabed points)");
  }
  const std::string prefix = stripYamlExtension(yaml_path);
  const std::string depth_path = prefix + "_depth.f32";
  std::ofstream depth(depth_path, std::ios::binary);
  depth.write(reinterpret_cast<const char*>(grid.depth_m.data()),
              static_cast<std::streamsize>(grid.depth_m.size() * sizeof(float)));
  if (!depth) {
    return Status::error("cannot write " + depth_path);
  }
  std::ostringstream yaml;
  yaml.precision(12);
  yaml << "# " << description << "\n"
       << "# Raw little-endian float32, row-major, NaN = no data. Cell (row, col) lies at north =\n"
       << "# north_min_m + row * resolution_m, east = east_min_m + col * resolution_m (local NED).\n"
       << "rows: " << grid.rows << "\ncols: " << grid.cols << "\nresolution_m: " << grid.resolution_m
       << "\nnorth_min_m: " << grid.north_min_m << "\neast_min_m: " << grid.east_min_m
       << "\ndepth_file: " << std::filesystem::path(depth_path).filename().string()
       << "\ndepth_units: \"metres below the origin (NED z, positive down)\"\n";
  if (origin) yaml << sss::core::originYamlKeys(*origin);
  std::ofstream out(prefix + ".yaml");
  out << yaml.str();
  if (!out) {
    return Status::error("cannot write " + prefix + ".yaml");
  }
  return writeHeightmapPng(prefix + ".png", grid);
}

Status writeSeabedPly(const std::string& path, const std::vector<SeabedPoint>& points,
                      const std::optional<sss::core::MissionOrigin>& origin) {
  std::ofstream out(path, std::ios::binary);
  out << "ply\nformat binary_little_endian 1.0\n"
      << "comment sss-slam quasi-dense bathymetry: x north, y east, z down (m, local NED of the mission origin)\n";
  // The origin's line without its '#': PLY comments take one line of text.
  if (origin) out << "comment" << sss::core::originCommentLine(*origin).substr(1) << "\n";
  out << "element vertex " << points.size() << "\n"
      << "property double x\nproperty double y\nproperty double z\n"
      << "property float range_residual\nproperty float plane_residual\nend_header\n";
  for (const SeabedPoint& point : points) {
    const double xyz[3] = {point.position_ned_m.x(), point.position_ned_m.y(), point.position_ned_m.z()};
    out.write(reinterpret_cast<const char*>(xyz), sizeof(xyz));
    out.write(reinterpret_cast<const char*>(&point.range_residual_m), sizeof(float));
    out.write(reinterpret_cast<const char*>(&point.plane_residual_m), sizeof(float));
  }
  if (!out) {
    return Status::error("cannot write " + path);
  }
  return Status::success();
}

}  // namespace sss::optimiser
