// sss-eval runs: inputs -> metrics -> table, JSON, figures. See report.hpp.
#include "tools/eval/report.hpp"

#include "tools/eval/figure_script.hpp"
#include "tools/eval/json_values.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace sss::eval {

using sss::core::Status;
namespace {

std::string defaultLabel(const EvalInput& input) {
  if (!input.label.empty()) return input.label;
  return std::filesystem::path(input.path).stem().string();
}

// printf-style cell: fixed decimals, "-" for NaN.
std::string cell(double value, int decimals) {
  if (!std::isfinite(value)) return "-";
  char text[48];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

size_t tableRpeIndex(const EvalReport& report) {
  const std::vector<double>& windows = report.options.trajectory.rpe.windows_m;
  size_t best = 0;
  for (size_t k = 1; k < windows.size(); ++k) {
    if (std::abs(windows[k] - report.options.table_rpe_window_m) <
        std::abs(windows[best] - report.options.table_rpe_window_m)) {
      best = k;
    }
  }
  return best;
}

std::vector<std::string> closureStatisticsCells(const RelativePoseErrorStatistics& s) {
  return {cell(s.along_m.abs.rmse, 3),     cell(s.along_m.abs.max, 3),     cell(s.lateral_m.abs.rmse, 3),
          cell(s.lateral_m.abs.max, 3),   cell(s.depth_m.abs.rmse, 3),    cell(s.depth_m.abs.max, 3),
          cell(s.heading_deg.abs.rmse, 3), cell(s.heading_deg.abs.max, 3), cell(s.horizontal_m.rmse, 3)};
}

std::vector<std::string> closureErrorCells(bool present, const RelativePoseError& e) {
  if (!present) return {"-", "-", "-", "-"};
  return {cell(e.along_m, 3), cell(e.lateral_m, 3), cell(e.depth_m, 3), cell(e.heading_rad * 180.0 / M_PI, 3)};
}

std::string formatClosureTable(const EvalReport& report) {
  const ClosureEvaluation& ev = report.closures.evaluation;
  const std::string dr_label = report.closures.dr.path.empty() ? "" : report.closures.dr.label;
  std::ostringstream out;
  out << "loop closures " << report.closures.path << ": " << ev.closures.size() << " (" << ev.without_truth
      << " outside the truth" << (dr_label.empty() ? ", no DR" : ", " + std::to_string(ev.without_dr) + " outside DR")
      << "); error = relative pose - truth's, in A's body frame (x along, y lateral, z depth)\n";
  std::vector<std::vector<std::string>> rows = {
      {"status", "n", "source", "along", "along", "lateral", "lateral", "depth", "depth", "heading", "heading", "horiz"},
      {"", "", "", "RMS m", "max m", "RMS m", "max m", "RMS m", "max m", "RMS deg", "max deg", "RMS m"}};
  for (const ClosureGroup& g : ev.groups) {
    std::vector<std::string> row = {g.status, std::to_string(g.count), "closure"};
    for (const std::string& c : closureStatisticsCells(g.closure)) row.push_back(c);
    rows.push_back(row);
    if (dr_label.empty()) continue;
    row = {"", std::to_string(g.dr.horizontal_m.count), dr_label};
    for (const std::string& c : closureStatisticsCells(g.dr)) row.push_back(c);
    rows.push_back(row);
  }
  out << formatColumns(rows);
  std::string nees;
  for (const ClosureGroup& g : ev.groups) {
    if (g.nees_count) nees += " " + g.status + " " + cell(g.mean_horizontal_nees, 2) + " (" + std::to_string(g.nees_count) + ")";
  }
  if (!nees.empty()) out << "mean horizontal NEES under the closures' own covariance (2 when consistent):" << nees << "\n";
  if (report.options.closure_table) {
    std::vector<std::vector<std::string>> list = {
        {"closure a-b", "round", "status", "true dx", "true dy", "along", "lateral", "depth", "heading"},
        {"", "", "", "m", "m", "err m", "err m", "err m", "err deg"}};
    // The closure's own sigmas and its horizontal NEES, when the file carries its covariance.
    bool any_covariance = false;
    for (const ClosureError& e : ev.closures) any_covariance = any_covariance || e.closure.has_covariance;
    if (any_covariance) {
      for (const char* name : {"sigma", "sigma", "NEES"}) list[0].push_back(name);
      for (const char* unit : {"along m", "lat. m", "horiz."}) list[1].push_back(unit);
    }
    if (!dr_label.empty()) {
      for (const char* name : {"DR along", "DR lateral", "DR depth", "DR heading"}) list[0].push_back(name);
      for (const char* unit : {"err m", "err m", "err m", "err deg"}) list[1].push_back(unit);
    }
    for (const ClosureError& e : ev.closures) {
      const ClosureRecord& c = e.closure;
      std::vector<std::string> row = {std::to_string(c.subframe_id_a) + "-" + std::to_string(c.subframe_id_b),
                                      c.round < 0 ? "-" : std::to_string(c.round), c.status,
                                      e.has_truth ? cell(e.truth.translation_m.x(), 2) : "-",
                                      e.has_truth ? cell(e.truth.translation_m.y(), 2) : "-"};
      for (const std::string& v : closureErrorCells(e.has_truth, e.closure_error)) row.push_back(v);
      if (any_covariance) {
        for (const double value : {c.sigmaM(0), c.sigmaM(1)}) row.push_back(std::isfinite(value) ? cell(value, 2) : "-");
        row.push_back(std::isfinite(e.horizontal_nees) ? cell(e.horizontal_nees, 1) : "-");
      }
      if (!dr_label.empty()) {
        for (const std::string& v : closureErrorCells(e.has_dr, e.dr_error)) row.push_back(v);
      }
      list.push_back(row);
    }
    out << "\n" << formatColumns(list);
  }
  return out.str();
}

std::string formatLceTable(const LceReport& lce, const TrueCorrespondenceOptions& options) {
  char summary[512];
  std::snprintf(summary, sizeof summary,
                "landmark consistency error (LCE): %zu correspondences (of %zu) from %zu seabed points seen from 2+ "
                "lines; grid %.1f m, swath %.0f-%.0f m, flat seabed at %.2f m (%s)\n",
                lce.correspondences.pairs.size(), lce.correspondences.candidate_pairs,
                lce.correspondences.seabed_points, options.grid_m, options.min_ground_range_m,
                options.max_ground_range_m, lce.seabed_depth_m, lce.seabed_depth_source.c_str());
  std::vector<std::vector<std::string>> rows = {{"trajectory", "pairs", "skipped", "mean", "RMSE", "median", "max"},
                                                {"", "", "", "m", "m", "m", "m"}};
  std::vector<const LceEntry*> entries = {&lce.truth};
  for (const LceEntry& e : lce.estimates) entries.push_back(&e);
  for (const LceEntry* e : entries) {
    const ErrorStatistics& h = e->result.horizontal_m;
    rows.push_back({e->label, std::to_string(h.count), std::to_string(e->result.skipped), cell(h.mean, 3),
                    cell(h.rmse, 3), cell(h.median, 3), cell(h.max, 3)});
  }
  return summary + formatColumns(rows);
}

std::string withSuffix(const std::string& png_path, const std::string& suffix) {
  const std::string stem = png_path.substr(0, png_path.size() - 4);  // checked to end in .png
  return stem + suffix + ".png";
}

}  // namespace

std::string fileSafeLabel(const std::string& label) {
  std::string safe = label;
  for (char& c : safe) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
                    c == '-';
    if (!ok) c = '_';
  }
  return safe.empty() ? "unnamed" : safe;
}

