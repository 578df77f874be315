// Heightmap reading, writing and comparison. See heightmap_metrics.hpp.
#include "tools/eval/heightmap_metrics.hpp"

#include "tools/eval/frame_alignment.hpp"
#include "tools/eval/yaml_file.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace sss::eval {

using sss::core::Status;
namespace {

namespace fs = std::filesystem;

std::string located(const std::string& path, const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  if (mark.line < 0) return path;
  return path + ":" + std::to_string(mark.line + 1);
}

template <typename T>
Status readKey(const std::string& path, const YAML::Node& root, const char* key, const char* type_name, T& value) {
  const YAML::Node node = root[key];
  if (!node) {
    return Status::error(path + ": missing key '" + key +
                         "' (a heightmap YAML has rows, cols, resolution_m, north_min_m, east_min_m, depth_file)");
  }
  try {
    if (!node.IsScalar()) throw YAML::Exception(node.Mark(), "not a scalar");
    value = node.as<T>();
    return Status::success();
  } catch (const YAML::Exception&) {
    std::ostringstream shown;
    shown << node;
    return Status::error(located(path, node) + ": " + key + ": '" + shown.str().substr(0, 60) + "' is not " +
                         type_name);
  }
}

// Grid coordinate with a little slack at the edges so identical grids do not fall off by rounding.
bool bracket(double fractional, int size, int& lower, double& alpha) {
  constexpr double kSlack = 1e-9;
  if (!(fractional >= -kSlack) || !(fractional <= size - 1 + kSlack)) return false;
  if (size == 1) {
    lower = 0;
    alpha = 0.0;
    return true;
  }
  fractional = std::clamp(fractional, 0.0, static_cast<double>(size - 1));
  lower = std::min(static_cast<int>(std::floor(fractional)), size - 2);
  alpha = fractional - lower;
  return true;
}

}  // namespace

std::optional<double> HeightmapRaster::sampleBilinear(double north_m, double east_m) const {
  if (rows <= 0 || cols <= 0 || depth_m.size() != static_cast<size_t>(rows) * cols) return std::nullopt;
  int r0 = 0, c0 = 0;
  double a = 0.0, b = 0.0;
  if (!bracket((north_m - north_min_m) / resolution_m, rows, r0, a)) return std::nullopt;
  if (!bracket((east_m - east_min_m) / resolution_m, cols, c0, b)) return std::nullopt;
  const int r1 = std::min(r0 + 1, rows - 1);
  const int c1 = std::min(c0 + 1, cols - 1);
  // Neighbours with zero weight do not count, so a point on a cell centre needs only that cell.
  const double weights[4] = {(1.0 - a) * (1.0 - b), (1.0 - a) * b, a * (1.0 - b), a * b};
  const float values[4] = {at(r0, c0), at(r0, c1), at(r1, c0), at(r1, c1)};
  double depth = 0.0;
  for (int k = 0; k < 4; ++k) {
    if (weights[k] == 0.0) continue;
    if (!std::isfinite(values[k])) return std::nullopt;
    depth += weights[k] * values[k];
  }
  return depth;
}

