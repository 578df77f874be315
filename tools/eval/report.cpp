// sss-eval runs: inputs -> metrics -> table, JSON, figures. See report.hpp.
#include "tools/eval/report.hpp"

#include "tools/eval/json_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace sss::eval {
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

void writeRelativePoseError(JsonWriter& json, const std::string& key, bool present, const RelativePoseError& e) {
  if (!present) {
    json.key(key).null();
    return;
  }
  json.key(key).beginObject();
  json.key("along_m").value(e.along_m);
  json.key("lateral_m").value(e.lateral_m);
  json.key("depth_m").value(e.depth_m);
  json.key("heading_deg").value(e.heading_rad * 180.0 / M_PI);
  json.endObject();
}

void writeClosuresJson(JsonWriter& json, const ClosureReport& closures) {
  const ClosureEvaluation& ev = closures.evaluation;
  json.key("closures").beginObject();
  json.key("path").value(closures.path);
  if (closures.dr.path.empty()) {
    json.key("dr").null();
  } else {
    json.key("dr").beginObject();
    json.key("label").value(closures.dr.label);
    json.key("path").value(closures.dr.path);
    json.endObject();
  }
  json.key("count").value(static_cast<uint64_t>(ev.closures.size()));
  json.key("without_truth").value(static_cast<uint64_t>(ev.without_truth));
  json.key("without_dr").value(static_cast<uint64_t>(ev.without_dr));
  json.key("groups").beginArray();
  for (const ClosureGroup& g : ev.groups) {
    json.beginObject();
    json.key("status").value(g.status);
    json.key("count").value(static_cast<uint64_t>(g.count));
    writeRelativePoseErrorStatistics(json, "closure", g.closure);
    writeRelativePoseErrorStatistics(json, "dr", g.dr);
    json.key("nees_count").value(static_cast<uint64_t>(g.nees_count));
    json.key("mean_horizontal_nees");
    if (g.nees_count) {
      json.value(g.mean_horizontal_nees);
    } else {
      json.null();
    }
    json.endObject();
  }
  json.endArray();
  json.key("closures").beginArray();
  for (const ClosureError& e : ev.closures) {
    const ClosureRecord& c = e.closure;
    json.beginObject();
    json.key("subframe_id_a").value(static_cast<int64_t>(c.subframe_id_a));
    json.key("subframe_id_b").value(static_cast<int64_t>(c.subframe_id_b));
    if (c.round < 0) json.key("round").null();
    else json.key("round").value(c.round);
    json.key("status").value(c.status);
    json.key("rejection").value(c.rejection);
    json.key("utime_a_us").value(static_cast<int64_t>(c.utime_a_us));
    json.key("utime_b_us").value(static_cast<int64_t>(c.utime_b_us));
    if (e.has_truth) {
      json.key("truth").beginObject();
      json.key("dx_m").value(e.truth.translation_m.x());
      json.key("dy_m").value(e.truth.translation_m.y());
      json.key("dz_m").value(e.truth.translation_m.z());
      json.key("dheading_deg").value(e.truth.heading_rad * 180.0 / M_PI);
      json.endObject();
    } else {
      json.key("truth").null();
    }
    writeRelativePoseError(json, "error", e.has_truth, e.closure_error);
    writeRelativePoseError(json, "dr_error", e.has_dr, e.dr_error);
    json.endObject();
  }
  json.endArray();
  json.endObject();
}

void writeLceEntry(JsonWriter& json, const LceEntry& entry) {
  writeErrorStatistics(json, "horizontal_m", entry.result.horizontal_m);
  json.key("skipped").value(static_cast<uint64_t>(entry.result.skipped));
}