Status runEvaluation(const EvalRequest& request, const EvalOptions& options, EvalReport& report) {
  report = EvalReport();
  report.options = options;
  report.truth_path = request.truth_path;
  // Everything is compared in the truth's frame: a file whose header names another origin (a run
  // with its own origin, the first fix) is re-expressed in it.
  std::optional<sss::core::MissionOrigin> truth_origin;
  if (!request.estimates.empty() || !request.closures_path.empty() || request.lce) {
    if (request.truth_path.empty()) {
      return Status::error("estimates, closures and LCE need the truth trajectory (--gt TRUTH.tum)");
    }
    TumReadResult truth = readTum(request.truth_path);
    if (!truth.ok) {
      return Status::error(truth.error);
    }
    report.truth = std::move(truth.poses);
    truth_origin = truth.origin;
    const std::vector<double> distance = cumulativeDistanceM(report.truth);
    report.truth_distance_m = distance.back();
    report.lines = segmentSurveyLines(report.truth, options.trajectory.lines);
  }
  std::vector<Trajectory> estimates;  // kept for the closures' DR and the LCE
  for (const EvalInput& input : request.estimates) {
    TumReadOptions in_truth_frame;
    in_truth_frame.target_origin = truth_origin;
    TumReadResult estimate = readTum(input.path, in_truth_frame);
    if (!estimate.ok) {
      return Status::error(estimate.error);
    }
    EstimateReport entry;
    entry.input = {defaultLabel(input), input.path};
    entry.evaluation = evaluateTrajectory(report.truth, estimate.poses, report.lines, options.trajectory);
    if (!entry.evaluation.ok) {
      return Status::error(input.path + ": " + entry.evaluation.error);
    }
    report.estimates.push_back(std::move(entry));
    estimates.push_back(std::move(estimate.poses));
  }
  if (!report.estimates.empty()) {
    const double first = report.estimates.front().evaluation.ate.horizontal_m.rmse;
    for (size_t i = 1; i < report.estimates.size(); ++i) {
      const double value = report.estimates[i].evaluation.ate.horizontal_m.rmse;
      if (first > 0.0) report.estimates[i].improvement_vs_first_percent = 100.0 * (first - value) / first;
    }
  }

  HeightmapRaster seabed;
  const bool lce_needs_seabed = request.lce && !std::isfinite(options.lce_seabed_depth_m) && !request.seabed_path.empty();
  if (!request.heightmaps.empty() || lce_needs_seabed) {
    if (request.seabed_path.empty()) {
      return Status::error("heightmaps need the true seabed (--seabed seabed.yaml)");
    }
    if (const Status read = readHeightmap(request.seabed_path, seabed); !read) {
      return read;
    }
  }
  HeightmapReadOptions in_seabed_frame;
  in_seabed_frame.target_origin = seabed.origin ? seabed.origin : truth_origin;
  if (!request.heightmaps.empty()) {
    for (const EvalInput& input : request.heightmaps) {
      HeightmapRaster estimate;
      if (const Status read = readHeightmap(input.path, estimate, in_seabed_frame); !read) {
        return read;
      }
      HeightmapReport entry;
      entry.input = {defaultLabel(input), input.path};
      entry.result = compareHeightmaps(seabed, estimate);
      if (!entry.result.ok) {
        return Status::error(input.path + ": " + entry.result.error);
      }
      report.heightmaps.push_back(std::move(entry));
    }
  }

  if (!request.closures_path.empty()) {
    std::vector<ClosureRecord> closures;
    if (const Status read = readClosureCsv(request.closures_path, closures); !read) {
      return read;
    }
    report.has_closures = true;
    report.closures.path = request.closures_path;
    Trajectory dr;
    if (!request.closures_dr_path.empty()) {
      TumReadOptions in_truth_frame;
      in_truth_frame.target_origin = truth_origin;
      TumReadResult read = readTum(request.closures_dr_path, in_truth_frame);
      if (!read.ok) {
        return Status::error(read.error);
      }
      dr = std::move(read.poses);
      report.closures.dr = {defaultLabel({"", request.closures_dr_path}), request.closures_dr_path};
    } else if (!estimates.empty()) {
      dr = estimates.front();
      report.closures.dr = report.estimates.front().input;
    }
    const double max_gap_s = options.trajectory.association.max_interpolation_gap_s;
    report.closures.evaluation = evaluateClosures(closures, report.truth, dr.empty() ? nullptr : &dr, max_gap_s);
  }

  if (request.lce && report.lines.empty() && request.lce_optional) {
    report.lce_skipped = "no survey lines found in the truth (LCE needs straight lines seen from both sides)";
  } else if (request.lce) {
    if (report.lines.empty()) {
      return Status::error(request.truth_path +
                           ": no survey lines found in the truth; --lce needs straight lines seen from both sides");
    }
    LceReport& lce = report.lce;
    if (std::isfinite(options.lce_seabed_depth_m)) {
      lce.seabed_depth_m = options.lce_seabed_depth_m;
      lce.seabed_depth_source = "--lce-seabed-depth-m";
    } else {
      lce.seabed_depth_m = flatSeabedDepthM(report.truth, lce_needs_seabed ? &seabed : nullptr,
                                            options.lce_default_altitude_m, lce.seabed_depth_source);
      if (lce_needs_seabed) lce.seabed_depth_source += " " + request.seabed_path;
    }
    LandmarkConsistencyOptions model;
    model.seabed_depth_m = lce.seabed_depth_m;
    model.max_interpolation_gap_s = options.trajectory.association.max_interpolation_gap_s;
    lce.correspondences = generateTrueCorrespondences(report.truth, report.lines, options.lce, model);
    lce.truth = {"truth (self-check)", landmarkConsistency(report.truth, lce.correspondences.pairs, model)};
    for (size_t i = 0; i < estimates.size(); ++i) {
      lce.estimates.push_back({report.estimates[i].input.label,
                               landmarkConsistency(estimates[i], lce.correspondences.pairs, model)});
    }
    report.has_lce = true;
  }
  return Status::success();
}

