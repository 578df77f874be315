// OpenCV drawing of the evaluation figures. See plots.hpp.
#include "tools/eval/plots.hpp"

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
namespace {

const cv::Scalar kBlack(0, 0, 0);
const cv::Scalar kGrid(225, 225, 225);
const cv::Scalar kAxis(90, 90, 90);
const cv::Scalar kWhite(255, 255, 255);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kFontScale = 0.5;
constexpr double kTitleScale = 0.65;

// Tableau 10 in BGR.
cv::Scalar paletteColour(int index) {
  static const std::array<cv::Scalar, 10> kPalette = {
      cv::Scalar(180, 119, 31), cv::Scalar(14, 127, 255), cv::Scalar(44, 160, 44),  cv::Scalar(40, 39, 214),
      cv::Scalar(189, 103, 148), cv::Scalar(75, 86, 140), cv::Scalar(194, 119, 227), cv::Scalar(127, 127, 127),
      cv::Scalar(34, 189, 188),  cv::Scalar(207, 190, 23)};
  return kPalette[static_cast<size_t>(std::abs(index)) % kPalette.size()];
}

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

void drawPolyline(cv::Mat& image, const std::vector<cv::Point2d>& points, const cv::Scalar& colour, int thickness,
                  bool dashed) {
  if (points.size() < 2) return;
  constexpr int kShift = 4;  // sub-pixel precision for anti-aliased lines
  const auto fixed = [](const cv::Point2d& p) {
    return cv::Point(static_cast<int>(std::lround(p.x * (1 << kShift))), static_cast<int>(std::lround(p.y * (1 << kShift))));
  };
  if (!dashed) {
    std::vector<cv::Point> fixed_points;
    fixed_points.reserve(points.size());
    for (const cv::Point2d& p : points) fixed_points.push_back(fixed(p));
    cv::polylines(image, fixed_points, false, colour, thickness, cv::LINE_AA, kShift);
    return;
  }
  // Dashes of 8 px with 6 px gaps along the path length.
  constexpr double kDash = 8.0, kPeriod = 14.0;
  double phase = 0.0;
  for (size_t i = 1; i < points.size(); ++i) {
    const cv::Point2d a = points[i - 1], b = points[i];
    const double length = cv::norm(b - a);
    double s = 0.0;
    while (s < length) {
      const double in_period = std::fmod(phase + s, kPeriod);
      const double piece = in_period < kDash ? std::min(kDash - in_period, length - s) : std::min(kPeriod - in_period, length - s);
      if (in_period < kDash && length > 0.0) {
        cv::line(image, fixed(a + (b - a) * (s / length)), fixed(a + (b - a) * ((s + piece) / length)), colour, thickness,
                 cv::LINE_AA, kShift);
      }
      s += std::max(piece, 1e-3);
    }
    phase += length;
  }
}

struct LegendEntry {
  std::string label;
  cv::Scalar colour;
  int thickness = 2;
  bool dashed = false;
};

// The box placed 8 px inside one corner of area: the corner with the fewest points under it.
cv::Rect emptiestCorner(const cv::Rect& area, const cv::Size& box, const std::vector<cv::Point2d>& points) {
  const std::array<cv::Point, 4> corners = {
      cv::Point(area.x + 8, area.y + 8), cv::Point(area.x + area.width - box.width - 8, area.y + 8),
      cv::Point(area.x + 8, area.y + area.height - box.height - 8),
      cv::Point(area.x + area.width - box.width - 8, area.y + area.height - box.height - 8)};
  size_t best = 0, best_count = SIZE_MAX;
  for (size_t k = 0; k < corners.size(); ++k) {
    const cv::Rect rect(corners[k], box);
    size_t count = 0;
    for (const cv::Point2d& p : points) count += rect.contains(cv::Point(static_cast<int>(p.x), static_cast<int>(p.y)));
    if (count < best_count) {
      best_count = count;
      best = k;
    }
  }
  return cv::Rect(corners[best], box);
}

// Legend box in the corner of `area` with the fewest data points under it.
void drawLegend(cv::Mat& image, const cv::Rect& area, const std::vector<LegendEntry>& entries,
                const std::vector<cv::Point2d>& data_points) {
  if (entries.empty()) return;
  int width = 0;
  for (const LegendEntry& e : entries) width = std::max(width, textSize(e.label).width);
  const int line_height = 20;
  const cv::Size box(width + 54, static_cast<int>(entries.size()) * line_height + 10);
  const cv::Rect rect = emptiestCorner(area, box, data_points);
  cv::rectangle(image, rect, kWhite, cv::FILLED);
  cv::rectangle(image, rect, kAxis, 1);
  for (size_t i = 0; i < entries.size(); ++i) {
    const int y = rect.y + 15 + static_cast<int>(i) * line_height;
    drawPolyline(image, {cv::Point2d(rect.x + 8, y - 4), cv::Point2d(rect.x + 40, y - 4)}, entries[i].colour,
                 entries[i].thickness, entries[i].dashed);
    putText(image, entries[i].label, cv::Point(rect.x + 46, y));
  }
}

bool savePng(const std::string& path, const cv::Mat& image, std::string& error) {
  try {
    if (cv::imwrite(path, image)) return true;
    error = "cannot write " + path + "; check the directory exists and the name ends in .png";
  } catch (const cv::Exception& e) {
    error = "cannot write " + path + ": " + e.what();
  }
  return false;
}

// Axis frame, grid and tick labels of a plot area whose data range is [x0, x1] x [y0, y1].
void drawAxes(cv::Mat& image, const cv::Rect& area, double x0, double x1, double y0, double y1,
              const std::string& x_label, const std::string& y_label) {
  const auto px = [&](double x) { return area.x + (x - x0) / (x1 - x0) * area.width; };
  const auto py = [&](double y) { return area.y + area.height - (y - y0) / (y1 - y0) * area.height; };
  double step = 0.0;
  for (double t : ticks(x0, x1, 8, step)) {
    const int x = static_cast<int>(std::lround(px(t)));
    cv::line(image, cv::Point(x, area.y), cv::Point(x, area.y + area.height), kGrid, 1);
    const std::string label = formatTick(t, step);
    putText(image, label, cv::Point(x - textSize(label).width / 2, area.y + area.height + 18));
  }
  for (double t : ticks(y0, y1, 8, step)) {
    const int y = static_cast<int>(std::lround(py(t)));
    cv::line(image, cv::Point(area.x, y), cv::Point(area.x + area.width, y), kGrid, 1);
    const std::string label = formatTick(t, step);
    putText(image, label, cv::Point(area.x - 8 - textSize(label).width, y + 5));
  }
  cv::rectangle(image, area, kAxis, 1);
  putText(image, x_label, cv::Point(area.x + area.width / 2 - textSize(x_label).width / 2, area.y + area.height + 42));
  // Vertical axis label, rotated.
  const cv::Size size = textSize(y_label);
  cv::Mat label(size.height + 8, size.width + 4, CV_8UC3, kWhite);
  putText(label, y_label, cv::Point(2, size.height + 2));
  cv::Mat rotated;
  cv::rotate(label, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
  const int x = 8;
  const int y = std::max(0, area.y + area.height / 2 - rotated.rows / 2);
  if (x + rotated.cols <= image.cols && y + rotated.rows <= image.rows) rotated.copyTo(image(cv::Rect(x, y, rotated.cols, rotated.rows)));
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

bool writeTrajectoryPlot(const std::string& path, const PlotTrajectory& truth, const std::vector<PlotTrajectory>& estimates,
                         const std::string& title, std::string& error) {
  const cv::Size canvas(1200, 1000);
  const cv::Rect area(90, 50, canvas.width - 90 - 30, canvas.height - 50 - 70);
  double min_n = 1e300, max_n = -1e300, min_e = 1e300, max_e = -1e300;
  const auto extend = [&](const PlotTrajectory& t) {
    for (const Eigen::Vector2d& p : t.north_east_m) {
      if (!p.allFinite()) continue;
      min_n = std::min(min_n, p.x());
      max_n = std::max(max_n, p.x());
      min_e = std::min(min_e, p.y());
      max_e = std::max(max_e, p.y());
    }
  };
  extend(truth);
  for (const PlotTrajectory& e : estimates) extend(e);
  if (min_n > max_n) {
    error = "trajectory plot " + path + ": nothing to draw";
    return false;
  }
  // Equal axes: one metre is the same number of pixels both ways, the data centred, 5% margin.
  const double span_n = std::max(max_n - min_n, 1.0) * 1.1;
  const double span_e = std::max(max_e - min_e, 1.0) * 1.1;
  const double scale = std::min(area.width / span_e, area.height / span_n);
  const double centre_n = 0.5 * (min_n + max_n), centre_e = 0.5 * (min_e + max_e);
  const double e0 = centre_e - 0.5 * area.width / scale, e1 = centre_e + 0.5 * area.width / scale;
  const double n0 = centre_n - 0.5 * area.height / scale, n1 = centre_n + 0.5 * area.height / scale;
  const auto pixel = [&](const Eigen::Vector2d& p) {
    return cv::Point2d(area.x + (p.y() - e0) * scale, area.y + area.height - (p.x() - n0) * scale);
  };

  cv::Mat image(canvas, CV_8UC3, kWhite);
  drawAxes(image, area, e0, e1, n0, n1, "east (m)", "north (m)");
  std::vector<cv::Point2d> all_points;
  std::vector<LegendEntry> legend;
  const auto draw = [&](const PlotTrajectory& t, const cv::Scalar& colour, int thickness) {
    std::vector<cv::Point2d> points;
    for (const Eigen::Vector2d& p : t.north_east_m) {
      if (p.allFinite()) points.push_back(pixel(p));
    }
    drawPolyline(image, points, colour, thickness, false);
    all_points.insert(all_points.end(), points.begin(), points.end());
    legend.push_back({t.label, colour, thickness, false});
  };
  for (size_t i = 0; i < estimates.size(); ++i) draw(estimates[i], paletteColour(static_cast<int>(i)), 2);
  // Truth last so it stays visible on top of estimates that follow it closely.
  draw(truth, kBlack, 1);
  std::rotate(legend.rbegin(), legend.rbegin() + 1, legend.rend());  // truth first in the legend
  if (!truth.north_east_m.empty() && truth.north_east_m.front().allFinite()) {
    const cv::Point2d start = pixel(truth.north_east_m.front());
    cv::circle(image, cv::Point(static_cast<int>(start.x), static_cast<int>(start.y)), 6, kBlack, 2, cv::LINE_AA);
    putText(image, "start", cv::Point(static_cast<int>(start.x) + 9, static_cast<int>(start.y) - 8));
  }
  drawLegend(image, area, legend, all_points);
  putText(image, title, cv::Point(area.x, 32), kTitleScale, kBlack, 1);
  char scale_note[96];
  std::snprintf(scale_note, sizeof scale_note, "equal axes, 1 px = %.3g m", 1.0 / scale);
  putText(image, scale_note, cv::Point(area.x + area.width - textSize(scale_note).width, 32));
  return savePng(path, image, error);
}

bool writeCurvePlot(const std::string& path, const std::vector<PlotCurve>& curves, const std::vector<PlotBand>& bands,
                    const std::string& title, const std::string& x_label, const std::string& y_label,
                    std::string& error) {
  const cv::Size canvas(1400, 620);
  const cv::Rect area(90, 70, canvas.width - 90 - 30, canvas.height - 70 - 70);
  double x0 = 1e300, x1 = -1e300, y1 = 0.0;
  for (const PlotCurve& c : curves) {
    for (size_t i = 0; i < std::min(c.x.size(), c.y.size()); ++i) {
      if (!std::isfinite(c.x[i]) || !std::isfinite(c.y[i])) continue;
      x0 = std::min(x0, c.x[i]);
      x1 = std::max(x1, c.x[i]);
      y1 = std::max(y1, c.y[i]);
    }
  }
  if (x0 > x1) {
    error = "curve plot " + path + ": nothing to draw";
    return false;
  }
  if (x1 - x0 < 1e-9) x1 = x0 + 1.0;
  double y0 = 0.0;
  for (const PlotCurve& c : curves) {
    for (double y : c.y) {
      if (std::isfinite(y)) y0 = std::min(y0, y);
    }
  }
  y1 = y1 > y0 ? y0 + (y1 - y0) * 1.08 : y0 + 1.0;
  const auto pixel = [&](double x, double y) {
    return cv::Point2d(area.x + (x - x0) / (x1 - x0) * area.width, area.y + area.height - (y - y0) / (y1 - y0) * area.height);
  };

  cv::Mat image(canvas, CV_8UC3, kWhite);
  for (const PlotBand& band : bands) {
    const double a = std::max(band.x_min, x0), b = std::min(band.x_max, x1);
    if (!(b > a)) continue;
    const int left = static_cast<int>(std::lround(pixel(a, 0).x)), right = static_cast<int>(std::lround(pixel(b, 0).x));
    cv::rectangle(image, cv::Rect(left, area.y, std::max(1, right - left), area.height), cv::Scalar(244, 240, 236),
                  cv::FILLED);
    if (textSize(band.label).width < right - left) {
      // Above the frame, so the legend never hides it.
      putText(image, band.label, cv::Point((left + right) / 2 - textSize(band.label).width / 2, area.y - 8), kFontScale,
              kAxis);
    }
  }
  drawAxes(image, area, x0, x1, y0, y1, x_label, y_label);
  std::vector<cv::Point2d> all_points;
  std::vector<LegendEntry> legend;
  for (const PlotCurve& c : curves) {
    std::vector<cv::Point2d> points;
    for (size_t i = 0; i < std::min(c.x.size(), c.y.size()); ++i) {
      if (std::isfinite(c.x[i]) && std::isfinite(c.y[i])) points.push_back(pixel(c.x[i], c.y[i]));
    }
    const cv::Scalar colour = paletteColour(c.colour_index);
    drawPolyline(image, points, colour, c.dashed ? 1 : 2, c.dashed);
    all_points.insert(all_points.end(), points.begin(), points.end());
    legend.push_back({c.label, colour, c.dashed ? 1 : 2, c.dashed});
  }
  drawLegend(image, area, legend, all_points);
  putText(image, title, cv::Point(area.x, 32), kTitleScale, kBlack, 1);
  if (!bands.empty()) {
    const std::string note = "shaded: survey lines";
    putText(image, note, cv::Point(area.x + area.width - textSize(note).width, 32), kFontScale, kAxis);
  }
  return savePng(path, image, error);
}

bool writeErrorMapPng(const std::string& path, const HeightmapRaster& map, const std::string& title, std::string& error,
                      const ErrorMapPngOptions& options, double* used_limit_m) {
  if (map.rows < 1 || map.cols < 1 || map.depth_m.size() != static_cast<size_t>(map.rows) * map.cols) {
    error = "error map " + path + ": empty raster";
    return false;
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
  return savePng(path, image, error);
}

// ---- maps (sss-report) --------------------------------------------------------------------

namespace {

const cv::Scalar kNoData(232, 232, 232);

cv::Scalar bgr(const PlotColour& c) { return cv::Scalar(c.b, c.g, c.r); }

// Text with a white outline: readable on mosaic texture.
void putOutlinedText(cv::Mat& image, const std::string& text, cv::Point at, double scale = kFontScale) {
  cv::putText(image, text, at, kFont, scale, kWhite, 3, cv::LINE_AA);
  cv::putText(image, text, at, kFont, scale, kBlack, 1, cv::LINE_AA);
}

// Largest 1, 2 or 5 x 10^k not above value.
double niceFloor(double value) {
  if (!(value > 0.0) || !std::isfinite(value)) return 1.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(value)));
  for (double m : {5.0, 2.0, 1.0}) {
    if (m * magnitude <= value * (1.0 + 1e-12)) return m * magnitude;
  }
  return magnitude;
}

// Where a north/east rectangle lands in an image: the map area and its scale (px per metre).
struct MapGeometry {
  cv::Rect area;
  double scale = 1.0;
  double east_min_m = 0.0;
  double north_max_m = 0.0;

  cv::Point2d pixel(double north_m, double east_m) const {
    return {area.x + (east_m - east_min_m) * scale, area.y + (north_max_m - north_m) * scale};
  }
  cv::Point2d pixel(const Eigen::Vector2d& north_east) const { return pixel(north_east.x(), north_east.y()); }
  double northMinM() const { return north_max_m - area.height / scale; }
  double eastMaxM() const { return east_min_m + area.width / scale; }
};

MapGeometry fitMap(const MapExtent& extent, int max_width_px, int max_height_px, cv::Point origin) {
  MapGeometry g;
  const double span_e = extent.east_max_m - extent.east_min_m, span_n = extent.north_max_m - extent.north_min_m;
  g.scale = std::min(max_width_px / span_e, max_height_px / span_n);
  g.area = cv::Rect(origin.x, origin.y, std::max(1, static_cast<int>(std::lround(span_e * g.scale))),
                    std::max(1, static_cast<int>(std::lround(span_n * g.scale))));
  g.east_min_m = extent.east_min_m;
  g.north_max_m = extent.north_max_m;
  return g;
}

MapExtent withMargin(MapExtent extent, double fraction) {
  const double margin =
      fraction * std::max({extent.north_max_m - extent.north_min_m, extent.east_max_m - extent.east_min_m, 1.0});
  extent.north_min_m -= margin;
  extent.north_max_m += margin;
  extent.east_min_m -= margin;
  extent.east_max_m += margin;
  return extent;
}

void extendExtent(MapExtent& extent, bool& any, double north_m, double east_m) {
  if (!std::isfinite(north_m) || !std::isfinite(east_m)) return;
  if (!any) {
    extent = {north_m, north_m, east_m, east_m};
    any = true;
    return;
  }
  extent.north_min_m = std::min(extent.north_min_m, north_m);
  extent.north_max_m = std::max(extent.north_max_m, north_m);
  extent.east_min_m = std::min(extent.east_min_m, east_m);
  extent.east_max_m = std::max(extent.east_max_m, east_m);
}

// The mosaic on the map's pixel grid: mean grey (CV_32F) and a validity mask (CV_8U). Coarser maps
// area-average first, so fine texture does not alias; no-data pixels do not darken their neighbours.
void resampleMosaic(const GreyMosaic& mosaic, const MapGeometry& g, cv::Mat& grey, cv::Mat& valid) {
  const cv::Mat source(mosaic.rows, mosaic.cols, CV_8UC1, const_cast<uint8_t*>(mosaic.pixels.data()));
  cv::Mat weight, weighted;
  cv::Mat(source > 0).convertTo(weight, CV_32F, 1.0 / 255.0);
  source.convertTo(weighted, CV_32F);
  double res_e = mosaic.resolution_m, res_n = mosaic.resolution_m;
  const double map_resolution_m = 1.0 / g.scale;
  if (map_resolution_m > 1.05 * mosaic.resolution_m) {
    const double factor = mosaic.resolution_m / map_resolution_m;
    const cv::Size size(std::max(1, static_cast<int>(std::lround(mosaic.cols * factor))),
                        std::max(1, static_cast<int>(std::lround(mosaic.rows * factor))));
    cv::resize(weighted, weighted, size, 0, 0, cv::INTER_AREA);
    cv::resize(weight, weight, size, 0, 0, cv::INTER_AREA);
    res_e = mosaic.cols * mosaic.resolution_m / size.width;
    res_n = mosaic.rows * mosaic.resolution_m / size.height;
  }
  // Map pixel (x, y) -> source (col, row), both at pixel centres.
  const cv::Matx23d to_source(1.0 / (g.scale * res_e), 0.0, ((g.east_min_m - mosaic.east_min_m) + 0.5 / g.scale) / res_e - 0.5,
                              0.0, 1.0 / (g.scale * res_n),
                              ((mosaic.north_max_m - g.north_max_m) + 0.5 / g.scale) / res_n - 0.5);
  cv::Mat weighted_map, weight_map;
  cv::warpAffine(weighted, weighted_map, to_source, g.area.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                 cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::warpAffine(weight, weight_map, to_source, g.area.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                 cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::divide(weighted_map, cv::max(weight_map, 1e-6), grey);
  valid = weight_map > 0.5;
}

void drawMosaic(cv::Mat& image, const MapGeometry& g, const GreyMosaic& mosaic, double base, double gain) {
  cv::Mat grey, valid;
  resampleMosaic(mosaic, g, grey, valid);
  cv::Mat roi = image(g.area);
  for (int y = 0; y < roi.rows; ++y) {
    for (int x = 0; x < roi.cols; ++x) {
      if (!valid.at<uint8_t>(y, x)) {
        roi.at<cv::Vec3b>(y, x) = cv::Vec3b(232, 232, 232);
        continue;
      }
      const auto v = cv::saturate_cast<uint8_t>(base + gain * grey.at<float>(y, x));
      roi.at<cv::Vec3b>(y, x) = cv::Vec3b(v, v, v);
    }
  }
}

// Metre ticks outside the frame: north on the left (optional), east below.
void drawMapTicks(cv::Mat& image, const MapGeometry& g, bool north_labels) {
  double step = 0.0;
  const int target_e = std::max(2, g.area.width / 110);
  for (double e : ticks(g.east_min_m, g.eastMaxM(), target_e, step)) {
    const int x = static_cast<int>(std::lround(g.pixel(0.0, e).x));
    cv::line(image, cv::Point(x, g.area.y + g.area.height), cv::Point(x, g.area.y + g.area.height + 5), kAxis, 1);
    const std::string label = formatTick(e, step);
    putText(image, label, cv::Point(x - textSize(label).width / 2, g.area.y + g.area.height + 20));
  }
  if (north_labels) {
    const int target_n = std::max(2, g.area.height / 90);
    for (double n : ticks(g.northMinM(), g.north_max_m, target_n, step)) {
      const int y = static_cast<int>(std::lround(g.pixel(n, 0.0).y));
      cv::line(image, cv::Point(g.area.x - 6, y), cv::Point(g.area.x - 1, y), kAxis, 1);
      const std::string label = formatTick(n, step);
      putText(image, label, cv::Point(g.area.x - 10 - textSize(label).width, y + 5));
    }
  }
  cv::rectangle(image, cv::Rect(g.area.x - 1, g.area.y - 1, g.area.width + 2, g.area.height + 2), kAxis, 1);
}

// "0 ... L m" bar of about a fifth of the map width with "north up", right-aligned at (right, y).
void drawScaleBar(cv::Mat& image, const MapGeometry& g, int right, int y) {
  const double length_m = niceFloor(0.2 * g.area.width / g.scale);
  const int length_px = static_cast<int>(std::lround(length_m * g.scale));
  char label[48];
  std::snprintf(label, sizeof label, "%g m", length_m);
  const std::string text = std::string(label) + "   (north up)";
  const int text_x = right - textSize(text).width;
  const int x1 = text_x - 8, x0 = x1 - length_px;
  cv::rectangle(image, cv::Rect(x0, y - 6, length_px / 2, 6), kBlack, cv::FILLED);
  cv::rectangle(image, cv::Rect(x0, y - 6, length_px, 6), kBlack, 1);
  putText(image, "0", cv::Point(x0 - 4 - textSize("0").width, y));
  putText(image, text, cv::Point(text_x, y));
}

struct MapLegendEntry {
  std::string label;
  cv::Scalar colour;
  int thickness = 2;
  int casing_px = 0;
  cv::Scalar casing;
};

// Legend box in the corner of the map with the fewest drawn points under it.
void drawMapLegend(cv::Mat& image, const cv::Rect& area, const std::vector<MapLegendEntry>& entries,
                   const std::vector<cv::Point2d>& points) {
  if (entries.empty()) return;
  int width = 0;
  for (const MapLegendEntry& e : entries) width = std::max(width, textSize(e.label).width);
  const int line_height = 22;
  const cv::Size box(width + 60, static_cast<int>(entries.size()) * line_height + 10);
  const cv::Rect rect = emptiestCorner(area, box, points);
  cv::rectangle(image, rect, kWhite, cv::FILLED);
  cv::rectangle(image, rect, kAxis, 1);
  for (size_t i = 0; i < entries.size(); ++i) {
    const MapLegendEntry& e = entries[i];
    const int y = rect.y + 16 + static_cast<int>(i) * line_height;
    const cv::Point a(rect.x + 8, y - 4), b(rect.x + 44, y - 4);
    if (e.casing_px > 0) cv::line(image, a, b, e.casing, e.thickness + 2 * e.casing_px, cv::LINE_AA);
    cv::line(image, a, b, e.colour, e.thickness, cv::LINE_AA);
    putText(image, e.label, cv::Point(rect.x + 52, y));
  }
}

cv::Mat blankFigure(int width, int height) { return cv::Mat(height, width, CV_8UC3, kWhite); }

// Text turned 90 degrees anticlockwise, left edge at x, centred on centre_y (an axis title).
void putVerticalText(cv::Mat& image, const std::string& text, int x, int centre_y, const cv::Scalar& colour) {
  const cv::Size size = textSize(text);
  cv::Mat label(size.height + 8, size.width + 4, CV_8UC3, kWhite);
  putText(label, text, cv::Point(2, size.height + 2), kFontScale, colour);
  cv::Mat rotated;
  cv::rotate(label, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
  const int y = std::max(0, centre_y - rotated.rows / 2);
  if (x >= 0 && x + rotated.cols <= image.cols && y + rotated.rows <= image.rows) {
    rotated.copyTo(image(cv::Rect(x, y, rotated.cols, rotated.rows)));
  }
}

}  // namespace

PlotColour paletteRgb(int index) {
  const cv::Scalar c = paletteColour(index);
  return {static_cast<uint8_t>(c[2]), static_cast<uint8_t>(c[1]), static_cast<uint8_t>(c[0])};
}

bool readMosaic(const std::string& yaml_path, GreyMosaic& mosaic, std::string& error) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::BadFile&) {
    error = yaml_path + ": cannot open; check the path";
    return false;
  } catch (const YAML::Exception& e) {
    error = yaml_path + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg;
    return false;
  }
  GreyMosaic result;
  try {
    if (!root.IsMap()) throw YAML::Exception(root.Mark(), "not a map");
    for (const char* key : {"resolution_m", "north_max_m", "east_min_m", "rows", "cols"}) {
      if (!root[key]) {
        error = yaml_path + ": missing key '" + key + "' (a mosaic YAML has resolution_m, north_max_m, east_min_m, rows, cols)";
        return false;
      }
    }
    result.resolution_m = root["resolution_m"].as<double>();
    result.north_max_m = root["north_max_m"].as<double>();
    result.east_min_m = root["east_min_m"].as<double>();
    result.rows = root["rows"].as<int>();
    result.cols = root["cols"].as<int>();
  } catch (const YAML::Exception& e) {
    error = yaml_path + ":" + std::to_string(e.mark.line + 1) + ": expected numbers for resolution_m, north_max_m, "
            "east_min_m and integers for rows, cols";
    return false;
  }
  if (!(result.resolution_m > 0.0) || !std::isfinite(result.resolution_m) || !std::isfinite(result.north_max_m) ||
      !std::isfinite(result.east_min_m) || result.rows < 1 || result.cols < 1) {
    error = yaml_path + ": resolution_m must be positive, the corners finite and rows, cols >= 1";
    return false;
  }
  std::filesystem::path png(yaml_path);
  png.replace_extension(".png");
  cv::Mat image;
  try {
    image = cv::imread(png.string(), cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {
    error = png.string() + ": cannot decode: " + e.what();
    return false;
  }
  if (image.empty()) {
    error = png.string() + ": missing or not a PNG (the image of " + yaml_path + ")";
    return false;
  }
  if (image.rows != result.rows || image.cols != result.cols) {
    error = png.string() + ": " + std::to_string(image.cols) + " x " + std::to_string(image.rows) + " pixels, but " +
            yaml_path + " says cols " + std::to_string(result.cols) + ", rows " + std::to_string(result.rows);
    return false;
  }
  if (!image.isContinuous()) image = image.clone();
  result.pixels.assign(image.ptr<uint8_t>(0), image.ptr<uint8_t>(0) + static_cast<size_t>(image.rows) * image.cols);
  mosaic = std::move(result);
  return true;
}

MapExtent mosaicDataExtent(const GreyMosaic& mosaic) {
  int row_min = mosaic.rows, row_max = -1, col_min = mosaic.cols, col_max = -1;
  for (int r = 0; r < mosaic.rows; ++r) {
    const uint8_t* row = mosaic.pixels.data() + static_cast<size_t>(r) * mosaic.cols;
    for (int c = 0; c < mosaic.cols; ++c) {
      if (row[c] == 0) continue;
      row_min = std::min(row_min, r);
      row_max = std::max(row_max, r);
      col_min = std::min(col_min, c);
      col_max = std::max(col_max, c);
    }
  }
  if (row_max < 0) return {};
  return {mosaic.north_max_m - (row_max + 1) * mosaic.resolution_m, mosaic.north_max_m - row_min * mosaic.resolution_m,
          mosaic.east_min_m + col_min * mosaic.resolution_m, mosaic.east_min_m + (col_max + 1) * mosaic.resolution_m};
}

bool writeMapPng(const std::string& path, const MapFigure& figure, std::string& error) {
  MapExtent extent = figure.extent;
  if (!extent.valid()) {
    bool any = false;
    if (figure.background) {
      const MapExtent data = mosaicDataExtent(*figure.background);
      if (data.valid()) {
        extendExtent(extent, any, data.north_min_m, data.east_min_m);
        extendExtent(extent, any, data.north_max_m, data.east_max_m);
      }
    }
    for (const MapPolyline& line : figure.polylines) {
      for (const Eigen::Vector2d& p : line.north_east_m) extendExtent(extent, any, p.x(), p.y());
    }
    for (const MapSegments& set : figure.segments) {
      for (const auto& [a, b] : set.north_east_m) {
        extendExtent(extent, any, a.x(), a.y());
        extendExtent(extent, any, b.x(), b.y());
      }
    }
    if (!any) {
      error = "map " + path + ": nothing to draw";
      return false;
    }
    // At least 10 m, and not thinner than 3:4 either way, so the legend and the ticks have room.
    const double span_n = std::max(extent.north_max_m - extent.north_min_m, 10.0);
    const double span_e = std::max(extent.east_max_m - extent.east_min_m, 10.0);
    const double pad_n = 0.5 * (std::max(span_n, 0.75 * span_e) - (extent.north_max_m - extent.north_min_m));
    const double pad_e = 0.5 * (std::max(span_e, 0.75 * span_n) - (extent.east_max_m - extent.east_min_m));
    extent.north_min_m -= pad_n;
    extent.north_max_m += pad_n;
    extent.east_min_m -= pad_e;
    extent.east_max_m += pad_e;
    extent = withMargin(extent, 0.04);
  }
  const int left = 80, top = 72, right = 30, bottom = 62;
  const MapGeometry g = fitMap(extent, figure.max_map_width_px, figure.max_map_height_px, cv::Point(left, top));
  const int text_width = std::max(textSize(figure.title, kTitleScale).width, textSize(figure.note).width) + 32;
  cv::Mat image = blankFigure(std::max({left + g.area.width + right, 760, text_width}), top + g.area.height + bottom);
  if (figure.background) drawMosaic(image, g, *figure.background, figure.background_base, figure.background_gain);

  // Lines are clipped to the map area (a sub-image), so nothing spills over the ticks.
  cv::Mat map = image(g.area);
  const cv::Point2d offset(g.area.x, g.area.y);
  std::vector<cv::Point2d> drawn;
  std::vector<MapLegendEntry> legend;
  for (const MapPolyline& line : figure.polylines) {
    std::vector<cv::Point2d> points;
    for (const Eigen::Vector2d& p : line.north_east_m) {
      if (p.allFinite()) points.push_back(g.pixel(p) - offset);
    }
    if (line.casing_px > 0) drawPolyline(map, points, bgr(line.casing_colour), line.thickness_px + 2 * line.casing_px, false);
    drawPolyline(map, points, bgr(line.colour), line.thickness_px, false);
    for (const cv::Point2d& p : points) drawn.push_back(p + offset);
    if (!line.label.empty()) {
      legend.push_back({line.label, bgr(line.colour), line.thickness_px, line.casing_px, bgr(line.casing_colour)});
    }
  }
  std::vector<MapLegendEntry> segment_legend;
  for (const MapSegments& set : figure.segments) {
    for (const auto& [a, b] : set.north_east_m) {
      if (!a.allFinite() || !b.allFinite()) continue;
      const cv::Point2d pa = g.pixel(a) - offset, pb = g.pixel(b) - offset;
      drawPolyline(map, {pa, pb}, bgr(set.colour), set.thickness_px, false);
      for (const cv::Point2d& p : {pa, pb}) {
        cv::circle(map, cv::Point(static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y))),
                   set.thickness_px + 1, bgr(set.colour), cv::FILLED, cv::LINE_AA);
        drawn.push_back(p + offset);
      }
      drawn.push_back(0.5 * (pa + pb) + offset);
    }
    if (!set.label.empty()) segment_legend.push_back({set.label, bgr(set.colour), set.thickness_px, 0, kWhite});
  }
  legend.insert(legend.end(), segment_legend.rbegin(), segment_legend.rend());  // top-most first
  for (const MapPolyline& line : figure.polylines) {
    if (!line.mark_start || line.north_east_m.empty() || !line.north_east_m.front().allFinite()) continue;
    const cv::Point2d p = g.pixel(line.north_east_m.front());
    const cv::Point centre(static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)));
    cv::circle(image, centre, 8, kWhite, 4, cv::LINE_AA);
    cv::circle(image, centre, 8, kBlack, 2, cv::LINE_AA);
    putOutlinedText(image, "start", cv::Point(centre.x + 12, centre.y - 10));
  }
  drawMapLegend(image, g.area, legend, drawn);
  drawMapTicks(image, g, true);
  putText(image, "east (m)", cv::Point(g.area.x, g.area.y + g.area.height + 44), kFontScale, kAxis);
  putVerticalText(image, "north (m)", 6, g.area.y + g.area.height / 2, kAxis);
  drawScaleBar(image, g, g.area.x + g.area.width, g.area.y + g.area.height + 46);
  putText(image, figure.title, cv::Point(16, 26), kTitleScale);
  if (!figure.note.empty()) putText(image, figure.note, cv::Point(16, 48), kFontScale, kAxis);
  return savePng(path, image, error);
}

bool writeMosaicPanelsPng(const std::string& path, const std::vector<MosaicPanel>& panels, const std::string& title,
                          std::string& error, int max_width_px, int max_panel_height_px) {
  MapExtent extent;
  bool any = false;
  for (const MosaicPanel& panel : panels) {
    if (!panel.mosaic) continue;
    const MapExtent data = mosaicDataExtent(*panel.mosaic);
    if (!data.valid()) continue;
    extendExtent(extent, any, data.north_min_m, data.east_min_m);
    extendExtent(extent, any, data.north_max_m, data.east_max_m);
  }
  if (panels.empty() || !any) {
    error = "mosaic panels " + path + ": no mosaic with data";
    return false;
  }
  extent = withMargin(extent, 0.02);
  const int left = 80, top = 96, right = 24, gap = 24, bottom = 62;
  const int count = static_cast<int>(panels.size());
  const int panel_width = std::max(100, (max_width_px - left - right - gap * (count - 1)) / count);
  MapGeometry first = fitMap(extent, panel_width, max_panel_height_px, cv::Point(left, top));
  const int width = left + count * first.area.width + (count - 1) * gap + right;
  cv::Mat image = blankFigure(std::max(width, 760), top + first.area.height + bottom);
  MapGeometry g = first;
  for (int k = 0; k < count; ++k) {
    g.area.x = left + k * (first.area.width + gap);
    if (panels[k].mosaic) {
      drawMosaic(image, g, *panels[k].mosaic, 0.0, 1.0);
    } else {
      image(g.area).setTo(kNoData);
    }
    drawMapTicks(image, g, k == 0);
    putText(image, panels[k].label, cv::Point(g.area.x, top - 12), kTitleScale, kBlack, 2);
  }
  putText(image, "east (m)", cv::Point(left, top + first.area.height + 44), kFontScale, kAxis);
  putVerticalText(image, "north (m)", 6, top + first.area.height / 2, kAxis);
  drawScaleBar(image, g, g.area.x + g.area.width, top + first.area.height + 46);
  putText(image, title, cv::Point(16, 26), kTitleScale);
  char note[160];
  std::snprintf(note, sizeof note, "same extent and scale, 1 px = %.2g m; light grey = no data", 1.0 / first.scale);
  putText(image, note, cv::Point(16, 50), kFontScale, kAxis);
  return savePng(path, image, error);
}

bool writeDepthMapPng(const std::string& path, const HeightmapRaster& map, const std::string& title, std::string& error,
                      const DepthMapPngOptions& options) {
  if (map.rows < 1 || map.cols < 1 || map.depth_m.size() != static_cast<size_t>(map.rows) * map.cols) {
    error = "depth map " + path + ": empty raster";
    return false;
  }
  // Block-average down to max_size_px (rows grow northwards; the image's row 0 is the north edge).
  const int largest = std::max(map.rows, map.cols);
  const int block = std::max(1, (largest + options.max_size_px - 1) / std::max(1, options.max_size_px));
  const int rows = (map.rows + block - 1) / block, cols = (map.cols + block - 1) / block;
  cv::Mat depth(rows, cols, CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  std::vector<float> finite;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      double sum = 0.0;
      int n = 0;
      for (int dr = 0; dr < block; ++dr) {
        for (int dc = 0; dc < block; ++dc) {
          const int rr = r * block + dr, cc = c * block + dc;
          if (rr >= map.rows || cc >= map.cols || !std::isfinite(map.at(rr, cc))) continue;
          sum += map.at(rr, cc);
          ++n;
        }
      }
      if (n == 0) continue;
      depth.at<float>(rows - 1 - r, c) = static_cast<float>(sum / n);
      finite.push_back(static_cast<float>(sum / n));
    }
  }
  if (finite.empty()) {
    error = "depth map " + path + ": the raster has no data";
    return false;
  }
  const auto percentile = [&](double q) {
    const size_t k = std::min(finite.size() - 1, static_cast<size_t>(q * finite.size()));
    std::nth_element(finite.begin(), finite.begin() + k, finite.end());
    return static_cast<double>(finite[k]);
  };
  double shallow = percentile(0.01), deep = percentile(0.99);
  if (deep - shallow < 0.1) {
    shallow -= 0.05;
    deep += 0.05;
  }
  // Colour index: shallow 255 (yellow), deep 0 (purple).
  cv::Mat index(rows, cols, CV_8U, cv::Scalar(0));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const float d = depth.at<float>(r, c);
      if (std::isfinite(d)) index.at<uint8_t>(r, c) = cv::saturate_cast<uint8_t>(255.0 * (deep - d) / (deep - shallow));
    }
  }
  cv::Mat raster;
  cv::applyColorMap(index, raster, cv::COLORMAP_VIRIDIS);
  const double cell_m = map.resolution_m * block;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const float d = depth.at<float>(r, c);
      if (!std::isfinite(d)) {
        raster.at<cv::Vec3b>(r, c) = cv::Vec3b(190, 190, 190);
        continue;
      }
      if (!options.hillshade) continue;
      // Light from the north-west, 45 deg up; elevation = -depth, 3x vertical exaggeration so
      // decimetre relief shows; image rows grow southwards.
      const auto at = [&](int rr, int cc) {
        rr = std::clamp(rr, 0, rows - 1);
        cc = std::clamp(cc, 0, cols - 1);
        const float v = depth.at<float>(rr, cc);
        return std::isfinite(v) ? static_cast<double>(v) : static_cast<double>(d);
      };
      constexpr double kExaggeration = 3.0;
      const double dz_east = -(at(r, c + 1) - at(r, c - 1)) / (2.0 * cell_m) * kExaggeration;
      const double dz_north = -(at(r - 1, c) - at(r + 1, c)) / (2.0 * cell_m) * kExaggeration;
      const Eigen::Vector3d normal = Eigen::Vector3d(-dz_east, -dz_north, 1.0).normalized();  // east, north, up
      const Eigen::Vector3d light(-0.5, 0.5, std::sqrt(0.5));
      const double shade = std::clamp(normal.dot(light) / light.z(), 0.0, 1.6);
      const double factor = 0.55 + 0.45 * shade;
      cv::Vec3b& px = raster.at<cv::Vec3b>(r, c);
      for (int k = 0; k < 3; ++k) px[k] = cv::saturate_cast<uint8_t>(px[k] * factor);
    }
  }
  const double zoom = std::max(1.0, 700.0 / std::max(rows, cols));
  if (zoom > 1.0) {
    cv::resize(raster, raster, cv::Size(static_cast<int>(std::lround(cols * zoom)), static_cast<int>(std::lround(rows * zoom))),
               0, 0, cv::INTER_NEAREST);
  }
  const double px_per_cell = static_cast<double>(raster.cols) / (cols * block);
  const double metres_per_px = map.resolution_m / px_per_cell;

  const int left = 90, right = 40, top = 88, below_map = 50, bar_height = 16;
  const int width = std::max(raster.cols + left + right, 820);
  const int bar_y = top + raster.rows + below_map;
  cv::Mat image(bar_y + bar_height + 70, width, CV_8UC3, kWhite);
  raster.copyTo(image(cv::Rect(left, top, raster.cols, raster.rows)));
  MapGeometry g;
  g.area = cv::Rect(left, top, raster.cols, raster.rows);
  g.scale = 1.0 / metres_per_px;
  g.east_min_m = map.east_min_m - 0.5 * map.resolution_m;
  g.north_max_m = map.north_min_m + (rows * block - 0.5) * map.resolution_m;
  drawMapTicks(image, g, true);
  putText(image, "east (m)", cv::Point(left + raster.cols / 2 - textSize("east (m)").width / 2, top + raster.rows + 40));
  putText(image, "north (m)", cv::Point(8, top - 10));
  putText(image, title, cv::Point(16, 28), kTitleScale);
  char note[200];
  std::snprintf(note, sizeof note, "north up, 1 px = %.3g m; colour %.2f-%.2f m depth (1st-99th percentile)%s",
                metres_per_px, shallow, deep, options.hillshade ? ", hill-shaded" : "");
  putText(image, note, cv::Point(16, 52), kFontScale, kAxis);

  // Colour bar: shallow (left) to deep (right), depth in metres.
  const int bar_width = std::min(width - 120, 520);
  const int bar_x = (width - bar_width) / 2;
  cv::Mat ramp(1, bar_width, CV_8U);
  for (int x = 0; x < bar_width; ++x) {
    ramp.at<uint8_t>(0, x) = cv::saturate_cast<uint8_t>(255.0 * (bar_width - 1 - x) / (bar_width - 1));
  }
  cv::Mat ramp_colour;
  cv::applyColorMap(ramp, ramp_colour, cv::COLORMAP_VIRIDIS);
  cv::resize(ramp_colour, ramp_colour, cv::Size(bar_width, bar_height), 0, 0, cv::INTER_NEAREST);
  ramp_colour.copyTo(image(cv::Rect(bar_x, bar_y, bar_width, bar_height)));
  cv::rectangle(image, cv::Rect(bar_x, bar_y, bar_width, bar_height + 1), kAxis, 1);
  for (int k = 0; k <= 4; ++k) {
    const double value = shallow + (deep - shallow) * k / 4.0;
    const int x = bar_x + (bar_width - 1) * k / 4;
    cv::line(image, cv::Point(x, bar_y + bar_height), cv::Point(x, bar_y + bar_height + 5), kAxis, 1);
    char label[32];
    std::snprintf(label, sizeof label, "%.1f m", value);
    putText(image, label, cv::Point(x - textSize(label).width / 2, bar_y + bar_height + 20));
  }
  const std::string legend = "depth below the origin: yellow = shallow, purple = deep, grey = no data";
  putText(image, legend, cv::Point(width / 2 - textSize(legend).width / 2, bar_y + bar_height + 46), kFontScale, kAxis);
  return savePng(path, image, error);
}

std::vector<PlotCurve> horizontalErrorCurves(const std::string& label, const std::vector<ErrorSample>& series,
                                             int colour_index, int64_t t0_us) {
  PlotCurve raw{label + " horizontal", {}, {}, colour_index, false};
  PlotCurve aligned{label + " horizontal, SE(3)-aligned", {}, {}, colour_index, true};
  for (const ErrorSample& s : series) {
    const double minutes = static_cast<double>(s.utime_us - t0_us) / 60e6;
    raw.x.push_back(minutes);
    raw.y.push_back(s.horizontal_m);
    aligned.x.push_back(minutes);
    aligned.y.push_back(s.aligned_horizontal_m);
  }
  return {std::move(raw), std::move(aligned)};
}

std::vector<PlotBand> surveyLineBands(const std::vector<SurveyLine>& lines, int64_t t0_us) {
  std::vector<PlotBand> bands;
  for (const SurveyLine& line : lines) {
    bands.push_back({static_cast<double>(line.start_utime_us - t0_us) / 60e6,
                     static_cast<double>(line.end_utime_us - t0_us) / 60e6, "line " + std::to_string(line.index)});
  }
  return bands;
}

}  // namespace sss::eval
