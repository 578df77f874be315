// sss-eval's JSON (schema sss-eval/1): the metrics of a run, its closures, LCE and matches. See
// report.hpp.
#include "tools/eval/report.hpp"

#include <cmath>
#include <string>

#include "tools/eval/json_writer.hpp"

namespace sss::eval {
namespace {

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