Status writeFigures(const EvalRequest& request, EvalReport& report) {
  // The PNGs are drawn by report_figures.py from X_figure_data/ beside X.png (figure_script.hpp).
  const std::filesystem::path plot(request.plot_path);
  const std::string out_dir = plot.parent_path().empty() ? "." : plot.parent_path().string();
  FigureBatch figures;
  if (!request.plot_path.empty()) {  // X.png -> X_figure_data (checked to end in .png)
    figures.data_dir = request.plot_path.substr(0, request.plot_path.size() - 4) + "_figure_data";
  }
  std::vector<std::string> paths;  // each figure's path as --plot names it
  const auto add = [&](const std::string& kind, const std::string& suffix, const std::string& title) -> Json& {
    paths.push_back(withSuffix(request.plot_path, suffix));
    return addFigure(figures, kind, std::filesystem::path(paths.back()).filename().string(), title);
  };
  if (!request.plot_path.empty() && !report.estimates.empty()) {
    const std::string title = "Trajectories (north/east), truth: " + std::filesystem::path(report.truth_path).filename().string();
    Json& map = add("map", "", title);
    map["lines"] = Json::array();
    for (size_t i = 0; i < report.estimates.size(); ++i) {
      const EstimateReport& e = report.estimates[i];
      std::vector<Eigen::Vector2d> points;
      for (const AssociatedPose& p : e.evaluation.association.pairs) points.push_back(p.estimate.translation.head<2>());
      map["lines"].push_back(mapLine(e.input.label, points, paletteColour(static_cast<int>(i))));
    }
    // Truth last so it stays visible on top of estimates that follow it closely.
    std::vector<Eigen::Vector2d> truth;
    for (const StampedPose& p : report.truth) truth.push_back(p.T_world_body.translation.head<2>());
    map["lines"].push_back(mapLine("truth", truth, "black", 1.2, true, true));

    // Error over time since the truth's first pose, in minutes; survey lines shaded.
    const int64_t t0 = report.truth.front().utime_us;
    Json& curves = add("curves", "_error", "Horizontal position error over the mission");
    curves["x_label"] = "time since start (min)";
    curves["y_label"] = "horizontal error (m)";
    curves["curves"] = Json::array();
    for (size_t i = 0; i < report.estimates.size(); ++i) {
      const EstimateReport& e = report.estimates[i];
      for (Json& curve : horizontalErrorCurves(e.input.label, e.evaluation.series, paletteColour(static_cast<int>(i)), t0))
        curves["curves"].push_back(std::move(curve));
    }
    curves["bands"] = surveyLineBands(report.lines, t0);
  }
  for (HeightmapReport& h : report.heightmaps) {
    const std::string safe = fileSafeLabel(h.input.label);
    if (!request.error_map_prefix.empty()) {
      const std::string prefix = request.error_map_prefix + "_" + safe;
      if (const Status written = writeHeightmap(prefix, h.result.error_map); !written) {
        return written;
      }
      h.error_map_yaml = prefix + ".yaml";
    }
    if (!request.plot_path.empty()) {
      char title[256];
      std::snprintf(title, sizeof title, "Heightmap error %s: MAE %.3f m over %.1f %% coverage", h.input.label.c_str(),
                    h.result.abs_error_m.mean, 100.0 * h.result.coverage_fraction);
      Json& figure = add("error_map", "_heightmap_" + safe, title);
      figure["raster"] = heightmapRaster(figures, h.result.error_map, "heightmap_error_" + safe);
      figure["limit_m"] = report.options.error_map_limit_m;  // <= 0: the script picks the p99
      h.error_map_png = paths.back();
    }
  }
  const FigureRun run = drawFigures(figures, out_dir, request.figures);
  const auto drawn = [&](const std::string& path) {
    const std::string file = std::filesystem::path(path).filename().string();
    return std::find(run.missing.begin(), run.missing.end(), file) == run.missing.end();
  };
  for (const std::string& path : paths) {
    if (drawn(path)) report.plots.push_back(path);
  }
  for (HeightmapReport& h : report.heightmaps) {
    if (!h.error_map_png.empty() && !drawn(h.error_map_png)) h.error_map_png.clear();
  }
  if (!run.problem.empty()) {
    return Status::error(run.problem);
  }
  return Status::success();
}

