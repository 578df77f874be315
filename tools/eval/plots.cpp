// The heightmap error map PNG drawn with OpenCV (the report's charts are drawn by
// report_figures.py) and the simulator's 8-bit mosaic reader. See plots.hpp.
#include "tools/eval/plots.hpp"
#include "tools/eval/yaml_file.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

namespace sss::eval {

using sss::core::Status;
namespace {

const cv::Scalar kBlack(0, 0, 0);
const cv::Scalar kAxis(90, 90, 90);
const cv::Scalar kWhite(255, 255, 255);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kFontScale = 0.5;
constexpr double kTitleScale = 0.65;

// Diverging blue - white - red (ColorBrewer RdBu reversed), v in [-1, 1]; BGR.
cv::Vec3b divergingColour(double v) {
  static const std::array<std::array<double, 3>, 5> kStops = {{
      {5, 48, 97}, {67, 147, 195}, {247, 247, 247}, {214, 96, 77}, {103, 0, 31}}};  // RGB at -1, -.5, 0, .5, 1
  const double x = (std::clamp(v, -1.0, 1.0) + 1.0) * 2.0;  // [0, 4]
  const int k = std::min(static_cast<int>(x), 3);
  const double a = x - k;
  cv::Vec3b bgr;
  for (int c = 0; c < 3; ++c) {
    const double value = (1.0 - a) * kStops[k][c] + a * kStops[k + 1][c];
    bgr[2 - c] = static_cast<uint8_t>(std::lround(value));
  }
  return bgr;
}

std::string formatTick(double value, double step) {
  char text[32];
  const int decimals = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  std::snprintf(text, sizeof text, "%.*f", std::clamp(decimals, 0, 6), std::abs(value) < 1e-12 * step ? 0.0 : value);
  return text;
}

std::vector<double> ticks(double min, double max, int target, double& step) {
  step = niceCeil((max - min) / std::max(1, target));
  std::vector<double> values;
  if (!(step > 0.0) || !std::isfinite(step)) return values;
  // Counted, not accumulated: a step below the coordinates' resolution cannot loop forever.
  const double first = std::ceil(min / step - 1e-9);
  for (int k = 0; k < 100; ++k) {
    const double t = (first + k) * step;
    if (t > max + 1e-9 * step) break;
    values.push_back(t);
  }
  return values;
}

void putText(cv::Mat& image, const std::string& text, cv::Point at, double scale = kFontScale,
             const cv::Scalar& colour = kBlack, int thickness = 1) {
  cv::putText(image, text, at, kFont, scale, colour, thickness, cv::LINE_AA);
}

cv::Size textSize(const std::string& text, double scale = kFontScale, int thickness = 1) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, scale, thickness, &baseline);
}

Status savePng(const std::string& path, const cv::Mat& image) {
  try {
    if (cv::imwrite(path, image)) return Status::success();
    return Status::error("cannot write " + path + "; check the directory exists and the name ends in .png");
  } catch (const cv::Exception& e) {
    return Status::error("cannot write " + path + ": " + e.what());
  }
}

}  // namespace

double niceCeil(double value) {
  if (!(value > 0.0) || !std::isfinite(value)) return 1.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(value)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * magnitude >= value * (1.0 - 1e-12)) return m * magnitude;
  }
  return 10.0 * magnitude;
}

