// sss-eval's JSON (schema sss-eval/1): the metrics of a run, its closures, LCE and matches. See
// report.hpp.
#include "tools/eval/report.hpp"

#include <cmath>
#include <string>
#include <utility>

#include "tools/eval/json_values.hpp"

namespace sss::eval {
namespace {

void writeRelativePoseError(Json& json, const std::string& key, bool present, const RelativePoseError& e) {
  if (!present) {
    json[key] = nullptr;
    return;
  }
  Json& error_json = (json[key] = Json::object());
  error_json["along_m"] = jsonValue(e.along_m);
  error_json["lateral_m"] = jsonValue(e.lateral_m);
  error_json["depth_m"] = jsonValue(e.depth_m);
  error_json["heading_deg"] = jsonValue(e.heading_rad * 180.0 / M_PI);
}

void writeClosuresJson(Json& json, const ClosureReport& closures) {
  const ClosureEvaluation& ev = closures.evaluation;
  Json& closures_json = (json["closures"] = Json::object());
  closures_json["path"] = jsonValue(closures.path);
  if (closures.dr.path.empty()) {
    closures_json["dr"] = nullptr;
  } else {
    Json& dr_json = (closures_json["dr"] = Json::object());
    dr_json["label"] = jsonValue(closures.dr.label);
    dr_json["path"] = jsonValue(closures.dr.path);
  }
  closures_json["count"] = jsonValue(static_cast<uint64_t>(ev.closures.size()));
  closures_json["without_truth"] = jsonValue(static_cast<uint64_t>(ev.without_truth));
  closures_json["without_dr"] = jsonValue(static_cast<uint64_t>(ev.without_dr));
  Json& groups_json = (closures_json["groups"] = Json::array());
  for (const ClosureGroup& g : ev.groups) {
    Json& group_json = groups_json.emplace_back(Json::object());
    group_json["status"] = jsonValue(g.status);
    group_json["count"] = jsonValue(static_cast<uint64_t>(g.count));
    writeRelativePoseErrorStatistics(group_json, "closure", g.closure);
    writeRelativePoseErrorStatistics(group_json, "dr", g.dr);
    group_json["nees_count"] = jsonValue(static_cast<uint64_t>(g.nees_count));
    if (g.nees_count) {
      group_json["mean_horizontal_nees"] = jsonValue(g.mean_horizontal_nees);
    } else {
      group_json["mean_horizontal_nees"] = nullptr;
    }
  }
  Json& closure_list_json = (closures_json["closures"] = Json::array());
  for (const ClosureError& e : ev.closures) {
    const ClosureRecord& c = e.closure;
    Json& closure_json = closure_list_json.emplace_back(Json::object());
    closure_json["subframe_id_a"] = jsonValue(static_cast<int64_t>(c.subframe_id_a));
    closure_json["subframe_id_b"] = jsonValue(static_cast<int64_t>(c.subframe_id_b));
    if (c.round < 0) closure_json["round"] = nullptr;
    else closure_json["round"] = jsonValue(c.round);
    closure_json["status"] = jsonValue(c.status);
    closure_json["rejection"] = jsonValue(c.rejection);
    closure_json["utime_a_us"] = jsonValue(static_cast<int64_t>(c.utime_a_us));
    closure_json["utime_b_us"] = jsonValue(static_cast<int64_t>(c.utime_b_us));
    if (e.has_truth) {
      Json& truth_json = (closure_json["truth"] = Json::object());
      truth_json["dx_m"] = jsonValue(e.truth.translation_m.x());
      truth_json["dy_m"] = jsonValue(e.truth.translation_m.y());
      truth_json["dz_m"] = jsonValue(e.truth.translation_m.z());
      truth_json["dheading_deg"] = jsonValue(e.truth.heading_rad * 180.0 / M_PI);
    } else {
      closure_json["truth"] = nullptr;
    }
    writeRelativePoseError(closure_json, "error", e.has_truth, e.closure_error);
    writeRelativePoseError(closure_json, "dr_error", e.has_dr, e.dr_error);
    // The closure's own horizontal sigmas (A's frame) and its error against them.
    for (const auto& [key, value] : {std::pair<const char*, double>{"sigma_along_m", c.sigmaM(0)},
                                     {"sigma_lateral_m", c.sigmaM(1)},
                                     {"horizontal_nees", e.horizontal_nees}}) {
      if (std::isfinite(value)) closure_json[key] = jsonValue(value);
      else closure_json[key] = nullptr;
    }
  }
}

void writeLceEntry(Json& json, const LceEntry& entry) {
  writeErrorStatistics(json, "horizontal_m", entry.result.horizontal_m);
  json["skipped"] = jsonValue(static_cast<uint64_t>(entry.result.skipped));
}

void writeLceJson(Json& json, const LceReport& lce, const TrueCorrespondenceOptions& options) {
  Json& lce_json = (json["lce"] = Json::object());
  lce_json["seabed_depth_m"] = jsonValue(lce.seabed_depth_m);
  lce_json["seabed_depth_source"] = jsonValue(lce.seabed_depth_source);
  lce_json["grid_m"] = jsonValue(options.grid_m);
  lce_json["min_ground_range_m"] = jsonValue(options.min_ground_range_m);
  lce_json["max_ground_range_m"] = jsonValue(options.max_ground_range_m);
  lce_json["max_correspondences"] = jsonValue(static_cast<uint64_t>(options.max_correspondences));
  lce_json["sightings"] = jsonValue(static_cast<uint64_t>(lce.correspondences.sightings));
  lce_json["seabed_points"] = jsonValue(static_cast<uint64_t>(lce.correspondences.seabed_points));
  lce_json["candidate_pairs"] = jsonValue(static_cast<uint64_t>(lce.correspondences.candidate_pairs));
  lce_json["correspondences"] = jsonValue(static_cast<uint64_t>(lce.correspondences.pairs.size()));
  Json& truth_json = (lce_json["truth"] = Json::object());
  writeLceEntry(truth_json, lce.truth);
  Json& estimates_json = (lce_json["estimates"] = Json::array());
  for (const LceEntry& e : lce.estimates) {
    Json& estimate_json = estimates_json.emplace_back(Json::object());
    estimate_json["label"] = jsonValue(e.label);
    writeLceEntry(estimate_json, e);
  }
}


void writeMatchTotals(Json& json, const MatchEvaluation& e) {
  json["matches"] = jsonValue(static_cast<int64_t>(e.matches));
  json["evaluated"] = jsonValue(static_cast<int64_t>(e.evaluated));
  json["within_2px"] = jsonValue(e.evaluated ? e.withinFraction() : std::numeric_limits<double>::quiet_NaN());
  json["recall_2px"] = jsonValue(e.matchable ? e.recall() : std::numeric_limits<double>::quiet_NaN());
  json["mean_error_px"] = jsonValue(e.evaluated ? e.meanErrorPx() : std::numeric_limits<double>::quiet_NaN());
  json["mean_error_m"] = jsonValue(e.evaluated ? e.meanErrorM() : std::numeric_limits<double>::quiet_NaN());
  json["mean_along_error_m"] = jsonValue(e.evaluated ? e.meanAlongErrorM() : std::numeric_limits<double>::quiet_NaN());
  json["mean_outward_error_m"] =
      jsonValue(e.evaluated ? e.meanOutwardErrorM() : std::numeric_limits<double>::quiet_NaN());
  json["probes"] = jsonValue(static_cast<int64_t>(e.probes));
  json["matchable"] = jsonValue(static_cast<int64_t>(e.matchable));
}

void writeMatchesJson(Json& json, const MatchFileEvaluation& m) {
  Json& matches_json = (json["matches"] = Json::object());
  matches_json["path"] = jsonValue(m.path);
  matches_json["mission"] = jsonValue(m.mission_dir);
  matches_json["decimation"] = jsonValue(m.decimation);
  matches_json["stride"] = jsonValue(m.stride);
  matches_json["probe_step"] = jsonValue(m.probe_step);
  matches_json["matching_pixel_m"] = jsonValue(m.matching_pixel_m);
  matches_json["subframes"] = jsonValue(static_cast<uint64_t>(m.subframes));
  Json& overall_json = (matches_json["overall"] = Json::object());
  overall_json["pairs"] = jsonValue(static_cast<uint64_t>(m.pairs.size()));
  writeMatchTotals(overall_json, m.overall);
  for (int t = 0; t < kPairTypes; ++t) {
    Json& pair_type_json = (matches_json[pairTypeName(static_cast<PairType>(t))] = Json::object());
    pair_type_json["pairs"] = jsonValue(static_cast<int64_t>(m.pairs_by_type[t]));
    writeMatchTotals(pair_type_json, m.by_type[t]);
  }
  Json& pairs_json = (matches_json["pairs"] = Json::array());
  for (const PairMatchReport& p : m.pairs) {
    Json& pair_json = pairs_json.emplace_back(Json::object());
    pair_json["subframe_id_a"] = jsonValue(p.subframe_a);
    pair_json["subframe_id_b"] = jsonValue(p.subframe_b);
    pair_json["round"] = jsonValue(p.round);
    pair_json["type"] = jsonValue(pairTypeName(p.type));
    pair_json["heading_difference_deg"] =
        jsonValue(std::abs(sss::core::wrapAngle(p.heading_b_rad - p.heading_a_rad)) * 180.0 / 3.14159265358979323846);
    writeMatchTotals(pair_json, p.evaluation);
  }
}


}  // namespace

std::string reportJson(const EvalReport& report) {
  Json json = Json::object();
  json["schema"] = jsonValue("sss-eval/1");

  Json& truth_json = (json["truth"] = Json::object());
  truth_json["path"] = jsonValue(report.truth_path);
  truth_json["poses"] = jsonValue(static_cast<uint64_t>(report.truth.size()));
  if (report.truth.empty()) {
    truth_json["start_utime_us"] = nullptr;
    truth_json["duration_s"] = nullptr;
  } else {
    truth_json["start_utime_us"] = jsonValue(static_cast<int64_t>(report.truth.front().utime_us));
    truth_json["duration_s"] = jsonValue(static_cast<double>(report.truth.back().utime_us - report.truth.front().utime_us) * 1e-6);
  }
  truth_json["distance_m"] = jsonValue(report.truth_distance_m);
  Json& lines_json = (truth_json["lines"] = Json::array());
  for (const SurveyLine& line : report.lines) {
    Json& line_json = lines_json.emplace_back(Json::object());
    line_json["index"] = jsonValue(line.index);
    line_json["start_utime_us"] = jsonValue(static_cast<int64_t>(line.start_utime_us));
    line_json["end_utime_us"] = jsonValue(static_cast<int64_t>(line.end_utime_us));
    line_json["length_m"] = jsonValue(line.length_m);
    line_json["heading_deg"] = jsonValue(line.heading_deg);
  }

  const TrajectoryEvaluationOptions& o = report.options.trajectory;
  Json& options_json = (json["options"] = Json::object());
  options_json["interpolate_truth"] = jsonValue(o.association.interpolate_truth);
  options_json["max_interpolation_gap_s"] = jsonValue(o.association.max_interpolation_gap_s);
  options_json["max_time_difference_s"] = jsonValue(o.association.max_time_difference_s);
  options_json["rpe_windows_m"] = jsonNumbers(o.rpe.windows_m, 10);
  options_json["line_course_window_m"] = jsonValue(o.lines.course_window_m);
  options_json["line_max_turn_rate_deg_per_m"] = jsonValue(o.lines.max_turn_rate_deg_per_m);
  options_json["line_max_heading_change_deg"] = jsonValue(o.lines.max_heading_change_deg);
  options_json["line_min_length_m"] = jsonValue(o.lines.min_line_length_m);

  Json& estimates_json = (json["estimates"] = Json::array());
  for (const EstimateReport& e : report.estimates) {
    const TrajectoryEvaluation& ev = e.evaluation;
    Json& estimate_json = estimates_json.emplace_back(Json::object());
    estimate_json["label"] = jsonValue(e.input.label);
    estimate_json["path"] = jsonValue(e.input.path);
    estimate_json["poses"] = jsonValue(static_cast<uint64_t>(ev.estimate_poses));
    estimate_json["matched"] = jsonValue(static_cast<uint64_t>(ev.association.pairs.size()));
    estimate_json["exact"] = jsonValue(static_cast<uint64_t>(ev.association.exact));
    estimate_json["interpolated"] = jsonValue(static_cast<uint64_t>(ev.association.interpolated));
    estimate_json["nearest"] = jsonValue(static_cast<uint64_t>(ev.association.nearest));
    estimate_json["unmatched"] = jsonValue(static_cast<uint64_t>(ev.association.unmatched));

    Json& ate_json = (estimate_json["ate"] = Json::object());
    writeErrorStatistics(ate_json, "position_m", ev.ate.position_m);
    writeErrorStatistics(ate_json, "horizontal_m", ev.ate.horizontal_m);
    writeErrorStatistics(ate_json, "vertical_m", ev.ate.vertical_m);
    writeErrorStatistics(ate_json, "rotation_deg", ev.ate.rotation_deg);
    writeErrorStatistics(ate_json, "aligned_position_m", ev.ate.aligned_position_m);
    writeErrorStatistics(ate_json, "aligned_horizontal_m", ev.ate.aligned_horizontal_m);
    Json& alignment_json = (ate_json["alignment"] = Json::object());
    const Eigen::Vector3d& t = ev.ate.T_truth_estimate.translation;
    const Eigen::Quaterniond& q = ev.ate.T_truth_estimate.rotation;
    alignment_json["translation_m"] = jsonNumbers({t.x(), t.y(), t.z()}, 10);
    alignment_json["quaternion_xyzw"] = jsonNumbers({q.x(), q.y(), q.z(), q.w()}, 10);
    alignment_json["rotation_deg"] = jsonValue(ev.ate.alignment_rotation_deg);
    alignment_json["heading_deg"] = jsonValue(ev.ate.alignment_heading_deg);
    writeErrorStatistics(ate_json, "gauge_free_horizontal_m", ev.ate.gauge_free_horizontal_m);
    writeErrorStatistics(ate_json, "gauge_horizontal_m", ev.ate.gauge_horizontal_m);
    ate_json["gauge_free_scale"] = jsonValue(ev.ate.gauge_free_scale);
    ate_json["gauge_free_rotation_deg"] = jsonValue(ev.ate.gauge_free_rotation_deg);

    Json& rpe_json = (estimate_json["rpe"] = Json::array());
    for (const RpeResult& rpe : ev.rpe) {
      Json& rpe_window_json = rpe_json.emplace_back(Json::object());
      rpe_window_json["window_m"] = jsonValue(rpe.window_m);
      writeErrorStatistics(rpe_window_json, "translation_percent", rpe.translation_percent);
      writeErrorStatistics(rpe_window_json, "translation_m", rpe.translation_m);
      writeErrorStatistics(rpe_window_json, "rotation_deg", rpe.rotation_deg);
    }

    Json& estimate_lines_json = (estimate_json["lines"] = Json::array());
    for (const LineError& line : ev.lines) {
      Json& line_json = estimate_lines_json.emplace_back(Json::object());
      line_json["index"] = jsonValue(line.line);
      writeErrorStatistics(line_json, "horizontal_m", line.horizontal_m);
      writeErrorStatistics(line_json, "position_m", line.position_m);
      writeErrorStatistics(line_json, "aligned_horizontal_m", line.aligned_horizontal_m);
    }
    estimate_json["improvement_vs_first_percent"] = jsonValue(e.improvement_vs_first_percent);

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
    Json& series_json = (estimate_json["series"] = Json::object());
    series_json["time_s"] = jsonNumbers(time, 10);
    series_json["distance_m"] = jsonNumbers(distance, 7);
    series_json["position_m"] = jsonNumbers(position, 5);
    series_json["horizontal_m"] = jsonNumbers(horizontal, 5);
    series_json["aligned_horizontal_m"] = jsonNumbers(aligned, 5);
    series_json["gauge_free_horizontal_m"] = jsonNumbers(gauge_free, 5);
    series_json["along_track_m"] = jsonNumbers(along, 5);
    series_json["across_track_m"] = jsonNumbers(across, 5);
    series_json["line"] = jsonNumbers(line, 5);
  }

  Json& heightmaps_json = (json["heightmaps"] = Json::array());
  for (const HeightmapReport& h : report.heightmaps) {
    const HeightmapErrorResult& r = h.result;
    Json& heightmaps_entry = heightmaps_json.emplace_back(Json::object());
    heightmaps_entry["label"] = jsonValue(h.input.label);
    heightmaps_entry["path"] = jsonValue(h.input.path);
    heightmaps_entry["estimate_cells"] = jsonValue(static_cast<uint64_t>(r.estimate_cells));
    heightmaps_entry["cells_with_data"] = jsonValue(static_cast<uint64_t>(r.cells_with_data));
    heightmaps_entry["compared_cells"] = jsonValue(static_cast<uint64_t>(r.compared_cells));
    heightmaps_entry["coverage_fraction"] = jsonValue(r.coverage_fraction);
    heightmaps_entry["covered_area_m2"] = jsonValue(r.covered_area_m2);
    writeErrorStatistics(heightmaps_entry, "abs_error_m", r.abs_error_m);
    heightmaps_entry["mean_signed_error_m"] = jsonValue(r.mean_signed_error_m);
    if (h.error_map_yaml.empty()) heightmaps_entry["error_map_yaml"] = nullptr;
    else heightmaps_entry["error_map_yaml"] = jsonValue(h.error_map_yaml);
    if (h.error_map_png.empty()) heightmaps_entry["error_map_png"] = nullptr;
    else heightmaps_entry["error_map_png"] = jsonValue(h.error_map_png);
  }

  if (report.has_closures) writeClosuresJson(json, report.closures);
  else json["closures"] = nullptr;
  if (report.has_lce) writeLceJson(json, report.lce, report.options.lce);
  else json["lce"] = nullptr;
  if (report.lce_skipped.empty()) json["lce_skipped"] = nullptr;
  else json["lce_skipped"] = jsonValue(report.lce_skipped);
  if (report.has_matches) writeMatchesJson(json, report.matches);
  else json["matches"] = nullptr;

  Json& outputs_json = (json["outputs"] = Json::object());
  outputs_json["json"] = jsonValue(report.json_path);
  Json& plots_json = (outputs_json["plots"] = Json::array());
  for (const std::string& plot : report.plots) plots_json.push_back(jsonValue(plot));
  return json.dump(2);
}

void writeErrorStatistics(Json& json, const std::string& key, const ErrorStatistics& stats) {
  Json& stats_json = (json[key] = Json::object());
  stats_json["count"] = jsonValue(static_cast<uint64_t>(stats.count));
  stats_json["rmse"] = jsonValue(stats.rmse);
  stats_json["mean"] = jsonValue(stats.mean);
  stats_json["median"] = jsonValue(stats.median);
  stats_json["max"] = jsonValue(stats.max);
}

void writeSignedStatistics(Json& json, const std::string& key, const SignedErrorStatistics& stats) {
  Json& stats_json = (json[key] = Json::object());
  stats_json["count"] = jsonValue(static_cast<uint64_t>(stats.abs.count));
  stats_json["rmse"] = jsonValue(stats.abs.rmse);
  stats_json["mean"] = jsonValue(stats.abs.mean);
  stats_json["median"] = jsonValue(stats.abs.median);
  stats_json["max"] = jsonValue(stats.abs.max);
  stats_json["bias"] = jsonValue(stats.bias);
}

void writeRelativePoseErrorStatistics(Json& json, const std::string& key, const RelativePoseErrorStatistics& s) {
  Json& stats_json = (json[key] = Json::object());
  writeSignedStatistics(stats_json, "along_m", s.along_m);
  writeSignedStatistics(stats_json, "lateral_m", s.lateral_m);
  writeSignedStatistics(stats_json, "depth_m", s.depth_m);
  writeSignedStatistics(stats_json, "heading_deg", s.heading_deg);
  writeErrorStatistics(stats_json, "horizontal_m", s.horizontal_m);
}

}  // namespace sss::eval