namespace {

std::vector<std::string> matchRow(const std::string& label, long pairs, const MatchEvaluation& e) {
  return {label, std::to_string(pairs), std::to_string(e.matches), std::to_string(e.evaluated),
          e.evaluated ? cell(e.meanErrorPx(), 2) : "-", e.evaluated ? cell(e.meanErrorM(), 3) : "-",
          e.evaluated ? cell(e.withinFraction(), 3) : "-", e.matchable ? cell(e.recall(), 3) : "-",
          e.evaluated ? cell(e.meanAlongErrorM(), 3) : "-", e.evaluated ? cell(e.meanOutwardErrorM(), 3) : "-"};
}

std::string formatMatchTable(const MatchFileEvaluation& m, bool per_pair) {
  std::ostringstream out;
  char title[512];
  std::snprintf(title, sizeof title,
                "matches %s against %s: %zu pairs (all rounds), %zu subframes; px of the matching image "
                "(1 ping x %.2f m)\n",
                m.path.c_str(), m.mission_dir.c_str(), m.pairs.size(), m.subframes, m.matching_pixel_m);
  out << title;
  std::vector<std::vector<std::string>> rows = {
      {"pair type", "pairs", "matches", "evaluated", "mean EPE", "mean EPE", "within", "recall", "bias along", "bias outward"},
      {"", "", "", "", "px", "m", "2 px", "2 px", "m", "m"}};
  for (int t = 0; t < kPairTypes; ++t) {
    rows.push_back(matchRow(pairTypeName(static_cast<PairType>(t)), m.pairs_by_type[t], m.by_type[t]));
  }
  rows.push_back(matchRow("all", static_cast<long>(m.pairs.size()), m.overall));
  out << formatColumns(rows);
  if (per_pair && !m.pairs.empty()) {
    std::vector<std::vector<std::string>> pair_rows = {
        {"pair", "round", "type", "matches", "evaluated", "EPE px", "EPE m", "within 2 px", "recall 2 px", "bias along m",
         "bias outward m"}};
    for (const PairMatchReport& p : m.pairs) {
      // matchRow's pair count becomes the round, followed by the type.
      std::vector<std::string> row = matchRow(std::to_string(p.subframe_a) + "-" + std::to_string(p.subframe_b), 0,
                                              p.evaluation);
      row[1] = std::to_string(p.round);
      row.insert(row.begin() + 2, pairTypeName(p.type));
      pair_rows.push_back(row);
    }
    out << "\n" << formatColumns(pair_rows);
  }
  return out.str();
}

}  // namespace

