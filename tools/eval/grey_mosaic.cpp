// The simulator's 8-bit grey mosaic (mosaic.yaml + mosaic.png), see grey_mosaic.hpp.
#include "tools/eval/grey_mosaic.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>

#include "tools/eval/yaml_file.hpp"

namespace sss::eval {

using sss::core::Status;

Status readMosaic(const std::string& yaml_path, GreyMosaic& mosaic) {
  const sss::core::Result<YAML::Node> loaded = loadYamlFile(yaml_path);
  if (!loaded) return loaded.status();
  const YAML::Node& root = *loaded;
  GreyMosaic result;
  try {
    if (!root.IsMap()) throw YAML::Exception(root.Mark(), "not a map");
    for (const char* key : {"resolution_m", "north_max_m", "east_min_m", "rows", "cols"}) {
      if (!root[key]) {
        return Status::error(yaml_path + ": missing key '" + key +
                             "' (a mosaic YAML has resolution_m, north_max_m, east_min_m, rows, cols)");
      }
    }
    result.resolution_m = root["resolution_m"].as<double>();
    result.north_max_m = root["north_max_m"].as<double>();
    result.east_min_m = root["east_min_m"].as<double>();
    result.rows = root["rows"].as<int>();
    result.cols = root["cols"].as<int>();
  } catch (const YAML::Exception& e) {
    return Status::error(yaml_path + ":" + std::to_string(e.mark.line + 1) +
                         ": expected numbers for resolution_m, north_max_m, east_min_m and integers for rows, cols");
  }
  if (!(result.resolution_m > 0.0) || !std::isfinite(result.resolution_m) || !std::isfinite(result.north_max_m) ||
      !std::isfinite(result.east_min_m) || result.rows < 1 || result.cols < 1) {
    return Status::error(yaml_path + ": resolution_m must be positive, the corners finite and rows, cols >= 1");
  }
  std::filesystem::path png(yaml_path);
  png.replace_extension(".png");
  cv::Mat image;
  try {
    image = cv::imread(png.string(), cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {
    return Status::error(png.string() + ": cannot decode: " + e.what());
  }
  if (image.empty()) {
    return Status::error(png.string() + ": missing or not a PNG (the image of " + yaml_path + ")");
  }
  if (image.rows != result.rows || image.cols != result.cols) {
    return Status::error(png.string() + ": " + std::to_string(image.cols) + " x " + std::to_string(image.rows) +
                         " pixels, but " + yaml_path + " says cols " + std::to_string(result.cols) + ", rows " +
                         std::to_string(result.rows));
  }
  if (!image.isContinuous()) image = image.clone();
  result.pixels.assign(image.ptr<uint8_t>(0), image.ptr<uint8_t>(0) + static_cast<size_t>(image.rows) * image.cols);
  mosaic = std::move(result);
  return Status::success();
}

}  // namespace sss::eval
