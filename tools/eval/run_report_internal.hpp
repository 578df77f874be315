// Internal to the per-run report (run_report.cpp and its figures and rendering): formatting,
// the tables and sections shared by the HTML and the Markdown, the verdict.
#pragma once

#include "tools/eval/run_report.hpp"
#include "tools/eval/csv_fields.hpp"
#include "tools/eval/json_values.hpp"
#include "tools/eval/figure_script.hpp"
#include "tools/eval/grey_mosaic.hpp"
#include "tools/eval/report.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <limits>
#include <string>
#include <vector>

namespace sss::eval::report_internal {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Colours shared by every figure: DR orange, SLAM cyan (palette indices).
constexpr int kDrColour = 1;
constexpr int kSlamColour = 9;

inline std::string joinPath(const std::string& dir, const std::string& name) { return (fs::path(dir) / name).string(); }

inline bool fileExists(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

inline double improvementPercent(double dr, double slam) {
  if (!std::isfinite(dr) || !std::isfinite(slam) || !(dr > 0.0)) return kNaN;
  return 100.0 * (dr - slam) / dr;
}

// "0.60 m" style: enough digits to compare at the scale of the value.
inline std::string metres(double value) {
  if (!std::isfinite(value)) return "-";
  char text[48];
  const double magnitude = std::abs(value);
  std::snprintf(text, sizeof text, magnitude >= 10.0 ? "%.1f m" : magnitude >= 1.0 ? "%.2f m" : "%.3f m", value);
  return text;
}

inline std::string fixed(double value, int decimals) {
  if (!std::isfinite(value)) return "-";
  char text[48];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

inline std::string percent(double value, bool sign = false) {
  if (!std::isfinite(value)) return "-";
  char text[48];
  const int decimals = std::abs(value) >= 10.0 ? 0 : 1;
  std::snprintf(text, sizeof text, sign ? "%+.*f %%" : "%.*f %%", decimals, value);
  return text;
}

inline std::string count(double value) {
  if (!std::isfinite(value)) return "-";
  char text[48];
  std::snprintf(text, sizeof text, "%.0f", value);
  return text;
}

inline std::string markdownEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|' || c == '*' || c == '_' || c == '`' || c == '[' || c == ']' || c == '<' || c == '>') out += '\\';
    out += c;
  }
  return out;
}

// ---- tables shared by the page and the Markdown -------------------------------------------

// A table cell; tone marks improvement (+1, green) or deterioration (-1, red).
struct Cell {
  std::string text;
  int tone = 0;
  int span = 1;  // columns this cell covers
};
struct Table {
  std::string caption;
  std::vector<std::string> header;
  std::vector<std::vector<Cell>> rows;
};

inline int toneOf(double improvement_percent, double same_percent) {
  if (!std::isfinite(improvement_percent)) return 0;
  if (improvement_percent >= same_percent) return 1;
  if (improvement_percent <= -same_percent) return -1;
  return 0;
}

inline Cell improvementCell(double value, double same_percent) { return {percent(value, true), toneOf(value, same_percent)}; }

// One figure of the report: its file name (beside index.html), heading and a caption.
struct Figure {
  std::string section;  // figures with the same section are shown side by side
  std::string file;
  std::string alt;
  std::string caption;
};

struct Section {
  std::string heading;
  std::string text;  // a short paragraph (plain text)
  std::vector<Figure> figures;
  std::vector<Table> tables;
};

// The closest configured RPE window to the wanted one.
inline size_t closestWindow(const std::vector<double>& windows, double wanted) {
  size_t best = 0;
  for (size_t k = 1; k < windows.size(); ++k) {
    if (std::abs(windows[k] - wanted) < std::abs(windows[best] - wanted)) best = k;
  }
  return best;
}

inline std::vector<Eigen::Vector2d> northEast(const Trajectory& poses) {
  std::vector<Eigen::Vector2d> points;
  points.reserve(poses.size());
  for (const StampedPose& p : poses) points.push_back(p.T_world_body.translation.head<2>());
  return points;
}

inline std::vector<Eigen::Vector2d> estimateNorthEast(const TrajectoryEvaluation& evaluation) {
  std::vector<Eigen::Vector2d> points;
  points.reserve(evaluation.association.pairs.size());
  for (const AssociatedPose& p : evaluation.association.pairs) points.push_back(p.estimate.translation.head<2>());
  return points;
}

inline double lineRmse(const TrajectoryEvaluation& evaluation, int line) {
  for (const LineError& l : evaluation.lines) {
    if (l.line == line) return l.horizontal_m.rmse;
  }
  return kNaN;
}

// The raster cut to the bounding box of its cells with data (plus a 2-cell border), so a map
// laid out on a large grid is not drawn mostly empty.
inline HeightmapRaster cropToData(const HeightmapRaster& map) {
  int row_min = map.rows, row_max = -1, col_min = map.cols, col_max = -1;
  for (int r = 0; r < map.rows; ++r) {
    for (int c = 0; c < map.cols; ++c) {
      if (!std::isfinite(map.at(r, c))) continue;
      row_min = std::min(row_min, r);
      row_max = std::max(row_max, r);
      col_min = std::min(col_min, c);
      col_max = std::max(col_max, c);
    }
  }
  if (row_max < 0) return map;
  row_min = std::max(0, row_min - 2);
  col_min = std::max(0, col_min - 2);
  row_max = std::min(map.rows - 1, row_max + 2);
  col_max = std::min(map.cols - 1, col_max + 2);
  HeightmapRaster crop = map;
  crop.rows = row_max - row_min + 1;
  crop.cols = col_max - col_min + 1;
  crop.north_min_m = map.northM(row_min);
  crop.east_min_m = map.eastM(col_min);
  crop.depth_m.resize(static_cast<size_t>(crop.rows) * crop.cols);
  for (int r = 0; r < crop.rows; ++r) {
    for (int c = 0; c < crop.cols; ++c) crop.at(r, c) = map.at(r + row_min, c + col_min);
  }
  return crop;
}

// Round up to 1, 2 or 5 x 10^k (a colour scale's limit).
inline double niceCeil(double value) {
  if (!(value > 0.0) || !std::isfinite(value)) return 1.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(value)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * magnitude >= value * (1.0 - 1e-12)) return m * magnitude;
  }
  return 10.0 * magnitude;
}

// p99 of |error| over the maps: one colour limit for both error maps, so they compare.
inline double sharedErrorLimit(const std::vector<const HeightmapRaster*>& maps) {
  std::vector<float> magnitudes;
  for (const HeightmapRaster* map : maps) {
    for (float v : map->depth_m) {
      if (std::isfinite(v)) magnitudes.push_back(std::abs(v));
    }
  }
  if (magnitudes.empty()) return 1.0;
  const size_t k = std::min(magnitudes.size() - 1, static_cast<size_t>(0.99 * magnitudes.size()));
  std::nth_element(magnitudes.begin(), magnitudes.begin() + k, magnitudes.end());
  return niceCeil(std::max(static_cast<double>(magnitudes[k]), 1e-3));
}

inline std::string closureSummaryText(const RunReport& report) {
  if (report.has_closures) {
    const LoopClosureCounts& c = report.closure_counts;
    std::string text = std::to_string(c.accepted) + " closure" + (c.accepted == 1 ? "" : "s") + " accepted, " +
                       std::to_string(c.rejected) + " rejected";
    if (report.has_summary && std::isfinite(report.summary.pairs_attempted)) {
      text += " (" + count(report.summary.pairs_attempted) + " pairs attempted)";
    }
    return text;
  }
  if (report.has_summary && std::isfinite(report.summary.closures_accepted)) {
    return count(report.summary.closures_accepted) + " closures accepted, " + count(report.summary.closures_rejected) +
           " rejected (from summary.json)";
  }
  return "closures unknown (no loop_closures.csv)";
}

inline std::string realTimeText(const RunSummary& s) {
  if (!std::isfinite(s.real_time_factor)) return "-";
  std::string text = fixed(s.real_time_factor, s.real_time_factor >= 10.0 ? 1 : 2);
  if (std::isfinite(s.mission_s) && std::isfinite(s.wall_s)) {
    text += " (" + fixed(s.mission_s, 0) + " s of mission in " + fixed(s.wall_s, 1) + " s wall)";
  }
  return text;
}

inline void makeVerdict(RunReport& report, const RunReportOptions& options) {
  const double dr = report.dr.ate.horizontal_m.rmse, slam = report.slam.ate.horizontal_m.rmse;
  const double change = -report.ate_improvement_percent;  // SLAM vs DR, negative = smaller error
  std::string text;
  if (!std::isfinite(change)) {
    report.outcome = "same";
    text = "Horizontal position error RMSE: " + metres(dr) + " (DR), " + metres(slam) + " (SLAM)";
  } else if (change <= -options.same_change_percent) {
    report.outcome = "better";
    text = "SLAM reduced the horizontal position error RMSE from " + metres(dr) + " (DR) to " + metres(slam) + " (" +
           percent(change, true) + ")";
  } else if (change >= options.same_change_percent) {
    report.outcome = "worse";
    text = "SLAM is worse than dead reckoning: the horizontal position error RMSE rose from " + metres(dr) + " (DR) to " +
           metres(slam) + " (" + percent(change, true) + ")";
  } else {
    report.outcome = "same";
    text = "SLAM left the horizontal position error RMSE about unchanged: " + metres(dr) + " (DR), " + metres(slam) +
           " (SLAM, " + percent(change, true) + ")";
  }
  text += ", " + closureSummaryText(report);
  if (report.heightmap_dr.present && report.heightmap_slam.present) {
    const double a = report.heightmap_dr.error.abs_error_m.mean, b = report.heightmap_slam.error.abs_error_m.mean;
    const double hm_change = -report.heightmap_improvement_percent;
    if (std::isfinite(hm_change) && hm_change <= -options.same_change_percent) {
      text += "; the heightmap error (MAE) fell from " + metres(a) + " to " + metres(b) + " (" + percent(hm_change, true) + ")";
    } else if (std::isfinite(hm_change) && hm_change >= options.same_change_percent) {
      text += "; the heightmap error (MAE) rose from " + metres(a) + " to " + metres(b) + " (" + percent(hm_change, true) + ")";
    } else {
      text += "; the heightmap error (MAE) stayed at about " + metres(b) + " (DR " + metres(a) + ")";
    }
  } else if (report.heightmap_slam.present) {
    text += "; the SLAM heightmap error (MAE) is " + metres(report.heightmap_slam.error.abs_error_m.mean);
  }
  report.verdict = text + ".";
}

struct FigureContext {
  const RunReportRequest& request;
  RunReport& report;
  std::vector<Section>& sections;
  FigureBatch& figures;  // drawn by report_figures.py once every section is described
};

// After the script: removes the figures it did not draw from the sections (a section left empty
// says so), lists the drawn PNGs in report.files and adds the one note saying why.
void dropUndrawnFigures(FigureContext& context, const FigureRun& run);

// Figures and sections (run_report_figures.cpp).
// Each describes its PNGs to context.figures (see report_figures.py for what each kind reads) and
// lists them in its section. background: the true-pose mosaic's raster entry, null without one.
void trajectoryFigures(FigureContext& context, const Trajectory& truth, const Json& background);
void closureFigure(FigureContext& context, const Json& background);
void productsSection(FigureContext& context);
void mosaicFigure(FigureContext& context);
void heightmapFigures(FigureContext& context);
// The metric tables and the key figures (run_report_figures.cpp).
std::vector<Table> metricTables(const RunReport& report, const RunReportOptions& options);
Table keyTable(const RunReport& report, const RunReportOptions& options);

// report.md, and the model of index.html (title, verdict, key table, notes, sections with their
// figures and tables, metric tables, inputs) that report_page.py renders (run_report_render.cpp).
std::string renderMarkdown(const RunReport& report, const RunReportRequest& request, const Table& key,
                           const std::vector<Section>& sections, const std::vector<Table>& tables,
                           const std::vector<std::string>& inputs);
Json pageJson(const RunReport& report, const RunReportRequest& request, const Table& key,
              const std::vector<Section>& sections, const std::vector<Table>& tables,
              const std::vector<std::string>& inputs);
sss::core::Status writeText(const std::string& path, const std::string& text);

}  // namespace sss::eval::report_internal