Status readHeightmap(const std::string& yaml_path, HeightmapRaster& raster, const HeightmapReadOptions& options) {
  const sss::core::Result<YAML::Node> loaded = loadYamlFile(yaml_path);
  if (!loaded) return loaded.status();
  const YAML::Node& root = *loaded;
  if (!root.IsMap()) {
    return Status::error(yaml_path +
                         ":1: expected a YAML map with rows, cols, resolution_m, north_min_m, east_min_m, depth_file");
  }
  HeightmapRaster result;
  std::string depth_file;
  Status read = readKey(yaml_path, root, "rows", "an integer", result.rows);
  if (read) read = readKey(yaml_path, root, "cols", "an integer", result.cols);
  if (read) read = readKey(yaml_path, root, "resolution_m", "a number", result.resolution_m);
  if (read) read = readKey(yaml_path, root, "north_min_m", "a number", result.north_min_m);
  if (read) read = readKey(yaml_path, root, "east_min_m", "a number", result.east_min_m);
  if (read) read = readKey(yaml_path, root, "depth_file", "a file name", depth_file);
  if (!read) return read;
  if (root["origin_latitude_deg"] || root["origin_longitude_deg"]) {
    sss::core::MissionOrigin origin;
    read = readKey(yaml_path, root, "origin_latitude_deg", "a number", origin.latitude_deg);
    if (read) read = readKey(yaml_path, root, "origin_longitude_deg", "a number", origin.longitude_deg);
    if (!read) return read;
    if (!sss::core::isValidOrigin(origin.latitude_deg, origin.longitude_deg)) {
      return Status::error(located(yaml_path, root["origin_latitude_deg"]) +
                           ": the origin must be a latitude in (-90, 90) and a longitude in [-180, 180] (degrees)");
    }
    result.origin = origin;
  }
  if (result.rows < 1 || result.cols < 1) {
    return Status::error(located(yaml_path, root[result.rows < 1 ? "rows" : "cols"]) + ": rows and cols must be >= 1");
  }
  if (!std::isfinite(result.resolution_m) || result.resolution_m <= 0.0) {
    return Status::error(located(yaml_path, root["resolution_m"]) + ": resolution_m must be a positive number");
  }
  if (!std::isfinite(result.north_min_m) || !std::isfinite(result.east_min_m)) {
    return Status::error(located(yaml_path, root["north_min_m"]) + ": north_min_m and east_min_m must be finite");
  }
  const int64_t cells = static_cast<int64_t>(result.rows) * result.cols;
  if (cells > options.max_cells) {
    return Status::error(located(yaml_path, root["rows"]) + ": " + std::to_string(result.rows) + " x " +
                         std::to_string(result.cols) + " cells exceeds the limit of " +
                         std::to_string(options.max_cells));
  }
  fs::path depth_path(depth_file);
  if (depth_path.is_relative()) depth_path = fs::path(yaml_path).parent_path() / depth_path;
  std::error_code ec;
  const uintmax_t size = fs::file_size(depth_path, ec);
  if (ec) {
    return Status::error(located(yaml_path, root["depth_file"]) + ": depth_file " + depth_path.string() + ": " +
                         ec.message());
  }
  const uintmax_t expected = static_cast<uintmax_t>(cells) * sizeof(float);
  if (size != expected) {
    return Status::error(depth_path.string() + ": " + std::to_string(size) + " bytes, but rows x cols x 4 = " +
                         std::to_string(expected) + " (" + yaml_path + "); the header and the raster do not match");
  }
  result.depth_m.resize(static_cast<size_t>(cells));
  std::ifstream in(depth_path, std::ios::binary);
  in.read(reinterpret_cast<char*>(result.depth_m.data()), static_cast<std::streamsize>(expected));
  if (!in) {
    return Status::error(depth_path.string() + ": read error");
  }
  if (const YAML::Node units = root["depth_units"]; units && units.IsScalar()) result.units = units.Scalar();
  if (options.target_origin && result.origin && !sameOrigin(*result.origin, *options.target_origin)) {
    reexpressHeightmap(result, *result.origin, *options.target_origin);
    result.origin = options.target_origin;
  }
  raster = std::move(result);
  return Status::success();
}