Status writeErrorMapPng(const std::string& path, const HeightmapRaster& map, const std::string& title,
                        const ErrorMapPngOptions& options, double* used_limit_m) {
  if (map.rows < 1 || map.cols < 1 || map.depth_m.size() != static_cast<size_t>(map.rows) * map.cols) {
    return Status::error("error map " + path + ": empty raster");
  }
  // Scale: symmetric, from the 99th percentile of |error| unless given.
  double limit = options.limit_m;
  if (!(limit > 0.0)) {
    std::vector<float> magnitudes;
    for (float v : map.depth_m) {
      if (std::isfinite(v)) magnitudes.push_back(std::abs(v));
    }
    double p99 = 0.0;
    if (!magnitudes.empty()) {
      const size_t k = std::min(magnitudes.size() - 1, static_cast<size_t>(0.99 * magnitudes.size()));
      std::nth_element(magnitudes.begin(), magnitudes.begin() + k, magnitudes.end());
      p99 = magnitudes[k];
    }
    limit = niceCeil(std::max(p99, 1e-3));
  }
  if (used_limit_m) *used_limit_m = limit;

  // Block-average down to max_size_px; small rasters are enlarged (nearest) to about 700 px.
  const int largest = std::max(map.rows, map.cols);
  const int block = std::max(1, (largest + options.max_size_px - 1) / std::max(1, options.max_size_px));
  const int rows = (map.rows + block - 1) / block, cols = (map.cols + block - 1) / block;
  cv::Mat raster(rows, cols, CV_8UC3);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      double sum = 0.0;
      int count = 0;
      for (int dr = 0; dr < block; ++dr) {
        for (int dc = 0; dc < block; ++dc) {
          const int rr = r * block + dr, cc = c * block + dc;
          if (rr >= map.rows || cc >= map.cols) continue;
          const float v = map.at(rr, cc);
          if (!std::isfinite(v)) continue;
          sum += v;
          ++count;
        }
      }
      raster.at<cv::Vec3b>(rows - 1 - r, c) = count == 0 ? cv::Vec3b(190, 190, 190) : divergingColour(sum / count / limit);
    }
  }
  const double zoom = std::max(1.0, 700.0 / std::max(rows, cols));
  if (zoom > 1.0) {
    cv::resize(raster, raster, cv::Size(static_cast<int>(std::lround(cols * zoom)), static_cast<int>(std::lround(rows * zoom))),
               0, 0, cv::INTER_NEAREST);
  }
  const double px_per_cell = static_cast<double>(raster.cols) / (cols * block);  // per original cell
  const double metres_per_px = map.resolution_m / px_per_cell;

  const int left = 90, right = 40, top = 88, below_map = 50, bar_height = 16;
  const int width = std::max(raster.cols + left + right, 820);
  const int bar_y = top + raster.rows + below_map;
  cv::Mat image(bar_y + bar_height + 70, width, CV_8UC3, kWhite);
  raster.copyTo(image(cv::Rect(left, top, raster.cols, raster.rows)));
  const cv::Rect frame(left - 1, top - 1, raster.cols + 2, raster.rows + 2);

  // Metre ticks: north on the left, east below, at cell centres' coordinates.
  double step = 0.0;
  const double north_max = map.northM(map.rows - 1), east_max = map.eastM(map.cols - 1);
  for (double n : ticks(map.north_min_m, north_max, 6, step)) {
    const int y = static_cast<int>(std::lround(top + raster.rows - ((n - map.north_min_m) / map.resolution_m + 0.5) * px_per_cell));
    if (y < top || y > top + raster.rows) continue;
    cv::line(image, cv::Point(left - 6, y), cv::Point(left - 1, y), kAxis, 1);
    const std::string label = formatTick(n, step);
    putText(image, label, cv::Point(left - 10 - textSize(label).width, y + 5));
  }
  for (double e : ticks(map.east_min_m, east_max, 6, step)) {
    const int x = static_cast<int>(std::lround(left + ((e - map.east_min_m) / map.resolution_m + 0.5) * px_per_cell));
    if (x < left || x > left + raster.cols) continue;
    cv::line(image, cv::Point(x, top + raster.rows), cv::Point(x, top + raster.rows + 5), kAxis, 1);
    const std::string label = formatTick(e, step);
    putText(image, label, cv::Point(x - textSize(label).width / 2, top + raster.rows + 20));
  }
  cv::rectangle(image, frame, kAxis, 1);
  putText(image, "east (m)", cv::Point(left + raster.cols / 2 - textSize("east (m)").width / 2, top + raster.rows + 40));
  putText(image, "north (m)", cv::Point(8, top - 10));
  putText(image, title, cv::Point(16, 28), kTitleScale);
  char note[160];
  std::snprintf(note, sizeof note, "north up, 1 px = %.3g m; colour scale +-%.3g m", metres_per_px, limit);
  putText(image, note, cv::Point(16, 52), kFontScale, kAxis);

  // Colour bar with ticks at -limit, -limit/2, 0, limit/2, limit.
  const int bar_width = std::min(width - 120, 520);
  const int bar_x = (width - bar_width) / 2;
  for (int x = 0; x < bar_width; ++x) {
    const cv::Vec3b colour = divergingColour(2.0 * x / (bar_width - 1) - 1.0);
    cv::line(image, cv::Point(bar_x + x, bar_y), cv::Point(bar_x + x, bar_y + bar_height), cv::Scalar(colour[0], colour[1], colour[2]));
  }
  cv::rectangle(image, cv::Rect(bar_x, bar_y, bar_width, bar_height + 1), kAxis, 1);
  for (int k = 0; k <= 4; ++k) {
    const double value = limit * (k - 2) / 2.0;
    const int x = bar_x + (bar_width - 1) * k / 4;
    cv::line(image, cv::Point(x, bar_y + bar_height), cv::Point(x, bar_y + bar_height + 5), kAxis, 1);
    char label[32];
    std::snprintf(label, sizeof label, "%+.3g m", value);
    if (k == 2) std::snprintf(label, sizeof label, "0");
    putText(image, label, cv::Point(x - textSize(label).width / 2, bar_y + bar_height + 20));
  }
  const std::string legend = "estimate - true depth: red = estimate deeper, blue = shallower, grey = no data";
  putText(image, legend, cv::Point(width / 2 - textSize(legend).width / 2, bar_y + bar_height + 46), kFontScale, kAxis);
  return savePng(path, image);
}

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
