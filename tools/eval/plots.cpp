// OpenCV drawing of the evaluation figures. See plots.hpp.
#include "tools/eval/plots.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

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

// Legend box in the corner of `area` with the fewest data points under it.
void drawLegend(cv::Mat& image, const cv::Rect& area, const std::vector<LegendEntry>& entries,
                const std::vector<cv::Point2d>& data_points) {
  if (entries.empty()) return;
  int width = 0;
  for (const LegendEntry& e : entries) width = std::max(width, textSize(e.label).width);
  const int line_height = 20;
  const cv::Size box(width + 54, static_cast<int>(entries.size()) * line_height + 10);
  const std::array<cv::Point, 4> corners = {
      cv::Point(area.x + 8, area.y + 8), cv::Point(area.x + area.width - box.width - 8, area.y + 8),
      cv::Point(area.x + 8, area.y + area.height - box.height - 8),
      cv::Point(area.x + area.width - box.width - 8, area.y + area.height - box.height - 8)};
  size_t best = 0, best_count = SIZE_MAX;
  for (size_t k = 0; k < corners.size(); ++k) {
    const cv::Rect rect(corners[k], box);
    size_t count = 0;
    for (const cv::Point2d& p : data_points) count += rect.contains(cv::Point(static_cast<int>(p.x), static_cast<int>(p.y)));
    if (count < best_count) {
      best_count = count;
      best = k;
    }
  }
  const cv::Rect rect(corners[best], box);
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

}  // namespace sss::eval