void writeLceJson(JsonWriter& json, const LceReport& lce, const TrueCorrespondenceOptions& options) {
  json.key("lce").beginObject();
  json.key("seabed_depth_m").value(lce.seabed_depth_m);
  json.key("seabed_depth_source").value(lce.seabed_depth_source);
  json.key("grid_m").value(options.grid_m);
  json.key("min_ground_range_m").value(options.min_ground_range_m);
  json.key("max_ground_range_m").value(options.max_ground_range_m);
  json.key("max_correspondences").value(static_cast<uint64_t>(options.max_correspondences));
  json.key("sightings").value(static_cast<uint64_t>(lce.correspondences.sightings));
  json.key("seabed_points").value(static_cast<uint64_t>(lce.correspondences.seabed_points));
  json.key("candidate_pairs").value(static_cast<uint64_t>(lce.correspondences.candidate_pairs));
  json.key("correspondences").value(static_cast<uint64_t>(lce.correspondences.pairs.size()));
  json.key("truth").beginObject();
  writeLceEntry(json, lce.truth);
  json.endObject();
  json.key("estimates").beginArray();
  for (const LceEntry& e : lce.estimates) {
    json.beginObject();
    json.key("label").value(e.label);
    writeLceEntry(json, e);
    json.endObject();
  }
  json.endArray();
  json.endObject();
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

bool runEvaluation(const EvalRequest& request, const EvalOptions& options, EvalReport& report, std::string& error) {
  report = EvalReport();
  report.options = options;
  report.truth_path = request.truth_path;
  // Everything is compared in the truth's frame: a file whose header names another origin (a run
  // with its own origin, the first fix) is re-expressed in it.
  std::optional<sss::core::MissionOrigin> truth_origin;
  if (!request.estimates.empty() || !request.closures_path.empty() || request.lce) {
    if (request.truth_path.empty()) {
      error = "estimates, closures and LCE need the truth trajectory (--gt TRUTH.tum)";
      return false;
    }
    TumReadResult truth = readTum(request.truth_path);
    if (!truth.ok) {
      error = truth.error;
      return false;
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
      error = estimate.error;
      return false;
    }
    EstimateReport entry;
    entry.input = {defaultLabel(input), input.path};
    entry.evaluation = evaluateTrajectory(report.truth, estimate.poses, report.lines, options.trajectory);
    if (!entry.evaluation.ok) {
      error = input.path + ": " + entry.evaluation.error;
      return false;
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
      error = "heightmaps need the true seabed (--seabed seabed.yaml)";
      return false;
    }
    if (!readHeightmap(request.seabed_path, seabed, error)) return false;
  }
  HeightmapReadOptions in_seabed_frame;
  in_seabed_frame.target_origin = seabed.origin ? seabed.origin : truth_origin;
  if (!request.heightmaps.empty()) {
    for (const EvalInput& input : request.heightmaps) {
      HeightmapRaster estimate;
      if (!readHeightmap(input.path, estimate, error, in_seabed_frame)) return false;
      HeightmapReport entry;
      entry.input = {defaultLabel(input), input.path};
      entry.result = compareHeightmaps(seabed, estimate);
      if (!entry.result.ok) {
        error = input.path + ": " + entry.result.error;
        return false;
      }
      report.heightmaps.push_back(std::move(entry));
    }
  }

  if (!request.closures_path.empty()) {
    std::vector<ClosureRecord> closures;
    if (!readClosureCsv(request.closures_path, closures, error)) return false;
    report.has_closures = true;
    report.closures.path = request.closures_path;
    Trajectory dr;
    if (!request.closures_dr_path.empty()) {
      TumReadOptions in_truth_frame;
      in_truth_frame.target_origin = truth_origin;
      TumReadResult read = readTum(request.closures_dr_path, in_truth_frame);
      if (!read.ok) {
        error = read.error;
        return false;
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
      error = request.truth_path + ": no survey lines found in the truth; --lce needs straight lines seen from both sides";
      return false;
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
  return true;
}

bool writeFigures(const EvalRequest& request, EvalReport& report, std::string& error) {
  if (!request.plot_path.empty() && !report.estimates.empty()) {
    PlotTrajectory truth{"truth", {}};
    for (const StampedPose& p : report.truth) truth.north_east_m.push_back(p.T_world_body.translation.head<2>());
    std::vector<PlotTrajectory> estimates;
    for (const EstimateReport& e : report.estimates) {
      PlotTrajectory t{e.input.label, {}};
      for (const AssociatedPose& p : e.evaluation.association.pairs) t.north_east_m.push_back(p.estimate.translation.head<2>());
      estimates.push_back(std::move(t));
    }
    const std::string title = "Trajectories (north/east), truth: " + std::filesystem::path(report.truth_path).filename().string();
    if (!writeTrajectoryPlot(request.plot_path, truth, estimates, title, error)) return false;
    report.plots.push_back(request.plot_path);

    // Error over time since the truth's first pose, in minutes; survey lines shaded.
    const int64_t t0 = report.truth.front().utime_us;
    std::vector<PlotCurve> curves;
    for (size_t i = 0; i < report.estimates.size(); ++i) {
      const EstimateReport& e = report.estimates[i];
      PlotCurve raw{e.input.label + " horizontal", {}, {}, static_cast<int>(i), false};
      PlotCurve aligned{e.input.label + " horizontal, SE(3)-aligned", {}, {}, static_cast<int>(i), true};
      for (const ErrorSample& s : e.evaluation.series) {
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
    const std::string error_path = withSuffix(request.plot_path, "_error");
    if (!writeCurvePlot(error_path, curves, bands, "Horizontal position error over the mission", "time since start (min)",
                        "horizontal error (m)", error)) {
      return false;
    }
    report.plots.push_back(error_path);
  }
  for (HeightmapReport& h : report.heightmaps) {
    const std::string safe = fileSafeLabel(h.input.label);
    if (!request.error_map_prefix.empty()) {
      const std::string prefix = request.error_map_prefix + "_" + safe;
      if (!writeHeightmap(prefix, h.result.error_map, error)) return false;
      h.error_map_yaml = prefix + ".yaml";
    }
    if (!request.plot_path.empty()) {
      const std::string png = withSuffix(request.plot_path, "_heightmap_" + safe);
      char title[256];
      std::snprintf(title, sizeof title, "Heightmap error %s: MAE %.3f m over %.1f %% coverage", h.input.label.c_str(),
                    h.result.abs_error_m.mean, 100.0 * h.result.coverage_fraction);
      if (!writeErrorMapPng(png, h.result.error_map, title, error, report.options.error_map_png)) return false;
      h.error_map_png = png;
      report.plots.push_back(png);
    }
  }
  return true;
}

namespace {

std::vector<std::string> matchRow(const std::string& label, long pairs, const MatchEvaluation& e) {
  return {label, std::to_string(pairs), std::to_string(e.matches), std::to_string(e.evaluated),
          e.evaluated ? cell(e.meanErrorPx(), 2) : "-", e.evaluated ? cell(e.meanErrorM(), 3) : "-",
          e.evaluated ? cell(e.withinFraction(), 3) : "-", e.matchable ? cell(e.recall(), 3) : "-"};
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
      {"pair type", "pairs", "matches", "evaluated", "mean EPE", "mean EPE", "within", "recall"},
      {"", "", "", "", "px", "m", "2 px", "2 px"}};
  for (int t = 0; t < kPairTypes; ++t) {
    rows.push_back(matchRow(pairTypeName(static_cast<PairType>(t)), m.pairs_by_type[t], m.by_type[t]));
  }
  rows.push_back(matchRow("all", static_cast<long>(m.pairs.size()), m.overall));
  out << formatColumns(rows);
  if (per_pair && !m.pairs.empty()) {
    std::vector<std::vector<std::string>> pair_rows = {
        {"pair", "round", "type", "matches", "evaluated", "EPE px", "EPE m", "within 2 px", "recall 2 px"}};
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

void writeMatchTotals(JsonWriter& json, const MatchEvaluation& e) {
  json.key("matches").value(static_cast<int64_t>(e.matches));
  json.key("evaluated").value(static_cast<int64_t>(e.evaluated));
  json.key("within_2px").value(e.evaluated ? e.withinFraction() : std::numeric_limits<double>::quiet_NaN());
  json.key("recall_2px").value(e.matchable ? e.recall() : std::numeric_limits<double>::quiet_NaN());
  json.key("mean_error_px").value(e.evaluated ? e.meanErrorPx() : std::numeric_limits<double>::quiet_NaN());
  json.key("mean_error_m").value(e.evaluated ? e.meanErrorM() : std::numeric_limits<double>::quiet_NaN());
  json.key("probes").value(static_cast<int64_t>(e.probes));
  json.key("matchable").value(static_cast<int64_t>(e.matchable));
}

void writeMatchesJson(JsonWriter& json, const MatchFileEvaluation& m) {
  json.key("matches").beginObject();
  json.key("path").value(m.path);
  json.key("mission").value(m.mission_dir);
  json.key("decimation").value(m.decimation);
  json.key("stride").value(m.stride);
  json.key("probe_step").value(m.probe_step);
  json.key("matching_pixel_m").value(m.matching_pixel_m);
  json.key("subframes").value(static_cast<uint64_t>(m.subframes));
  json.key("overall").beginObject();
  json.key("pairs").value(static_cast<uint64_t>(m.pairs.size()));
  writeMatchTotals(json, m.overall);
  json.endObject();
  for (int t = 0; t < kPairTypes; ++t) {
    json.key(pairTypeName(static_cast<PairType>(t))).beginObject();
    json.key("pairs").value(static_cast<int64_t>(m.pairs_by_type[t]));
    writeMatchTotals(json, m.by_type[t]);
    json.endObject();
  }
  json.key("pairs").beginArray();
  for (const PairMatchReport& p : m.pairs) {
    json.beginObject();
    json.key("subframe_id_a").value(p.subframe_a);
    json.key("subframe_id_b").value(p.subframe_b);
    json.key("round").value(p.round);
    json.key("type").value(pairTypeName(p.type));
    json.key("heading_difference_deg")
        .value(std::abs(sss::core::wrapAngle(p.heading_b_rad - p.heading_a_rad)) * 180.0 / 3.14159265358979323846);
    writeMatchTotals(json, p.evaluation);
    json.endObject();
  }
  json.endArray();
  json.endObject();
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

std::string reportJson(const EvalReport& report) {
  JsonWriter json;
  json.beginObject();
  json.key("schema").value("sss-eval/1");

  json.key("truth").beginObject();
  json.key("path").value(report.truth_path);
  json.key("poses").value(static_cast<uint64_t>(report.truth.size()));
  if (report.truth.empty()) {
    json.key("start_utime_us").null();
    json.key("duration_s").null();
  } else {
    json.key("start_utime_us").value(static_cast<int64_t>(report.truth.front().utime_us));
    json.key("duration_s").value(static_cast<double>(report.truth.back().utime_us - report.truth.front().utime_us) * 1e-6);
  }
  json.key("distance_m").value(report.truth_distance_m);
  json.key("lines").beginArray();
  for (const SurveyLine& line : report.lines) {
    json.beginObject();
    json.key("index").value(line.index);
    json.key("start_utime_us").value(static_cast<int64_t>(line.start_utime_us));
    json.key("end_utime_us").value(static_cast<int64_t>(line.end_utime_us));
    json.key("length_m").value(line.length_m);
    json.key("heading_deg").value(line.heading_deg);
    json.endObject();
  }
  json.endArray();
  json.endObject();

  const TrajectoryEvaluationOptions& o = report.options.trajectory;
  json.key("options").beginObject();
  json.key("interpolate_truth").value(o.association.interpolate_truth);
  json.key("max_interpolation_gap_s").value(o.association.max_interpolation_gap_s);
  json.key("max_time_difference_s").value(o.association.max_time_difference_s);
  json.key("rpe_windows_m").numbers(o.rpe.windows_m, 10);
  json.key("line_course_window_m").value(o.lines.course_window_m);
  json.key("line_max_turn_rate_deg_per_m").value(o.lines.max_turn_rate_deg_per_m);
  json.key("line_max_heading_change_deg").value(o.lines.max_heading_change_deg);
  json.key("line_min_length_m").value(o.lines.min_line_length_m);
  json.endObject();

  json.key("estimates").beginArray();
  for (const EstimateReport& e : report.estimates) {
    const TrajectoryEvaluation& ev = e.evaluation;
    json.beginObject();
    json.key("label").value(e.input.label);
    json.key("path").value(e.input.path);
    json.key("poses").value(static_cast<uint64_t>(ev.estimate_poses));
    json.key("matched").value(static_cast<uint64_t>(ev.association.pairs.size()));
    json.key("exact").value(static_cast<uint64_t>(ev.association.exact));
    json.key("interpolated").value(static_cast<uint64_t>(ev.association.interpolated));
    json.key("nearest").value(static_cast<uint64_t>(ev.association.nearest));
    json.key("unmatched").value(static_cast<uint64_t>(ev.association.unmatched));

    json.key("ate").beginObject();
    writeErrorStatistics(json, "position_m", ev.ate.position_m);
    writeErrorStatistics(json, "horizontal_m", ev.ate.horizontal_m);
    writeErrorStatistics(json, "vertical_m", ev.ate.vertical_m);
    writeErrorStatistics(json, "rotation_deg", ev.ate.rotation_deg);
    writeErrorStatistics(json, "aligned_position_m", ev.ate.aligned_position_m);
    writeErrorStatistics(json, "aligned_horizontal_m", ev.ate.aligned_horizontal_m);
    json.key("alignment").beginObject();
    const Eigen::Vector3d& t = ev.ate.T_truth_estimate.translation;
    const Eigen::Quaterniond& q = ev.ate.T_truth_estimate.rotation;
    json.key("translation_m").numbers({t.x(), t.y(), t.z()}, 10);
    json.key("quaternion_xyzw").numbers({q.x(), q.y(), q.z(), q.w()}, 10);
    json.key("rotation_deg").value(ev.ate.alignment_rotation_deg);
    json.key("heading_deg").value(ev.ate.alignment_heading_deg);
    json.endObject();
    writeErrorStatistics(json, "gauge_free_horizontal_m", ev.ate.gauge_free_horizontal_m);
    writeErrorStatistics(json, "gauge_horizontal_m", ev.ate.gauge_horizontal_m);
    json.key("gauge_free_scale").value(ev.ate.gauge_free_scale);
    json.key("gauge_free_rotation_deg").value(ev.ate.gauge_free_rotation_deg);
    json.endObject();

    json.key("rpe").beginArray();
    for (const RpeResult& rpe : ev.rpe) {
      json.beginObject();
      json.key("window_m").value(rpe.window_m);
      writeErrorStatistics(json, "translation_percent", rpe.translation_percent);
      writeErrorStatistics(json, "translation_m", rpe.translation_m);
      writeErrorStatistics(json, "rotation_deg", rpe.rotation_deg);
      json.endObject();
    }
    json.endArray();

    json.key("lines").beginArray();
    for (const LineError& line : ev.lines) {
      json.beginObject();
      json.key("index").value(line.line);
      writeErrorStatistics(json, "horizontal_m", line.horizontal_m);
      writeErrorStatistics(json, "position_m", line.position_m);
      writeErrorStatistics(json, "aligned_horizontal_m", line.aligned_horizontal_m);
      json.endObject();
    }
    json.endArray();
    json.key("improvement_vs_first_percent").value(e.improvement_vs_first_percent);

    std::vector<double> time, distance, position, horizontal, aligned, gauge_free, along, across, line;
    const int64_t t0 = report.truth.front().utime_us;
    for (const ErrorSample& s : ev.series) {
      time.push_back(static_cast<double>(s.utime_us - t0) * 1e-6);
      distance.push_back(s.distance_m);
      position.push_back(s.position_m);
      horizontal.push_back(s.horizontal_m);
      aligned.push_back(s.aligned_horizontal_m);
      gauge_free.push_back(s.gauge_free_horizontal_m);
      along.push_back(s.along_track_m);
      across.push_back(s.across_track_m);
      line.push_back(s.line);
    }
    json.key("series").beginObject();
    json.key("time_s").numbers(time, 10);
    json.key("distance_m").numbers(distance, 7);
    json.key("position_m").numbers(position, 5);
    json.key("horizontal_m").numbers(horizontal, 5);
    json.key("aligned_horizontal_m").numbers(aligned, 5);
    json.key("gauge_free_horizontal_m").numbers(gauge_free, 5);
    json.key("along_track_m").numbers(along, 5);
    json.key("across_track_m").numbers(across, 5);
    json.key("line").numbers(line, 5);
    json.endObject();
    json.endObject();
  }
  json.endArray();

  json.key("heightmaps").beginArray();
  for (const HeightmapReport& h : report.heightmaps) {
    const HeightmapErrorResult& r = h.result;
    json.beginObject();
    json.key("label").value(h.input.label);
    json.key("path").value(h.input.path);
    json.key("estimate_cells").value(static_cast<uint64_t>(r.estimate_cells));
    json.key("cells_with_data").value(static_cast<uint64_t>(r.cells_with_data));
    json.key("compared_cells").value(static_cast<uint64_t>(r.compared_cells));
    json.key("coverage_fraction").value(r.coverage_fraction);
    json.key("covered_area_m2").value(r.covered_area_m2);
    writeErrorStatistics(json, "abs_error_m", r.abs_error_m);
    json.key("mean_signed_error_m").value(r.mean_signed_error_m);
    if (h.error_map_yaml.empty()) json.key("error_map_yaml").null();
    else json.key("error_map_yaml").value(h.error_map_yaml);
    if (h.error_map_png.empty()) json.key("error_map_png").null();
    else json.key("error_map_png").value(h.error_map_png);
    json.endObject();
  }
  json.endArray();

  if (report.has_closures) writeClosuresJson(json, report.closures);
  else json.key("closures").null();
  if (report.has_lce) writeLceJson(json, report.lce, report.options.lce);
  else json.key("lce").null();
  if (report.lce_skipped.empty()) json.key("lce_skipped").null();
  else json.key("lce_skipped").value(report.lce_skipped);
  if (report.has_matches) writeMatchesJson(json, report.matches);
  else json.key("matches").null();

  json.key("outputs").beginObject();
  json.key("json").value(report.json_path);
  json.key("plots").beginArray();
  for (const std::string& plot : report.plots) json.value(plot);
  json.endArray();
  json.endObject();
  json.endObject();
  return json.str();
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

void writeErrorStatistics(JsonWriter& json, const std::string& key, const ErrorStatistics& stats) {
  json.key(key).beginObject();
  json.key("count").value(static_cast<uint64_t>(stats.count));
  json.key("rmse").value(stats.rmse);
  json.key("mean").value(stats.mean);
  json.key("median").value(stats.median);
  json.key("max").value(stats.max);
  json.endObject();
}

void writeSignedStatistics(JsonWriter& json, const std::string& key, const SignedErrorStatistics& stats) {
  json.key(key).beginObject();
  json.key("count").value(static_cast<uint64_t>(stats.abs.count));
  json.key("rmse").value(stats.abs.rmse);
  json.key("mean").value(stats.abs.mean);
  json.key("median").value(stats.abs.median);
  json.key("max").value(stats.abs.max);
  json.key("bias").value(stats.bias);
  json.endObject();
}

void writeRelativePoseErrorStatistics(JsonWriter& json, const std::string& key, const RelativePoseErrorStatistics& s) {
  json.key(key).beginObject();
  writeSignedStatistics(json, "along_m", s.along_m);
  writeSignedStatistics(json, "lateral_m", s.lateral_m);
  writeSignedStatistics(json, "depth_m", s.depth_m);
  writeSignedStatistics(json, "heading_deg", s.heading_deg);
  writeErrorStatistics(json, "horizontal_m", s.horizontal_m);
  json.endObject();
}

}  // namespace sss::eval