Status writeHeightmap(const std::string& path, const HeightmapRaster& raster) {
  if (raster.rows < 1 || raster.cols < 1 || raster.depth_m.size() != static_cast<size_t>(raster.rows) * raster.cols) {
    return Status::error("writeHeightmap " + path + ": raster has " + std::to_string(raster.depth_m.size()) +
                         " values for " + std::to_string(raster.rows) + " x " + std::to_string(raster.cols) + " cells");
  }
  if (!(raster.resolution_m > 0.0)) {
    return Status::error("writeHeightmap " + path + ": resolution_m must be positive");
  }
  std::string prefix = path;
  for (const char* extension : {".yaml", ".yml"}) {
    const std::string ext(extension);
    if (prefix.size() > ext.size() && prefix.compare(prefix.size() - ext.size(), ext.size(), ext) == 0) {
      prefix.resize(prefix.size() - ext.size());
      break;
    }
  }
  const std::string yaml_path = prefix + ".yaml";
  const std::string depth_path = prefix + "_depth.f32";
  {
    std::ofstream out(depth_path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(raster.depth_m.data()),
              static_cast<std::streamsize>(raster.depth_m.size() * sizeof(float)));
    if (!out) {
      return Status::error("cannot write " + depth_path + "; check the directory exists, is writable and has space");
    }
  }
  std::ostringstream yaml;
  yaml.precision(12);
  std::istringstream description(raster.description.empty() ? std::string("Heightmap") : raster.description);
  for (std::string line; std::getline(description, line);) yaml << "# " << line << "\n";
  yaml << "# Raw little-endian float32, row-major, NaN = no data. Cell (row, col) lies at north =\n"
       << "# north_min_m + row * resolution_m, east = east_min_m + col * resolution_m (local NED).\n"
       << "rows: " << raster.rows << "\ncols: " << raster.cols << "\nresolution_m: " << raster.resolution_m
       << "\nnorth_min_m: " << raster.north_min_m << "\neast_min_m: " << raster.east_min_m
       << "\ndepth_file: " << fs::path(depth_path).filename().string() << "\ndepth_units: \"" << raster.units << "\"\n";
  if (raster.origin) yaml << sss::core::originYamlKeys(*raster.origin);
  std::ofstream out(yaml_path, std::ios::binary);
  out << yaml.str();
  out.close();
  if (!out) {
    return Status::error("cannot write " + yaml_path + "; check the directory exists and is writable");
  }
  return Status::success();
}

HeightmapErrorResult compareHeightmaps(const HeightmapRaster& truth, const HeightmapRaster& estimate) {
  HeightmapErrorResult result;
  if (estimate.depth_m.size() != static_cast<size_t>(estimate.rows) * estimate.cols || estimate.rows < 1 ||
      estimate.cols < 1) {
    result.error = "the estimate heightmap is empty or its size does not match rows x cols";
    return result;
  }
  if (truth.depth_m.size() != static_cast<size_t>(truth.rows) * truth.cols || truth.rows < 1 || truth.cols < 1) {
    result.error = "the true seabed is empty or its size does not match rows x cols";
    return result;
  }
  result.estimate_cells = estimate.depth_m.size();
  HeightmapRaster& map = result.error_map;
  map.rows = estimate.rows;
  map.cols = estimate.cols;
  map.resolution_m = estimate.resolution_m;
  map.north_min_m = estimate.north_min_m;
  map.east_min_m = estimate.east_min_m;
  map.depth_m.assign(estimate.depth_m.size(), std::numeric_limits<float>::quiet_NaN());
  map.description = "Heightmap error: estimate depth - true depth (positive: estimate deeper)";
  map.units = "metres (estimate - truth, positive = estimate deeper)";
  std::vector<double> abs_errors;
  double signed_sum = 0.0;
  for (int r = 0; r < estimate.rows; ++r) {
    for (int c = 0; c < estimate.cols; ++c) {
      const float value = estimate.at(r, c);
      if (!std::isfinite(value)) continue;
      ++result.cells_with_data;
      const std::optional<double> true_depth = truth.sampleBilinear(estimate.northM(r), estimate.eastM(c));
      if (!true_depth) continue;
      const double e = value - *true_depth;
      map.at(r, c) = static_cast<float>(e);
      abs_errors.push_back(std::abs(e));
      signed_sum += e;
    }
  }
  result.compared_cells = abs_errors.size();
  result.coverage_fraction = static_cast<double>(result.cells_with_data) / static_cast<double>(result.estimate_cells);
  result.covered_area_m2 = static_cast<double>(result.cells_with_data) * estimate.resolution_m * estimate.resolution_m;
  if (!abs_errors.empty()) result.mean_signed_error_m = signed_sum / static_cast<double>(abs_errors.size());
  result.abs_error_m = errorStatistics(std::move(abs_errors));
  if (result.compared_cells == 0) {
    result.error = result.cells_with_data == 0 ? "the estimate heightmap has no data (all NaN)"
                                               : "no estimate cell with data lies on the true seabed; check both use "
                                                 "the same local NED origin";
    return result;
  }
  result.ok = true;
  return result;
}

}  // namespace sss::eval