std::string formatTable(const EvalReport& report) {
  std::ostringstream out;
  if (!report.truth.empty()) {
    char summary[512];
    std::snprintf(summary, sizeof summary, "truth %s: %zu poses, %.1f s, %.0f m, %zu survey lines\n",
                  report.truth_path.c_str(), report.truth.size(),
                  static_cast<double>(report.truth.back().utime_us - report.truth.front().utime_us) * 1e-6,
                  report.truth_distance_m, report.lines.size());
    out << summary;
  }
  if (!report.estimates.empty()) {
    const size_t rpe_index = tableRpeIndex(report);
    const std::string rpe_window = report.options.trajectory.rpe.windows_m.empty()
                                       ? "RPE"
                                       : "RPE " + cell(report.options.trajectory.rpe.windows_m[rpe_index], 0) + " m";
    std::vector<std::vector<std::string>> rows = {
        {"estimate", "poses", "ATE raw", "ATE aligned", "horiz ATE", "horiz max", "horiz al.", "horiz g-free",
         rpe_window, rpe_window, "vs first"},
        {"", "matched", "RMSE m", "RMSE m", "RMSE m", "m", "RMSE m", "RMSE m", "mean %", "mean deg", "horiz %"}};
    for (const EstimateReport& e : report.estimates) {
      const TrajectoryEvaluation& ev = e.evaluation;
      const RpeResult* rpe = ev.rpe.empty() ? nullptr : &ev.rpe[rpe_index];
      rows.push_back({e.input.label, std::to_string(ev.association.pairs.size()) + "/" + std::to_string(ev.estimate_poses),
                      cell(ev.ate.position_m.rmse, 3), cell(ev.ate.aligned_position_m.rmse, 3),
                      cell(ev.ate.horizontal_m.rmse, 3), cell(ev.ate.horizontal_m.max, 3),
                      cell(ev.ate.aligned_horizontal_m.rmse, 3), cell(ev.ate.gauge_free_horizontal_m.rmse, 3),
                      rpe ? cell(rpe->translation_percent.mean, 3) : "-", rpe ? cell(rpe->rotation_deg.mean, 3) : "-",
                      std::isfinite(e.improvement_vs_first_percent) ? cell(e.improvement_vs_first_percent, 1) : "-"});
    }
    out << "\n" << formatColumns(rows);
    // What no relative measurement sees: the rotation and scale about each estimate's start.
    out << "\ngauge-free horizontal ATE: after the best rotation (clockwise +) and scale about the estimate's first "
           "position, no shift;\ngauge = the raw error they explain (raw^2 = gauge^2 + gauge-free^2)\n";
    std::vector<std::vector<std::string>> gauge_rows = {
        {"estimate", "rotation", "scale", "gauge", "gauge-free", "gauge-free", "gauge-free"},
        {"", "deg", "", "RMSE m", "RMSE m", "mean m", "max m"}};
    for (const EstimateReport& e : report.estimates) {
      const AteResult& ate = e.evaluation.ate;
      gauge_rows.push_back({e.input.label, cell(ate.gauge_free_rotation_deg, 4), cell(ate.gauge_free_scale, 5),
                            cell(ate.gauge_horizontal_m.rmse, 3), cell(ate.gauge_free_horizontal_m.rmse, 3),
                            cell(ate.gauge_free_horizontal_m.mean, 3), cell(ate.gauge_free_horizontal_m.max, 3)});
    }
    out << formatColumns(gauge_rows);
    if (!report.lines.empty()) {
      out << "\nhorizontal ATE RMSE per survey line (m, raw)\n";
      std::vector<std::vector<std::string>> line_rows(1);
      line_rows[0].push_back("estimate");
      for (const SurveyLine& line : report.lines) {
        line_rows[0].push_back("L" + std::to_string(line.index) + " " + cell(line.heading_deg, 0) + "deg");
      }
      for (const EstimateReport& e : report.estimates) {
        std::vector<std::string> row = {e.input.label};
        for (const SurveyLine& line : report.lines) {
          std::string value = "-";
          for (const LineError& l : e.evaluation.lines) {
            if (l.line == line.index) value = cell(l.horizontal_m.rmse, 3);
          }
          row.push_back(value);
        }
        line_rows.push_back(row);
      }
      out << formatColumns(line_rows);
    }
  }
  if (!report.heightmaps.empty()) {
    std::vector<std::vector<std::string>> rows = {
        {"heightmap", "cells", "coverage", "MAE", "RMSE", "median", "max", "bias"},
        {"", "compared", "%", "m", "m", "m", "m", "m"}};
    for (const HeightmapReport& h : report.heightmaps) {
      const HeightmapErrorResult& r = h.result;
      rows.push_back({h.input.label, std::to_string(r.compared_cells), cell(100.0 * r.coverage_fraction, 1),
                      cell(r.abs_error_m.mean, 3), cell(r.abs_error_m.rmse, 3), cell(r.abs_error_m.median, 3),
                      cell(r.abs_error_m.max, 3), cell(r.mean_signed_error_m, 3)});
    }
    out << "\n" << formatColumns(rows);
  }
  if (report.has_closures) out << "\n" << formatClosureTable(report);
  if (report.has_lce) out << "\n" << formatLceTable(report.lce, report.options.lce);
  if (!report.lce_skipped.empty()) out << "\nlandmark consistency error (LCE) skipped: " << report.lce_skipped << "\n";
  if (report.has_matches) out << "\n" << formatMatchTable(report.matches, report.options.match_table);
  return out.str();
}


std::string formatColumns(const std::vector<std::vector<std::string>>& rows) {
  std::vector<size_t> width;
  for (const auto& row : rows) {
    if (width.size() < row.size()) width.resize(row.size(), 0);
    for (size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], row[c].size());
  }
  std::string out;
  for (const auto& row : rows) {
    std::string line;
    for (size_t c = 0; c < row.size(); ++c) {
      const std::string padding(width[c] - row[c].size(), ' ');
      line += c == 0 ? row[c] + padding : "  " + padding + row[c];
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line + "\n";
  }
  return out;
}

}  // namespace sss::eval
