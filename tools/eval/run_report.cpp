// The per-run report: inputs -> metrics -> verdict, figures, index.html, report.md, metrics.json.
// See run_report.hpp.
#include "tools/eval/run_report.hpp"

#include "tools/eval/csv_fields.hpp"
#include "tools/eval/json_writer.hpp"
#include "tools/eval/plots.hpp"
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

namespace sss::eval {
namespace {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Colours shared by every figure: DR orange, SLAM cyan (palette indices).
constexpr int kDrColour = 1;
constexpr int kSlamColour = 9;

std::string joinPath(const std::string& dir, const std::string& name) { return (fs::path(dir) / name).string(); }

bool fileExists(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

double improvementPercent(double dr, double slam) {
  if (!std::isfinite(dr) || !std::isfinite(slam) || !(dr > 0.0)) return kNaN;
  return 100.0 * (dr - slam) / dr;
}

// "0.60 m" style: enough digits to compare at the scale of the value.
std::string metres(double value) {
  if (!std::isfinite(value)) return "-";
  char text[48];
  const double magnitude = std::abs(value);
  std::snprintf(text, sizeof text, magnitude >= 10.0 ? "%.1f m" : magnitude >= 1.0 ? "%.2f m" : "%.3f m", value);
  return text;
}

std::string fixed(double value, int decimals) {
  if (!std::isfinite(value)) return "-";
  char text[48];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

std::string percent(double value, bool sign = false) {
  if (!std::isfinite(value)) return "-";
  char text[48];
  const int decimals = std::abs(value) >= 10.0 ? 0 : 1;
  std::snprintf(text, sizeof text, sign ? "%+.*f %%" : "%.*f %%", decimals, value);
  return text;
}

std::string count(double value) {
  if (!std::isfinite(value)) return "-";
  char text[48];
  std::snprintf(text, sizeof text, "%.0f", value);
  return text;
}

std::string htmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string markdownEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|' || c == '*' || c == '_' || c == '`' || c == '[' || c == ']' || c == '<' || c == '>') out += '\\';
    out += c;
  }
  return out;
}

// ---- tables shared by the HTML and the Markdown ------------------------------------------

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

int toneOf(double improvement_percent, double same_percent) {
  if (!std::isfinite(improvement_percent)) return 0;
  if (improvement_percent >= same_percent) return 1;
  if (improvement_percent <= -same_percent) return -1;
  return 0;
}

Cell improvementCell(double value, double same_percent) { return {percent(value, true), toneOf(value, same_percent)}; }

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
size_t closestWindow(const std::vector<double>& windows, double wanted) {
  size_t best = 0;
  for (size_t k = 1; k < windows.size(); ++k) {
    if (std::abs(windows[k] - wanted) < std::abs(windows[best] - wanted)) best = k;
  }
  return best;
}

std::vector<Eigen::Vector2d> northEast(const Trajectory& poses) {
  std::vector<Eigen::Vector2d> points;
  points.reserve(poses.size());
  for (const StampedPose& p : poses) points.push_back(p.T_world_body.translation.head<2>());
  return points;
}

std::vector<Eigen::Vector2d> estimateNorthEast(const TrajectoryEvaluation& evaluation) {
  std::vector<Eigen::Vector2d> points;
  points.reserve(evaluation.association.pairs.size());
  for (const AssociatedPose& p : evaluation.association.pairs) points.push_back(p.estimate.translation.head<2>());
  return points;
}

double lineRmse(const TrajectoryEvaluation& evaluation, int line) {
  for (const LineError& l : evaluation.lines) {
    if (l.line == line) return l.horizontal_m.rmse;
  }
  return kNaN;
}

// The raster cut to the bounding box of its cells with data (plus a 2-cell border), so a map
// laid out on a large grid is not drawn mostly empty.
HeightmapRaster cropToData(const HeightmapRaster& map) {
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

// p99 of |error| over the maps: one colour limit for both error maps, so they compare.
double sharedErrorLimit(const std::vector<const HeightmapRaster*>& maps) {
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

std::string closureSummaryText(const RunReport& report) {
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

std::string realTimeText(const RunSummary& s) {
  if (!std::isfinite(s.real_time_factor)) return "-";
  std::string text = fixed(s.real_time_factor, s.real_time_factor >= 10.0 ? 1 : 2);
  if (std::isfinite(s.mission_s) && std::isfinite(s.wall_s)) {
    text += " (" + fixed(s.mission_s, 0) + " s of mission in " + fixed(s.wall_s, 1) + " s wall)";
  }
  return text;
}

void makeVerdict(RunReport& report, const RunReportOptions& options) {
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

// ---- inputs --------------------------------------------------------------------------------

// A file whose header names another origin than target_origin is re-expressed in its frame; the
// file's own origin goes to *origin when given.
bool readTrajectoryInput(const std::string& path, const std::string& what, Trajectory& poses, std::string& error,
                         const std::optional<sss::core::MissionOrigin>& target_origin = std::nullopt,
                         std::optional<sss::core::MissionOrigin>* origin = nullptr) {
  if (!fileExists(path)) {
    error = path + ": missing (" + what + ")";
    return false;
  }
  TumReadOptions options;
  options.target_origin = target_origin;
  TumReadResult result = readTum(path, options);
  if (!result.ok) {
    error = result.error;
    return false;
  }
  poses = std::move(result.poses);
  if (origin) *origin = result.origin;
  return true;
}

// Heightmaps are compared in the truth's frame (a run with its own origin is re-expressed).
HeightmapReadOptions truthFrame(const RunReport& report) {
  HeightmapReadOptions options;
  options.target_origin = report.truth_origin;
  return options;
}

void readHeightmaps(RunReport& report, const RunReportRequest& request) {
  const std::string seabed_path = joinPath(request.mission_dir, "seabed.yaml");
  const std::string slam_path = joinPath(request.run_dir, "heightmap.yaml");
  const std::string dr_path = joinPath(request.run_dir, "heightmap_dr.yaml");
  const bool have_slam = fileExists(slam_path), have_dr = fileExists(dr_path);
  if (!have_slam) report.notes.push_back("no SLAM heightmap (" + slam_path + "): heightmap section without it");
  if (!have_dr) report.notes.push_back("no DR heightmap (" + dr_path + "): heightmap section without it");
  if (!have_slam && !have_dr) return;
  HeightmapRaster seabed;
  std::string error;
  if (!fileExists(seabed_path)) {
    report.notes.push_back("no true seabed (" + seabed_path + "): heightmap errors not computed");
  } else if (!readHeightmap(seabed_path, seabed, error, truthFrame(report))) {
    report.notes.push_back("true seabed unusable, heightmap errors not computed: " + error);
    seabed = HeightmapRaster();
  } else {
    report.seabed_path = seabed_path;
  }
  for (auto [path, entry, present] : {std::tuple{slam_path, &report.heightmap_slam, have_slam},
                                      std::tuple{dr_path, &report.heightmap_dr, have_dr}}) {
    if (!present || report.seabed_path.empty()) continue;
    HeightmapRaster estimate;
    if (!readHeightmap(path, estimate, error, truthFrame(report))) {
      report.notes.push_back("heightmap unusable: " + error);
      continue;
    }
    entry->path = path;
    entry->error = compareHeightmaps(seabed, estimate);
    if (!entry->error.ok) {
      report.notes.push_back(path + ": not compared with the seabed: " + entry->error.error);
      continue;
    }
    entry->present = true;
  }
  if (report.heightmap_dr.present && report.heightmap_slam.present) {
    report.heightmap_improvement_percent =
        improvementPercent(report.heightmap_dr.error.abs_error_m.mean, report.heightmap_slam.error.abs_error_m.mean);
  }
}

// ---- figures -------------------------------------------------------------------------------

struct FigureContext {
  const RunReportRequest& request;
  RunReport& report;
  std::vector<Section>& sections;
};

// Writes one PNG through draw(path, error); records the file, or a note when it fails.
template <typename Draw>
bool drawFigure(FigureContext& context, const std::string& name, const Draw& draw) {
  const std::string path = joinPath(context.request.out_dir, name);
  std::string error;
  if (!draw(path, error)) {
    context.report.notes.push_back("figure " + name + " not drawn: " + error);
    return false;
  }
  context.report.files.push_back(path);
  return true;
}

void trajectoryFigures(FigureContext& context, const Trajectory& truth, const GreyMosaic* mosaic) {
  RunReport& report = context.report;
  Section section{"1. Trajectories over the mosaic", "", {}, {}};
  MapFigure map;
  map.title = mosaic ? "Trajectories over the true-pose mosaic: truth, dead reckoning (DR), SLAM"
                     : "Trajectories: truth, dead reckoning (DR), SLAM (no mosaic in the mission folder)";
  map.background = mosaic;
  MapPolyline truth_line{"truth", northEast(truth), {255, 255, 255}, 3, 1, {0, 0, 0}, true};
  MapPolyline dr_line{"dead reckoning (DR)", estimateNorthEast(report.dr), paletteRgb(kDrColour), 2, 0, {}, false};
  MapPolyline slam_line{"SLAM", estimateNorthEast(report.slam), paletteRgb(kSlamColour), 2, 0, {}, false};
  map.polylines = {truth_line, dr_line, slam_line};
  map.note = "horizontal error RMSE: DR " + metres(report.dr.ate.horizontal_m.rmse) + " (max " +
             metres(report.dr.ate.horizontal_m.max) + "), SLAM " + metres(report.slam.ate.horizontal_m.rmse) + " (max " +
             metres(report.slam.ate.horizontal_m.max) + "); lines closer than a pixel overlap";
  if (drawFigure(context, "trajectories.png", [&](const std::string& path, std::string& error) {
        return writeMapPng(path, map, error);
      })) {
    section.figures.push_back({"", "trajectories.png", "trajectories over the mosaic",
                               "Truth (white, black outline), DR (orange) and SLAM (cyan) over the mosaic rendered from "
                               "the true poses. The error over time below resolves what is finer than a pixel here."});
  }
  context.sections.push_back(section);

  Section errors{"2. Horizontal error over time", "", {}, {}};
  const int64_t t0 = truth.front().utime_us;
  std::vector<PlotCurve> curves;
  for (const auto& [label, evaluation, colour] :
       {std::tuple{std::string("DR"), &report.dr, kDrColour}, std::tuple{std::string("SLAM"), &report.slam, kSlamColour}}) {
    PlotCurve raw{label + " horizontal", {}, {}, colour, false};
    PlotCurve aligned{label + " horizontal, SE(3)-aligned", {}, {}, colour, true};
    for (const ErrorSample& s : evaluation->series) {
      const double minutes = static_cast<double>(s.utime_us - t0) / 60e6;
      raw.x.push_back(minutes);
      raw.y.push_back(s.horizontal_m);
      aligned.x.push_back(minutes);
      aligned.y.push_back(s.aligned_horizontal_m);
    }
    curves.push_back(std::move(raw));
    curves.push_back(std::move(aligned));
  }
  std::vector<PlotBand> bands;
  for (const SurveyLine& line : report.lines) {
    bands.push_back({static_cast<double>(line.start_utime_us - t0) / 60e6, static_cast<double>(line.end_utime_us - t0) / 60e6,
                     "line " + std::to_string(line.index)});
  }
  if (drawFigure(context, "error_over_time.png", [&](const std::string& path, std::string& error) {
        return writeCurvePlot(path, curves, bands, "Horizontal position error against the truth: DR vs SLAM",
                              "time since start (min)", "horizontal error (m)", error);
      })) {
    errors.figures.push_back({"", "error_over_time.png", "horizontal error over time",
                              "Solid: raw error; dashed: after the best rigid (SE(3)) alignment of the whole trajectory, "
                              "i.e. the shape error without the global offset. Shaded: survey lines."});
  }
  context.sections.push_back(errors);
}

// The tie report as mbnavadjust users read it: each closure's offset from DR's relative pose
// (before the solve) and from the final estimate's (after), and the decision. The largest
// offsets before the solve first; at most kMaxTieRows rows (loop_closures.csv has them all).
constexpr size_t kMaxTieRows = 60;
Table tieTable(const std::vector<LoopClosureRecord>& closures) {
  Table table;
  std::vector<const LoopClosureRecord*> ties;
  for (const LoopClosureRecord& r : closures) {
    if (r.before && r.after) ties.push_back(&r);
  }
  if (ties.empty()) return table;
  std::stable_sort(ties.begin(), ties.end(), [](const LoopClosureRecord* a, const LoopClosureRecord* b) {
    return a->before->head<2>().norm() > b->before->head<2>().norm();
  });
  table.caption = "Tie report: offset of each closure from DR (before) and from the solution (after), along / across "
                  "/ depth in m and heading in deg, in A's body frame" +
                  (ties.size() > kMaxTieRows ? " (the " + std::to_string(kMaxTieRows) + " largest of " +
                                                   std::to_string(ties.size()) + "; all in loop_closures.csv)"
                                             : std::string());
  table.header = {"subframes", "decision", "before along", "across", "depth", "heading", "after along", "across",
                  "depth", "heading"};
  for (size_t i = 0; i < ties.size() && i < kMaxTieRows; ++i) {
    const LoopClosureRecord& r = *ties[i];
    std::vector<Cell> row = {{r.subframes.empty() ? "line " + std::to_string(r.line) : r.subframes},
                             {r.status + (r.status == "rejected" && !r.rejection.empty() ? " (" + r.rejection + ")" : "")}};
    for (const Eigen::Vector4d* offset : {&*r.before, &*r.after}) {
      for (int k = 0; k < 3; ++k) row.push_back({fixed((*offset)(k), 2)});
      row.push_back({fixed((*offset)(3) * 180.0 / M_PI, 2)});
    }
    // Accepted closures the solution does not explain within a metre stand out.
    if (r.status == "accepted" && r.after->head<2>().norm() > 1.0) {
      for (size_t c = 6; c < 8; ++c) row[c].tone = -1;
    }
    table.rows.push_back(std::move(row));
  }
  return table;
}

void closureFigure(FigureContext& context, const GreyMosaic* mosaic) {
  RunReport& report = context.report;
  Section section{"3. Loop closures", "", {}, {}};
  if (!report.has_closures) {
    section.text = "No loop-closure file: this section is empty (see the notes).";
    context.sections.push_back(section);
    return;
  }
  const LoopClosureCounts& c = report.closure_counts;
  MapFigure map;
  map.title = "Loop closures between subframes over the SLAM trajectory";
  map.background = mosaic;
  map.background_base = 150.0;  // faded, so the graph reads first
  map.background_gain = 0.4;
  map.polylines.push_back({"SLAM trajectory", estimateNorthEast(report.slam), {70, 70, 70}, 1, 0, {}, true});
  MapSegments accepted{"accepted (" + std::to_string(c.accepted) + ")", {}, paletteRgb(2), 2};
  MapSegments rejected{"rejected (" + std::to_string(c.rejected) + ")", {}, paletteRgb(3), 2};
  MapSegments other{"superseded / pending (" + std::to_string(c.superseded + c.pending) + ")", {}, paletteRgb(7), 2};
  for (const LoopClosureRecord& r : report.closures) {
    MapSegments& set = r.status == "accepted" ? accepted : r.status == "rejected" ? rejected : other;
    set.north_east_m.emplace_back(r.centre_a_north_east_m, r.centre_b_north_east_m);
  }
  map.segments = {other, rejected, accepted};  // accepted on top
  if (c.superseded + c.pending == 0) map.segments.erase(map.segments.begin());
  map.note = "each segment joins the centres of the two subframes of a closure (final SLAM estimate)";
  if (drawFigure(context, "loop_closures.png", [&](const std::string& path, std::string& error) {
        return writeMapPng(path, map, error);
      })) {
    std::string caption = "Green: accepted closures; red: rejected";
    if (!c.rejection_reasons.empty()) {
      caption += " (";
      bool first = true;
      for (const auto& [reason, n] : c.rejection_reasons) {
        caption += (first ? "" : ", ") + reason + " " + std::to_string(n);
        first = false;
      }
      caption += ")";
    }
    caption += "; grey: superseded or still pending.";
    section.figures.push_back({"", "loop_closures.png", "loop-closure graph", caption});
  }
  section.tables.push_back(tieTable(report.closures));
  if (section.tables.back().rows.empty()) section.tables.pop_back();
  context.sections.push_back(section);
}

// What the run leaves for the survey: coverage, the fixes and calibration, the GeoTIFFs.
void productsSection(FigureContext& context) {
  const RunReport& report = context.report;
  if (!report.has_summary) return;
  const RunSummary& s = report.summary;
  Section section{"6. Survey products", "", {}, {}};
  std::string text;
  if (std::isfinite(s.covered_m2)) {
    text += "Coverage under the SLAM poses: " + fixed(s.covered_m2 / 10000.0, 2) + " ha, " +
            fixed(100.0 * s.fraction_seen_twice, 1) + " % of it seen from two lines or more (what side-scan " +
            "SLAM can use). ";
  }
  if (!s.geotiffs.empty()) {
    text += "GeoTIFFs (" + (s.geotiff_crs.empty() ? std::string("no CRS: set products.projected_crs") : s.geotiff_crs) +
            "): ";
    for (size_t i = 0; i < s.geotiffs.size(); ++i) text += (i ? ", " : "") + s.geotiffs[i];
    text += ".";
  }
  section.text = text;
  const std::string coverage_png = joinPath(context.request.run_dir, "coverage.png");
  if (fileExists(coverage_png)) {
    std::error_code ec;
    fs::copy_file(coverage_png, joinPath(context.request.out_dir, "coverage.png"),
                  fs::copy_options::overwrite_existing, ec);
    if (!ec) {
      section.figures.push_back({"", "coverage.png", "coverage",
                                 "Survey lines that saw each 5 m cell: grey one, green two, blue three or more."});
    }
  }
  Table fixes;
  fixes.caption = "Absolute fixes and DR calibration (final smoothing)";
  fixes.header = {"quantity", "value", "sigma"};
  if (std::isfinite(s.fixes_fed) && s.fixes_fed > 0) {
    fixes.rows.push_back({{"fixes accepted / given"},
                          {fixed(s.fixes_accepted, 0) + " / " + fixed(s.fixes_fed, 0)},
                          {""}});
    fixes.rows.push_back({{"fix residual RMS (m)"}, {fixed(s.fixes_rms_residual_m, 2)}, {""}});
  }
  if (s.calibration_estimated && std::isfinite(s.dvl_scale_sigma)) {
    fixes.rows.push_back({{"DVL scale error (%)"},
                          {fixed(100.0 * s.dvl_scale, 3)},
                          {fixed(100.0 * s.dvl_scale_sigma, 3)}});
  }
  if (s.calibration_estimated) {
    fixes.rows.push_back({{"heading bias (deg)"},
                          {fixed(s.heading_bias_rad * 180.0 / M_PI, 3)},
                          {fixed(s.heading_bias_sigma_rad * 180.0 / M_PI, 3)}});
  }
  if (!fixes.rows.empty()) section.tables.push_back(fixes);
  if (section.text.empty() && section.figures.empty() && section.tables.empty()) return;
  context.sections.push_back(section);
}

void mosaicFigure(FigureContext& context) {
  Section section{"4. Mosaics: DR vs SLAM", "", {}, {}};
  GreyMosaic dr, slam;
  std::string error;
  bool ok = true;
  for (auto [name, mosaic] : {std::pair{"mosaic_dr.yaml", &dr}, std::pair{"mosaic_slam.yaml", &slam}}) {
    const std::string path = joinPath(context.request.run_dir, name);
    if (!fileExists(path)) {
      context.report.notes.push_back("no " + std::string(name) + " in the run folder (" + path + "): no mosaic comparison");
      ok = false;
    } else if (!readMosaic(path, *mosaic, error)) {
      context.report.notes.push_back("mosaic unusable, no mosaic comparison: " + error);
      ok = false;
    }
  }
  if (ok && drawFigure(context, "mosaics_dr_slam.png", [&](const std::string& path, std::string& e) {
        return writeMosaicPanelsPng(path, {{"dead reckoning (DR)", &dr}, {"SLAM", &slam}},
                                    "Mosaics rendered with the DR and the SLAM navigation", e);
      })) {
    section.figures.push_back({"", "mosaics_dr_slam.png", "DR vs SLAM mosaics",
                               "Where lines overlap, features should be single and sharp; doubled or smeared features "
                               "show navigation error."});
  } else {
    section.text = "Not available (see the notes).";
  }
  context.sections.push_back(section);
}

void heightmapFigures(FigureContext& context) {
  RunReport& report = context.report;
  Section section{"5. Heightmaps", "", {}, {}};
  const std::string slam_path = joinPath(context.request.run_dir, "heightmap.yaml");
  HeightmapRaster slam;
  std::string error;
  if (fileExists(slam_path) && readHeightmap(slam_path, slam, error)) {
    char title[256];
    std::snprintf(title, sizeof title, "SLAM heightmap: %.2g m cells, grid %zu x %zu", slam.resolution_m,
                  static_cast<size_t>(slam.cols), static_cast<size_t>(slam.rows));
    if (drawFigure(context, "heightmap_slam.png", [&](const std::string& path, std::string& e) {
          return writeDepthMapPng(path, cropToData(slam), title, e);
        })) {
      section.figures.push_back({"depth", "heightmap_slam.png", "SLAM heightmap", "Gridded bathymetry from the SLAM poses."});
    }
  }
  std::vector<const HeightmapRaster*> maps;
  for (const RunHeightmap* h : {&report.heightmap_dr, &report.heightmap_slam}) {
    if (h->present) maps.push_back(&h->error.error_map);
  }
  if (!maps.empty()) {
    ErrorMapPngOptions png_options;
    png_options.limit_m = sharedErrorLimit(maps);
    png_options.max_size_px = 700;
    for (const auto& [label, name, entry] :
         {std::tuple{std::string("DR"), std::string("heightmap_error_dr.png"), &report.heightmap_dr},
          std::tuple{std::string("SLAM"), std::string("heightmap_error_slam.png"), &report.heightmap_slam}}) {
      if (!entry->present) continue;
      char title[256];
      std::snprintf(title, sizeof title, "Heightmap error, %s: MAE %.3f m, bias %+.3f m", label.c_str(),
                    entry->error.abs_error_m.mean, entry->error.mean_signed_error_m);
      if (drawFigure(context, name, [&](const std::string& path, std::string& e) {
            return writeErrorMapPng(path, cropToData(entry->error.error_map), title, e, png_options);
          })) {
        section.figures.push_back({"errors", name, label + " heightmap error",
                                   label + " heightmap minus the true seabed (same colour scale for DR and SLAM)."});
      }
    }
  }
  if (section.figures.empty()) section.text = "Not available (see the notes).";
  context.sections.push_back(section);
}

// ---- tables --------------------------------------------------------------------------------

std::vector<Table> metricTables(const RunReport& report, const RunReportOptions& options) {
  const double same = options.same_change_percent;
  std::vector<Table> tables;
  Table trajectory{"Trajectory against the truth (" + std::to_string(report.truth_poses) + " poses, " +
                       fixed(report.duration_s / 60.0, 1) + " min, " + fixed(report.distance_m, 0) + " m)",
                   {"metric", "DR", "SLAM", "improvement"},
                   {}};
  const auto row = [&](const std::string& name, double dr, double slam, const std::string& unit, int decimals) {
    trajectory.rows.push_back({{name}, {fixed(dr, decimals) + unit}, {fixed(slam, decimals) + unit},
                               improvementCell(improvementPercent(dr, slam), same)});
  };
  const AteResult& d = report.dr.ate;
  const AteResult& s = report.slam.ate;
  row("ATE horizontal RMSE", d.horizontal_m.rmse, s.horizontal_m.rmse, " m", 3);
  row("ATE horizontal max", d.horizontal_m.max, s.horizontal_m.max, " m", 3);
  row("ATE horizontal RMSE, SE(3)-aligned", d.aligned_horizontal_m.rmse, s.aligned_horizontal_m.rmse, " m", 3);
  row("ATE horizontal max, SE(3)-aligned", d.aligned_horizontal_m.max, s.aligned_horizontal_m.max, " m", 3);
  row("ATE horizontal RMSE, gauge-free", d.gauge_free_horizontal_m.rmse, s.gauge_free_horizontal_m.rmse, " m", 3);
  row("ATE horizontal max, gauge-free", d.gauge_free_horizontal_m.max, s.gauge_free_horizontal_m.max, " m", 3);
  // The fitted gauge itself: no better or worse, so no improvement cell.
  trajectory.rows.push_back({{"gauge fit: rotation about the start (clockwise +)"},
                             {fixed(d.gauge_free_rotation_deg, 4) + " deg"},
                             {fixed(s.gauge_free_rotation_deg, 4) + " deg"},
                             {""}});
  trajectory.rows.push_back(
      {{"gauge fit: scale about the start"}, {fixed(d.gauge_free_scale, 5)}, {fixed(s.gauge_free_scale, 5)}, {""}});
  row("ATE 3D RMSE", d.position_m.rmse, s.position_m.rmse, " m", 3);
  if (!report.dr.rpe.empty() && !report.slam.rpe.empty()) {
    const std::string window = fixed(report.rpe_window_m, 0) + " m";
    row("RPE per " + window + ", translation (mean)", report.dr.rpe[report.rpe_index].translation_percent.mean,
        report.slam.rpe[report.rpe_index].translation_percent.mean, " %", 3);
    row("RPE per " + window + ", rotation (mean)", report.dr.rpe[report.rpe_index].rotation_deg.mean,
        report.slam.rpe[report.rpe_index].rotation_deg.mean, " deg", 3);
  }
  const auto matched = [](const TrajectoryEvaluation& e) {
    return std::to_string(e.association.pairs.size()) + "/" + std::to_string(e.estimate_poses);
  };
  if (report.has_lce) {
    row("landmark consistency error (LCE) mean", report.lce_dr.mean, report.lce_slam.mean, " m", 3);
    row("landmark consistency error (LCE) RMSE", report.lce_dr.rmse, report.lce_slam.rmse, " m", 3);
  }
  if (report.has_closure_errors) {
    // DR column: DR's relative pose between the two subframe centres; SLAM column: the closure's.
    const std::string accepted = " (" + std::to_string(report.closure_errors_accepted) + " accepted)";
    row("closure relative pose error RMS, horizontal" + accepted, report.closure_errors_dr.horizontal_m.rmse,
        report.closure_errors.horizontal_m.rmse, " m", 3);
    row("closure relative pose error RMS, lateral" + accepted, report.closure_errors_dr.lateral_m.abs.rmse,
        report.closure_errors.lateral_m.abs.rmse, " m", 3);
    row("closure relative pose error RMS, heading" + accepted, report.closure_errors_dr.heading_deg.abs.rmse,
        report.closure_errors.heading_deg.abs.rmse, " deg", 3);
  }
  trajectory.rows.push_back({{"poses matched to the truth"}, {matched(report.dr)}, {matched(report.slam)}, {""}});
  tables.push_back(trajectory);

  if (!report.lines.empty()) {
    Table lines{"Horizontal ATE RMSE per survey line (raw)", {"line", "heading", "length", "DR", "SLAM", "improvement"}, {}};
    for (const SurveyLine& line : report.lines) {
      const double dr = lineRmse(report.dr, line.index), slam = lineRmse(report.slam, line.index);
      lines.rows.push_back({{"line " + std::to_string(line.index)}, {fixed(line.heading_deg, 0) + " deg"},
                            {fixed(line.length_m, 0) + " m"}, {fixed(dr, 3) + " m"}, {fixed(slam, 3) + " m"},
                            improvementCell(improvementPercent(dr, slam), same)});
    }
    tables.push_back(lines);
  }

  if (report.heightmap_dr.present || report.heightmap_slam.present) {
    Table heightmap{"Heightmap against the true seabed", {"metric", "DR", "SLAM", "improvement"}, {}};
    const HeightmapErrorResult& a = report.heightmap_dr.error;
    const HeightmapErrorResult& b = report.heightmap_slam.error;
    const bool has_a = report.heightmap_dr.present, has_b = report.heightmap_slam.present;
    const auto value = [](bool has, double v, const std::string& unit, int decimals) {
      return has ? fixed(v, decimals) + unit : std::string("-");
    };
    const auto hm_row = [&](const std::string& name, double va, double vb, const std::string& unit, int decimals,
                            bool improvement) {
      heightmap.rows.push_back({{name}, {value(has_a, va, unit, decimals)}, {value(has_b, vb, unit, decimals)},
                                improvement && has_a && has_b ? improvementCell(improvementPercent(va, vb), same) : Cell{""}});
    };
    hm_row("MAE", a.abs_error_m.mean, b.abs_error_m.mean, " m", 3, true);
    hm_row("RMSE", a.abs_error_m.rmse, b.abs_error_m.rmse, " m", 3, true);
    hm_row("max |error|", a.abs_error_m.max, b.abs_error_m.max, " m", 3, false);
    hm_row("bias (estimate - truth)", a.mean_signed_error_m, b.mean_signed_error_m, " m", 3, false);
    hm_row("coverage of the grid", 100.0 * a.coverage_fraction, 100.0 * b.coverage_fraction, " %", 1, false);
    tables.push_back(heightmap);
  }

  Table run{"The run", {"figure", "value"}, {}};
  const LoopClosureCounts& c = report.closure_counts;
  if (report.has_closures) {
    run.rows.push_back({{"closures accepted"}, {std::to_string(c.accepted)}});
    std::string rejected = std::to_string(c.rejected);
    if (!c.rejection_reasons.empty()) {
      rejected += " (";
      bool first = true;
      for (const auto& [reason, n] : c.rejection_reasons) {
        rejected += (first ? "" : ", ") + reason + " " + std::to_string(n);
        first = false;
      }
      rejected += ")";
    }
    run.rows.push_back({{"closures rejected"}, {rejected}});
    run.rows.push_back({{"closures superseded / pending"}, {std::to_string(c.superseded) + " / " + std::to_string(c.pending)}});
  }
  if (report.has_summary) {
    const RunSummary& m = report.summary;
    if (!report.has_closures) {
      run.rows.push_back({{"closures accepted"}, {count(m.closures_accepted)}});
      run.rows.push_back({{"closures rejected"}, {count(m.closures_rejected)}});
    }
    run.rows.push_back({{"subframe pairs attempted"}, {count(m.pairs_attempted)}});
    run.rows.push_back({{"pings"}, {count(m.pings)}});
    run.rows.push_back({{"subframes"}, {count(m.subframes)}});
    run.rows.push_back({{"mission duration"}, {fixed(m.mission_s, 0) + " s"}});
    run.rows.push_back({{"wall time"}, {fixed(m.wall_s, 1) + " s"}});
    run.rows.push_back({{"real-time factor"}, {realTimeText(m)}});
    run.rows.push_back({{"peak memory (RSS)"}, {fixed(m.peak_rss_mib, 0) + " MiB"}});
  }
  if (!run.rows.empty()) tables.push_back(run);
  return tables;
}

// The few numbers an engineer reads first.
Table keyTable(const RunReport& report, const RunReportOptions& options) {
  const double same = options.same_change_percent;
  Table table{"", {"", "DR", "SLAM", "improvement"}, {}};
  table.rows.push_back({{"horizontal position error RMSE"}, {metres(report.dr.ate.horizontal_m.rmse)},
                        {metres(report.slam.ate.horizontal_m.rmse)}, improvementCell(report.ate_improvement_percent, same)});
  table.rows.push_back({{"after SE(3) alignment (shape)"}, {metres(report.dr.ate.aligned_horizontal_m.rmse)},
                        {metres(report.slam.ate.aligned_horizontal_m.rmse)},
                        improvementCell(report.aligned_ate_improvement_percent, same)});
  table.rows.push_back({{"gauge-free (what side-scan can see)"}, {metres(report.dr.ate.gauge_free_horizontal_m.rmse)},
                        {metres(report.slam.ate.gauge_free_horizontal_m.rmse)},
                        improvementCell(report.gauge_free_ate_improvement_percent, same)});
  if (report.heightmap_dr.present || report.heightmap_slam.present) {
    table.rows.push_back({{"heightmap MAE"},
                          {report.heightmap_dr.present ? metres(report.heightmap_dr.error.abs_error_m.mean) : "-"},
                          {report.heightmap_slam.present ? metres(report.heightmap_slam.error.abs_error_m.mean) : "-"},
                          improvementCell(report.heightmap_improvement_percent, same)});
  }
  table.rows.push_back({{"closures"}, {closureSummaryText(report), 0, 3}});
  if (report.has_summary) table.rows.push_back({{"real-time factor"}, {realTimeText(report.summary), 0, 3}});
  return table;
}

// ---- HTML and Markdown ---------------------------------------------------------------------

std::string htmlTable(const Table& table) {
  std::ostringstream out;
  out << "<table>\n";
  if (!table.caption.empty()) out << "<caption>" << htmlEscape(table.caption) << "</caption>\n";
  out << "<tr>";
  for (const std::string& h : table.header) out << "<th>" << htmlEscape(h) << "</th>";
  out << "</tr>\n";
  for (const auto& row : table.rows) {
    out << "<tr>";
    for (size_t c = 0; c < row.size(); ++c) {
      const char* tone = row[c].tone > 0 ? " class=\"good\"" : row[c].tone < 0 ? " class=\"bad\"" : "";
      const std::string span =
          row[c].span > 1 ? " colspan=\"" + std::to_string(row[c].span) + "\" style=\"text-align:left\"" : "";
      out << (c == 0 ? "<th scope=\"row\"" : "<td") << tone << span << ">" << htmlEscape(row[c].text)
          << (c == 0 ? "</th>" : "</td>");
    }
    out << "</tr>\n";
  }
  out << "</table>\n";
  return out.str();
}

std::string markdownTable(const Table& table) {
  std::ostringstream out;
  if (!table.caption.empty()) out << "**" << markdownEscape(table.caption) << "**\n\n";
  out << "|";
  for (const std::string& h : table.header) out << " " << markdownEscape(h) << " |";
  out << "\n|";
  for (size_t c = 0; c < table.header.size(); ++c) out << (c == 0 ? " --- |" : " ---: |");
  out << "\n";
  for (const auto& row : table.rows) {
    out << "|";
    for (const Cell& cell : row) {
      out << " " << markdownEscape(cell.text) << " |";
      for (int k = 1; k < cell.span; ++k) out << " |";
    }
    out << "\n";
  }
  return out.str() + "\n";
}

const char* kCss =
    "body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,sans-serif;max-width:1240px;margin:1.5em auto;"
    "padding:0 1em;color:#222;line-height:1.4}\n"
    "h1{font-size:1.5em;margin-bottom:.3em}h2{font-size:1.2em;margin-top:1.8em;border-bottom:1px solid #ddd}\n"
    ".verdict{font-size:1.15em;padding:.7em 1em;border-left:6px solid #888;background:#f4f4f4}\n"
    ".verdict.better{border-color:#2a9d2a;background:#eaf6ea}.verdict.worse{border-color:#c62828;background:#fbeaea}\n"
    "table{border-collapse:collapse;margin:.6em 0 1.2em}caption{text-align:left;font-weight:600;padding:.3em 0}\n"
    "th,td{border:1px solid #ccc;padding:.25em .6em;text-align:right}th[scope=row]{text-align:left;font-weight:normal}\n"
    "tr:first-child th{background:#f0f0f0}td.good{background:#dff2df}td.bad{background:#f8dcdc}\n"
    "figure{margin:.5em 0 1.2em}figure img{max-width:100%;border:1px solid #ccc}figcaption{color:#555;font-size:.92em}\n"
    ".row{display:flex;gap:1em;flex-wrap:wrap}.row figure{flex:1 1 45%}\n"
    ".notes{background:#fff8e1;border:1px solid #f0d890;padding:.5em 1em}.small{color:#666;font-size:.9em}\n";

std::string renderHtml(const RunReport& report, const RunReportRequest& request, const Table& key,
                       const std::vector<Section>& sections, const std::vector<Table>& tables,
                       const std::vector<std::string>& inputs) {
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" << htmlEscape(report.title)
      << "</title>\n<style>\n" << kCss << "</style>\n</head>\n<body>\n";
  out << "<h1>" << htmlEscape(report.title) << "</h1>\n";
  out << "<p class=\"small\">mission " << htmlEscape(request.mission_dir) << " &middot; run " << htmlEscape(request.run_dir)
      << "</p>\n";
  out << "<p class=\"verdict " << report.outcome << "\">" << htmlEscape(report.verdict) << "</p>\n";
  out << htmlTable(key);
  if (!report.notes.empty()) {
    out << "<div class=\"notes\"><strong>Notes</strong> (missing or unusable inputs; their sections are left out)\n<ul>\n";
    for (const std::string& note : report.notes) out << "<li>" << htmlEscape(note) << "</li>\n";
    out << "</ul></div>\n";
  }
  for (const Section& section : sections) {
    out << "<h2>" << htmlEscape(section.heading) << "</h2>\n";
    if (!section.text.empty()) out << "<p>" << htmlEscape(section.text) << "</p>\n";
    std::string open_row;
    for (size_t i = 0; i < section.figures.size(); ++i) {
      const Figure& f = section.figures[i];
      const bool grouped = !f.section.empty();
      const bool starts = grouped && (i == 0 || section.figures[i - 1].section != f.section);
      const bool ends = grouped && (i + 1 == section.figures.size() || section.figures[i + 1].section != f.section);
      if (starts) out << "<div class=\"row\">\n";
      out << "<figure><img src=\"" << htmlEscape(f.file) << "\" alt=\"" << htmlEscape(f.alt) << "\"><figcaption>"
          << htmlEscape(f.caption) << "</figcaption></figure>\n";
      if (ends) out << "</div>\n";
    }
    for (const Table& table : section.tables) out << htmlTable(table);
  }
  out << "<h2>7. Metrics</h2>\n";
  out << "<p class=\"small\">improvement = (DR - SLAM) / DR; green: SLAM better, red: SLAM worse. ATE: absolute "
         "trajectory error against the truth at the same time stamps; SE(3)-aligned: after the best rigid alignment "
         "of the whole trajectory; gauge-free: after the best horizontal rotation and scale about the estimate's first "
         "position, without a shift (what a constant heading bias and a DVL scale factor do, which no loop closure "
         "sees). RPE: relative pose error over the given path length.</p>\n";
  for (const Table& table : tables) out << htmlTable(table);
  out << "<h2>Inputs</h2>\n<ul class=\"small\">\n";
  for (const std::string& input : inputs) out << "<li>" << htmlEscape(input) << "</li>\n";
  out << "</ul>\n<p class=\"small\">Written by sss-report (machine-readable: <a href=\"metrics.json\">metrics.json</a>).</p>\n";
  out << "</body>\n</html>\n";
  return out.str();
}

std::string renderMarkdown(const RunReport& report, const RunReportRequest& request, const Table& key,
                           const std::vector<Section>& sections, const std::vector<Table>& tables,
                           const std::vector<std::string>& inputs) {
  std::ostringstream out;
  out << "# " << markdownEscape(report.title) << "\n\n";
  out << "mission `" << request.mission_dir << "`, run `" << request.run_dir << "`\n\n";
  out << "> **" << (report.outcome == "better" ? "Better" : report.outcome == "worse" ? "Worse" : "About the same")
      << ":** " << markdownEscape(report.verdict) << "\n\n";
  out << markdownTable(key);
  if (!report.notes.empty()) {
    out << "**Notes** (missing or unusable inputs; their sections are left out)\n\n";
    for (const std::string& note : report.notes) out << "- " << markdownEscape(note) << "\n";
    out << "\n";
  }
  for (const Section& section : sections) {
    out << "## " << markdownEscape(section.heading) << "\n\n";
    if (!section.text.empty()) out << markdownEscape(section.text) << "\n\n";
    for (const Figure& f : section.figures) {
      out << "![" << markdownEscape(f.alt) << "](" << f.file << ")\n\n" << "*" << markdownEscape(f.caption) << "*\n\n";
    }
    for (const Table& table : section.tables) out << markdownTable(table);
  }
  out << "## 7. Metrics\n\nimprovement = (DR - SLAM) / DR, positive: SLAM better.\n\n";
  for (const Table& table : tables) out << markdownTable(table);
  out << "## Inputs\n\n";
  for (const std::string& input : inputs) out << "- `" << input << "`\n";
  out << "\nMachine-readable: [metrics.json](metrics.json).\n";
  return out.str();
}

bool writeText(const std::string& path, const std::string& text, std::string& error) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) {
    error = "cannot write " + path + "; check the directory exists, is writable and has space";
    return false;
  }
  return true;
}

}  // namespace

// ---- loop closures and summary -----------------------------------------------------------

bool readLoopClosures(const std::string& path, std::vector<LoopClosureRecord>& closures, std::string& error) {
  const std::vector<const char*> kCentres = {"north_a_m", "east_a_m", "north_b_m", "east_b_m"};
  CsvTable table;
  if (!readCsvTable(path, {"status", kCentres[0], kCentres[1], kCentres[2], kCentres[3]},
                    "subframe_id_a,subframe_id_b,...,status,...,north_a_m,east_a_m,north_b_m,east_b_m", table, error)) {
    return false;
  }
  closures.clear();
  for (const CsvRow& row : table.rows) {
    LoopClosureRecord record;
    record.line = row.line;
    record.status = table.field(row, "status");
    if (record.status != "accepted" && record.status != "rejected" && record.status != "pending" &&
        record.status != "superseded") {
      error = table.where(row) + "status '" + record.status + "' is not accepted, rejected, pending or superseded";
      return false;
    }
    if (table.has("rejection")) record.rejection = table.field(row, "rejection");
    double values[4];
    if (!parseNumberColumns(table, row, kCentres, values, error)) return false;
    record.centre_a_north_east_m = Eigen::Vector2d(values[0], values[1]);
    record.centre_b_north_east_m = Eigen::Vector2d(values[2], values[3]);
    if (table.has("subframe_id_a") && table.has("subframe_id_b")) {
      record.subframes = table.field(row, "subframe_id_a") + "-" + table.field(row, "subframe_id_b");
    }
    for (auto [prefix, target] : {std::pair{"before_", &record.before}, std::pair{"after_", &record.after}}) {
      const std::string p = prefix;
      const std::vector<std::string> names = {p + "along_m", p + "across_m", p + "depth_m", p + "heading_rad"};
      if (!table.has(names[0])) continue;
      const std::vector<const char*> columns = {names[0].c_str(), names[1].c_str(), names[2].c_str(), names[3].c_str()};
      double offset[4];
      if (!parseNumberColumns(table, row, columns, offset, error)) return false;
      *target = Eigen::Vector4d(offset[0], offset[1], offset[2], offset[3]);
    }
    closures.push_back(std::move(record));
  }
  return true;
}

LoopClosureCounts countClosures(const std::vector<LoopClosureRecord>& closures) {
  LoopClosureCounts counts;
  for (const LoopClosureRecord& r : closures) {
    if (r.status == "accepted") ++counts.accepted;
    else if (r.status == "rejected") {
      ++counts.rejected;
      ++counts.rejection_reasons[r.rejection.empty() ? "unknown" : r.rejection];
    } else if (r.status == "pending") ++counts.pending;
    else ++counts.superseded;
  }
  return counts;
}

bool readRunSummary(const std::string& path, RunSummary& summary, std::string& error) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    error = path + ": cannot open; check the path";
    return false;
  } catch (const YAML::Exception& e) {
    error = path + ":" + std::to_string(e.mark.line + 1) + ": not valid JSON: " + e.msg;
    return false;
  }
  if (!root.IsMap()) {
    error = path + ": expected a JSON object with pings, subframes, closures_accepted, wall_s, ...";
    return false;
  }
  RunSummary result;
  const std::pair<const char*, double*> keys[] = {
      {"pings", &result.pings},
      {"subframes", &result.subframes},
      {"pairs_attempted", &result.pairs_attempted},
      {"closures_accepted", &result.closures_accepted},
      {"closures_rejected", &result.closures_rejected},
      {"wall_s", &result.wall_s},
      {"mission_s", &result.mission_s},
      {"real_time_factor", &result.real_time_factor},
      {"peak_rss_mib", &result.peak_rss_mib}};
  for (const auto& [key, value] : keys) {
    const YAML::Node node = root[key];
    double number = kNaN;
    if (node && node.IsScalar() && parseFiniteDouble(node.Scalar(), number)) {
      *value = number;
    } else {
      result.missing_keys.push_back(key);
    }
  }
  // Optional blocks (older runs lack them): read what is there, quietly.
  const auto optional = [&](const char* block, const char* key, double& value) {
    const YAML::Node node = root[block] ? root[block][key] : YAML::Node();
    double number = kNaN;
    if (node && node.IsScalar() && parseFiniteDouble(node.Scalar(), number)) value = number;
  };
  optional("coverage", "covered_m2", result.covered_m2);
  optional("coverage", "fraction_seen_twice", result.fraction_seen_twice);
  optional("fixes", "fed", result.fixes_fed);
  optional("fixes", "accepted", result.fixes_accepted);
  optional("fixes", "rejected_gate", result.fixes_rejected);
  optional("fixes", "rms_residual_m", result.fixes_rms_residual_m);
  optional("calibration", "dvl_scale", result.dvl_scale);
  optional("calibration", "dvl_scale_sigma", result.dvl_scale_sigma);
  optional("calibration", "heading_bias_rad", result.heading_bias_rad);
  optional("calibration", "heading_bias_sigma_rad", result.heading_bias_sigma_rad);
  if (root["calibration"] && root["calibration"]["estimated"] && root["calibration"]["estimated"].IsScalar()) {
    result.calibration_estimated = root["calibration"]["estimated"].Scalar() == "true";
  }
  if (root["geotiff"] && root["geotiff"].IsMap()) {
    if (root["geotiff"]["crs"] && root["geotiff"]["crs"].IsScalar()) result.geotiff_crs = root["geotiff"]["crs"].Scalar();
    if (root["geotiff"]["files"] && root["geotiff"]["files"].IsSequence()) {
      for (const auto& file : root["geotiff"]["files"]) {
        if (file.IsScalar()) result.geotiffs.push_back(file.Scalar());
      }
    }
  }
  summary = std::move(result);
  return true;
}

// ---- the report ----------------------------------------------------------------------------

RunReport writeRunReport(const RunReportRequest& request, const RunReportOptions& options) {
  RunReport report;
  report.title = request.title;
  if (report.title.empty()) {
    fs::path run = fs::path(request.run_dir).lexically_normal();
    if (run.filename().empty()) run = run.parent_path();  // "dir/"
    report.title = "sss-slam run " + (run.filename().empty() ? request.run_dir : run.filename().string());
  }
  const auto fail = [&](RunReportStatus status, const std::string& error) {
    report.status = status;
    report.error = error;
    return report;
  };
  try {
    // Required: the truth, the SLAM estimate, some DR.
    std::string error;
    if (!fs::is_directory(request.mission_dir)) {
      return fail(RunReportStatus::bad_input, request.mission_dir + ": not a folder (--mission: the sss-sim --out folder)");
    }
    if (!fs::is_directory(request.run_dir)) {
      return fail(RunReportStatus::bad_input, request.run_dir + ": not a folder (--run: the sss-process output folder)");
    }
    report.truth_path = joinPath(request.mission_dir, "ground_truth.tum");
    report.slam_path = joinPath(request.run_dir, "slam.tum");
    report.dr_path = joinPath(request.run_dir, "dead_reckoning.tum");
    Trajectory truth, dr, slam;
    if (!readTrajectoryInput(report.truth_path, "the simulator's ground truth; is --mission the sss-sim --out folder?",
                             truth, error, std::nullopt, &report.truth_origin) ||
        !readTrajectoryInput(report.slam_path, "the SLAM trajectory; is --run the sss-process output folder?", slam,
                             error, report.truth_origin)) {
      return fail(RunReportStatus::bad_input, error);
    }
    if (!fileExists(report.dr_path)) {
      const std::string fallback = joinPath(request.mission_dir, "dead_reckoning.tum");
      if (!fileExists(fallback)) {
        return fail(RunReportStatus::bad_input, report.dr_path + ": missing, and so is " + fallback +
                                                    " (the dead reckoning SLAM is compared with)");
      }
      report.notes.push_back("no dead_reckoning.tum in the run folder; the mission's " + fallback + " stands in for DR");
      report.dr_path = fallback;
    }
    if (!readTrajectoryInput(report.dr_path, "dead reckoning", dr, error, report.truth_origin)) {
      return fail(RunReportStatus::bad_input, error);
    }

    report.truth_poses = truth.size();
    report.duration_s = static_cast<double>(truth.back().utime_us - truth.front().utime_us) * 1e-6;
    report.distance_m = cumulativeDistanceM(truth).back();
    report.lines = segmentSurveyLines(truth, options.trajectory.lines);
    report.dr = evaluateTrajectory(truth, dr, report.lines, options.trajectory);
    if (!report.dr.ok) return fail(RunReportStatus::bad_input, report.dr_path + ": " + report.dr.error);
    report.slam = evaluateTrajectory(truth, slam, report.lines, options.trajectory);
    if (!report.slam.ok) return fail(RunReportStatus::bad_input, report.slam_path + ": " + report.slam.error);
    if (!options.trajectory.rpe.windows_m.empty()) {
      report.rpe_index = closestWindow(options.trajectory.rpe.windows_m, options.rpe_window_m);
      report.rpe_window_m = options.trajectory.rpe.windows_m[report.rpe_index];
    }
    report.ate_improvement_percent = improvementPercent(report.dr.ate.horizontal_m.rmse, report.slam.ate.horizontal_m.rmse);
    report.aligned_ate_improvement_percent =
        improvementPercent(report.dr.ate.aligned_horizontal_m.rmse, report.slam.ate.aligned_horizontal_m.rmse);
    report.gauge_free_ate_improvement_percent =
        improvementPercent(report.dr.ate.gauge_free_horizontal_m.rmse, report.slam.ate.gauge_free_horizontal_m.rmse);

    // Optional inputs: each missing or unusable one becomes a note.
    readHeightmaps(report, request);
    report.closures_path = joinPath(request.run_dir, "loop_closures.csv");
    if (!fileExists(report.closures_path)) {
      report.notes.push_back("no loop_closures.csv in the run folder (" + report.closures_path + "): no closure graph");
    } else if (!readLoopClosures(report.closures_path, report.closures, error)) {
      report.notes.push_back("loop closures unusable, no closure graph: " + error);
    } else {
      report.has_closures = true;
      report.closure_counts = countClosures(report.closures);
      // The same file as sss-eval --closures reads: relative pose errors of the accepted closures.
      std::vector<ClosureRecord> records;
      if (!readClosureCsv(report.closures_path, records, error)) {
        report.notes.push_back("loop closures without relative poses, no closure errors: " + error);
      } else {
        const ClosureEvaluation closures =
            evaluateClosures(records, truth, &dr, options.trajectory.association.max_interpolation_gap_s);
        for (const ClosureGroup& group : closures.groups) {
          if (group.status != "accepted") continue;
          report.has_closure_errors = true;
          report.closure_errors_accepted = group.count;
          report.closure_errors = group.closure;
          report.closure_errors_dr = group.dr;
        }
      }
    }
    if (!report.lines.empty()) {
      // Landmark consistency on correspondences made from the truth (sss-eval --lce).
      HeightmapRaster seabed;
      const std::string seabed_path = joinPath(request.mission_dir, "seabed.yaml");
      const bool have_seabed = fileExists(seabed_path) && readHeightmap(seabed_path, seabed, error, truthFrame(report));
      LandmarkConsistencyOptions model;
      model.seabed_depth_m = flatSeabedDepthM(truth, have_seabed ? &seabed : nullptr, options.lce_altitude_m,
                                              report.lce_seabed_depth_source);
      model.max_interpolation_gap_s = options.trajectory.association.max_interpolation_gap_s;
      const TrueCorrespondences pairs = generateTrueCorrespondences(truth, report.lines, options.lce, model);
      if (!pairs.pairs.empty()) {
        report.has_lce = true;
        report.lce_seabed_depth_m = model.seabed_depth_m;
        report.lce_correspondences = pairs.pairs.size();
        report.lce_truth_max_m = landmarkConsistency(truth, pairs.pairs, model).horizontal_m.max;
        report.lce_dr = landmarkConsistency(dr, pairs.pairs, model).horizontal_m;
        report.lce_slam = landmarkConsistency(slam, pairs.pairs, model).horizontal_m;
      }
    }
    const std::string summary_path = joinPath(request.run_dir, "summary.json");
    if (!fileExists(summary_path)) {
      report.notes.push_back("no summary.json in the run folder (" + summary_path + "): no run figures (time, memory)");
    } else if (!readRunSummary(summary_path, report.summary, error)) {
      report.notes.push_back("run summary unusable: " + error);
    } else {
      report.has_summary = true;
      if (!report.summary.missing_keys.empty()) {
        std::string keys;
        for (const std::string& key : report.summary.missing_keys) keys += (keys.empty() ? "" : ", ") + key;
        report.notes.push_back(summary_path + " lacks numbers for: " + keys);
      }
    }
    GreyMosaic truth_mosaic;
    const GreyMosaic* background = nullptr;
    const std::string mosaic_path = joinPath(request.mission_dir, "mosaic.yaml");
    if (!fileExists(mosaic_path)) {
      report.notes.push_back("no true-pose mosaic (" + mosaic_path + "): trajectories drawn on a blank background");
    } else if (!readMosaic(mosaic_path, truth_mosaic, error)) {
      report.notes.push_back("true-pose mosaic unusable, trajectories drawn on a blank background: " + error);
    } else {
      background = &truth_mosaic;
    }
    makeVerdict(report, options);

    // Outputs.
    std::error_code ec;
    fs::create_directories(request.out_dir, ec);
    if (ec || !fs::is_directory(request.out_dir)) {
      return fail(RunReportStatus::write_failed,
                  "cannot create " + request.out_dir + (ec ? ": " + ec.message() : std::string()));
    }
    std::vector<Section> sections;
    FigureContext context{request, report, sections};
    trajectoryFigures(context, truth, background);
    closureFigure(context, background);
    mosaicFigure(context);
    heightmapFigures(context);
    productsSection(context);

    const Table key = keyTable(report, options);
    const std::vector<Table> tables = metricTables(report, options);
    std::vector<std::string> inputs = {report.truth_path, report.dr_path, report.slam_path};
    if (report.has_closures) inputs.push_back(report.closures_path);
    if (!report.seabed_path.empty()) inputs.push_back(report.seabed_path);
    for (const RunHeightmap* h : {&report.heightmap_dr, &report.heightmap_slam}) {
      if (h->present) inputs.push_back(h->path);
    }
    if (background) inputs.push_back(mosaic_path);
    if (report.has_summary) inputs.push_back(summary_path);

    const std::string html_path = joinPath(request.out_dir, "index.html");
    const std::string md_path = joinPath(request.out_dir, "report.md");
    const std::string json_path = joinPath(request.out_dir, "metrics.json");
    // Files listed before they are written, so metrics.json lists itself and both pages.
    for (const std::string& path : {html_path, md_path, json_path}) report.files.push_back(path);
    report.index_html = html_path;
    if (!writeText(html_path, renderHtml(report, request, key, sections, tables, inputs), error) ||
        !writeText(md_path, renderMarkdown(report, request, key, sections, tables, inputs), error) ||
        !writeText(json_path, runReportJson(report, request), error)) {
      return fail(RunReportStatus::write_failed, error);
    }
  } catch (const std::bad_alloc&) {
    return fail(RunReportStatus::bad_input, "out of memory; are the inputs the right files?");
  } catch (const std::exception& e) {
    return fail(RunReportStatus::bad_input, e.what());
  }
  return report;
}

std::string formatRunTable(const RunReport& report) {
  std::vector<std::vector<std::string>> rows = {{"", "DR", "SLAM", "improvement"}};
  rows.push_back({"horizontal ATE RMSE", metres(report.dr.ate.horizontal_m.rmse), metres(report.slam.ate.horizontal_m.rmse),
                  percent(report.ate_improvement_percent, true)});
  rows.push_back({"  SE(3)-aligned", metres(report.dr.ate.aligned_horizontal_m.rmse),
                  metres(report.slam.ate.aligned_horizontal_m.rmse), percent(report.aligned_ate_improvement_percent, true)});
  rows.push_back({"  gauge-free", metres(report.dr.ate.gauge_free_horizontal_m.rmse),
                  metres(report.slam.ate.gauge_free_horizontal_m.rmse),
                  percent(report.gauge_free_ate_improvement_percent, true)});
  if (report.has_lce) {
    rows.push_back({"LCE mean", metres(report.lce_dr.mean), metres(report.lce_slam.mean),
                    percent(improvementPercent(report.lce_dr.mean, report.lce_slam.mean), true)});
  }
  rows.push_back({"heightmap MAE", report.heightmap_dr.present ? metres(report.heightmap_dr.error.abs_error_m.mean) : "-",
                  report.heightmap_slam.present ? metres(report.heightmap_slam.error.abs_error_m.mean) : "-",
                  percent(report.heightmap_improvement_percent, true)});
  std::string out = report.title + "\n" + report.verdict + "\n\n" + formatColumns(rows);
  // Free-text rows under the table, their values starting at its second column.
  const size_t indent = std::string("horizontal ATE RMSE").size() + 2;
  const auto line = [&](const std::string& label, const std::string& value) {
    out += label + std::string(indent > label.size() ? indent - label.size() : 1, ' ') + value + "\n";
  };
  line("closures", closureSummaryText(report));
  if (report.has_summary) line("real-time factor", realTimeText(report.summary));
  line("report", report.index_html);
  return out;
}

std::string runReportJson(const RunReport& report, const RunReportRequest& request) {
  JsonWriter json;
  json.beginObject();
  json.key("schema").value("sss-report/1");
  json.key("title").value(report.title);
  json.key("mission_dir").value(request.mission_dir);
  json.key("run_dir").value(request.run_dir);
  json.key("out_dir").value(request.out_dir);
  json.key("verdict").value(report.verdict);
  json.key("outcome").value(report.outcome);

  json.key("trajectory").beginObject();
  json.key("truth_path").value(report.truth_path);
  json.key("truth_poses").value(static_cast<uint64_t>(report.truth_poses));
  json.key("duration_s").value(report.duration_s);
  json.key("distance_m").value(report.distance_m);
  json.key("lines").beginArray();
  for (const SurveyLine& line : report.lines) {
    json.beginObject();
    json.key("index").value(line.index);
    json.key("length_m").value(line.length_m);
    json.key("heading_deg").value(line.heading_deg);
    json.endObject();
  }
  json.endArray();
  json.key("rpe_window_m").value(report.rpe_window_m);
  for (const auto& [key, path, evaluation] :
       {std::tuple{"dr", report.dr_path, &report.dr}, std::tuple{"slam", report.slam_path, &report.slam}}) {
    json.key(key).beginObject();
    json.key("path").value(path);
    json.key("poses").value(static_cast<uint64_t>(evaluation->estimate_poses));
    json.key("matched").value(static_cast<uint64_t>(evaluation->association.pairs.size()));
    writeErrorStatistics(json, "ate_horizontal_m", evaluation->ate.horizontal_m);
    writeErrorStatistics(json, "ate_aligned_horizontal_m", evaluation->ate.aligned_horizontal_m);
    writeErrorStatistics(json, "ate_gauge_free_horizontal_m", evaluation->ate.gauge_free_horizontal_m);
    json.key("gauge_free_scale").value(evaluation->ate.gauge_free_scale);
    json.key("gauge_free_rotation_deg").value(evaluation->ate.gauge_free_rotation_deg);
    writeErrorStatistics(json, "ate_position_m", evaluation->ate.position_m);
    const bool has_rpe = report.rpe_index < evaluation->rpe.size();
    json.key("rpe_translation_percent").value(has_rpe ? evaluation->rpe[report.rpe_index].translation_percent.mean : kNaN);
    json.key("rpe_rotation_deg").value(has_rpe ? evaluation->rpe[report.rpe_index].rotation_deg.mean : kNaN);
    json.key("lines").beginArray();
    for (const LineError& line : evaluation->lines) {
      json.beginObject();
      json.key("index").value(line.line);
      json.key("horizontal_rmse_m").value(line.horizontal_m.rmse);
      json.endObject();
    }
    json.endArray();
    json.endObject();
  }
  json.key("ate_horizontal_rmse_improvement_percent").value(report.ate_improvement_percent);
  json.key("ate_aligned_horizontal_rmse_improvement_percent").value(report.aligned_ate_improvement_percent);
  json.key("ate_gauge_free_horizontal_rmse_improvement_percent").value(report.gauge_free_ate_improvement_percent);
  json.endObject();

  if (report.heightmap_dr.present || report.heightmap_slam.present) {
    json.key("heightmap").beginObject();
    json.key("seabed_path").value(report.seabed_path);
    for (const auto& [key, entry] : {std::pair{"dr", &report.heightmap_dr}, std::pair{"slam", &report.heightmap_slam}}) {
      if (!entry->present) {
        json.key(key).null();
        continue;
      }
      const HeightmapErrorResult& r = entry->error;
      json.key(key).beginObject();
      json.key("path").value(entry->path);
      json.key("mae_m").value(r.abs_error_m.mean);
      json.key("rmse_m").value(r.abs_error_m.rmse);
      json.key("median_m").value(r.abs_error_m.median);
      json.key("max_m").value(r.abs_error_m.max);
      json.key("bias_m").value(r.mean_signed_error_m);
      json.key("coverage_fraction").value(r.coverage_fraction);
      json.key("compared_cells").value(static_cast<uint64_t>(r.compared_cells));
      json.endObject();
    }
    json.key("mae_improvement_percent").value(report.heightmap_improvement_percent);
    json.endObject();
  } else {
    json.key("heightmap").null();
  }

  if (report.has_closures) {
    const LoopClosureCounts& c = report.closure_counts;
    json.key("closures").beginObject();
    json.key("path").value(report.closures_path);
    json.key("accepted").value(static_cast<uint64_t>(c.accepted));
    json.key("rejected").value(static_cast<uint64_t>(c.rejected));
    json.key("pending").value(static_cast<uint64_t>(c.pending));
    json.key("superseded").value(static_cast<uint64_t>(c.superseded));
    json.key("total").value(static_cast<uint64_t>(c.total()));
    json.key("rejection_reasons").beginObject();
    for (const auto& [reason, n] : c.rejection_reasons) json.key(reason).value(static_cast<uint64_t>(n));
    json.endObject();
    json.endObject();
  } else {
    json.key("closures").null();
  }

  if (report.has_closure_errors) {
    json.key("closure_errors").beginObject();
    json.key("accepted").value(static_cast<uint64_t>(report.closure_errors_accepted));
    writeRelativePoseErrorStatistics(json, "closure", report.closure_errors);
    writeRelativePoseErrorStatistics(json, "dr", report.closure_errors_dr);
    json.endObject();
  } else {
    json.key("closure_errors").null();
  }
  if (report.has_lce) {
    json.key("lce").beginObject();
    json.key("seabed_depth_m").value(report.lce_seabed_depth_m);
    json.key("seabed_depth_source").value(report.lce_seabed_depth_source);
    json.key("correspondences").value(static_cast<uint64_t>(report.lce_correspondences));
    json.key("truth_max_m").value(report.lce_truth_max_m);
    writeErrorStatistics(json, "dr", report.lce_dr);
    writeErrorStatistics(json, "slam", report.lce_slam);
    json.key("mean_improvement_percent").value(improvementPercent(report.lce_dr.mean, report.lce_slam.mean));
    json.endObject();
  } else {
    json.key("lce").null();
  }

  if (report.has_summary) {
    const RunSummary& s = report.summary;
    json.key("run").beginObject();
    json.key("pings").value(s.pings);
    json.key("subframes").value(s.subframes);
    json.key("pairs_attempted").value(s.pairs_attempted);
    json.key("closures_accepted").value(s.closures_accepted);
    json.key("closures_rejected").value(s.closures_rejected);
    json.key("wall_s").value(s.wall_s);
    json.key("mission_s").value(s.mission_s);
    json.key("real_time_factor").value(s.real_time_factor);
    json.key("peak_rss_mib").value(s.peak_rss_mib);
    json.endObject();
  } else {
    json.key("run").null();
  }

  json.key("notes").beginArray();
  for (const std::string& note : report.notes) json.value(note);
  json.endArray();
  json.key("files").beginArray();
  for (const std::string& file : report.files) json.value(file);
  json.endArray();
  json.endObject();
  return json.str() + "\n";
}

}  // namespace sss::eval
