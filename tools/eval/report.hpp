// One evaluation run of sss-eval: reads the truth, the estimates, heightmaps and loop closures,
// computes every metric, and renders the terminal table, the JSON report and the figures.
//
// JSON report (schema "sss-eval/1"; keys are stable, new keys may be added; numbers that do not
// exist, e.g. statistics over zero samples, are null). `stats` is
// {"count", "rmse", "mean", "median", "max"}.
// {
//   "schema": "sss-eval/1",
//   "truth": {"path", "poses", "start_utime_us", "duration_s", "distance_m",
//             "lines": [{"index", "start_utime_us", "end_utime_us", "length_m", "heading_deg"}]},
//   "options": {"interpolate_truth", "max_interpolation_gap_s", "max_time_difference_s",
//               "rpe_windows_m": [...], "line_course_window_m", "line_max_turn_rate_deg_per_m",
//               "line_max_heading_change_deg", "line_min_length_m"},
//   "estimates": [{
//     "label", "path", "poses", "matched", "exact", "interpolated", "nearest", "unmatched",
//     "ate": {"position_m": stats, "horizontal_m": stats, "vertical_m": stats, "rotation_deg": stats,
//             "aligned_position_m": stats, "aligned_horizontal_m": stats,
//             "alignment": {"translation_m": [n, e, d], "quaternion_xyzw": [x, y, z, w],
//                           "rotation_deg", "heading_deg"},
//             "gauge_free_horizontal_m": stats (after the best rotation and scale about the
//             estimate's first position, no shift; AteResult), "gauge_horizontal_m": stats (the raw
//             error that rotation and scale explain), "gauge_free_scale", "gauge_free_rotation_deg"
//             (clockwise from north positive)},
//     "rpe": [{"window_m", "translation_percent": stats, "translation_m": stats, "rotation_deg": stats}],
//     "lines": [{"index", "horizontal_m": stats, "position_m": stats, "aligned_horizontal_m": stats}],
//     "improvement_vs_first_percent": (first horizontal ATE RMSE - this) / first * 100, null for the first,
//     "series": {"time_s" (since the truth's first pose), "distance_m", "position_m", "horizontal_m",
//                "aligned_horizontal_m", "gauge_free_horizontal_m", "along_track_m", "across_track_m",
//                "line" (-1 off lines)}
//   }],
//   "heightmaps": [{"label", "path", "estimate_cells", "cells_with_data", "compared_cells",
//                   "coverage_fraction", "covered_area_m2", "abs_error_m": stats (MAE = mean),
//                   "mean_signed_error_m", "error_map_yaml", "error_map_png" (null when not written)}],
//   "closures": null | {  (--closures; error = estimate - truth in A's true body frame)
//     "path", "dr": null | {"label", "path"}, "count", "without_truth", "without_dr",
//     "groups": [{"status" (accepted, rejected, superseded, pending), "count",
//                 "closure": errors, "dr": errors (count 0 without DR)}],
//     "closures": [{"subframe_id_a", "subframe_id_b", "round", "status", "rejection", "utime_a_us",
//                   "utime_b_us", "truth": null | {"dx_m", "dy_m", "dz_m", "dheading_deg"},
//                   "error": null | component, "dr_error": null | component}]},
//     errors = {"along_m", "lateral_m", "depth_m", "heading_deg": stats of |error| + "bias" (mean
//               signed error), "horizontal_m": stats of |(along, lateral)|};
//     component = {"along_m", "lateral_m", "depth_m", "heading_deg"} (signed)
//   "lce": null | {  (landmark consistency error on correspondences made from the truth; sss-eval
//                     computes it whenever there are --gt and --est, unless --no-lce)
//     "seabed_depth_m", "seabed_depth_source", "grid_m", "min_ground_range_m", "max_ground_range_m",
//     "max_correspondences", "sightings", "seabed_points", "candidate_pairs", "correspondences",
//     "truth": {"horizontal_m": stats, "skipped"} (the self-check, ~0),
//     "estimates": [{"label", "horizontal_m": stats, "skipped"}]},
//   "lce_skipped": null | why the LCE asked for by default was not computed (no survey lines),
//   "matches": null | {  (--matches matches.csv --mission DIR; end-point error against the simulator's truth,
//                         px of the matching image: rows = pings, columns = decimation bins)
//     "path", "mission", "decimation", "stride", "probe_step", "matching_pixel_m", "subframes",
//     "overall": totals, "parallel": totals, "anti_parallel": totals, "crossing": totals (each + "pairs"),
//     "pairs": [{"subframe_id_a", "subframe_id_b", "round", "type", "heading_difference_deg", totals}]},
//     totals = {"matches", "evaluated", "within_2px" (fraction of evaluated), "recall_2px", "mean_error_px",
//               "mean_error_m", "probes", "matchable"}
//   "outputs": {"json", "plots": [...]}
// }
#pragma once

#include "tools/eval/closure_metrics.hpp"
#include "tools/eval/figure_script.hpp"
#include "tools/eval/heightmap_metrics.hpp"
#include "tools/eval/landmark_consistency.hpp"
#include "tools/eval/json_values.hpp"
#include "tools/eval/match_metrics.hpp"
#include "tools/eval/grey_mosaic.hpp"
#include "tools/eval/trajectory_io.hpp"
#include "tools/eval/trajectory_metrics.hpp"

#include <limits>
#include <string>
#include <vector>

namespace sss::eval {

struct EvalInput {
  std::string label;  // empty: the file name without its extension
  std::string path;
};

struct EvalRequest {
  std::string truth_path;              // TUM; needed when there are estimates
  std::vector<EvalInput> estimates;    // TUM
  std::string seabed_path;             // heightmap YAML of the true seabed; needed with heightmaps
  std::vector<EvalInput> heightmaps;   // heightmap YAMLs
  std::string json_path;               // empty: no JSON
  std::string plot_path;               // X.png: X.png (trajectories), X_error.png, X_heightmap_<label>.png
  std::string error_map_prefix;        // P: P_<label>.yaml + P_<label>_depth.f32 per heightmap
  std::string closures_path;           // loop_closures.csv of sss-process; needs the truth
  std::string closures_dr_path;        // DR trajectory for the closures' baseline; empty: the first estimate
  bool lce = false;                    // landmark consistency of the truth and every estimate
  bool lce_optional = false;           // lce by default, not asked for: no survey lines skips it, not an error
  std::string matches_path;            // matches.csv of sss-process --write-matches; needs mission_dir
  std::string mission_dir;             // the sss-sim folder (mission.yaml) the matches are evaluated against
  FigureScriptOptions figures;         // the interpreter and the script that draw the PNGs
};

struct EvalOptions {
  TrajectoryEvaluationOptions trajectory;
  double table_rpe_window_m = 50.0;  // the table shows the configured window closest to this
  // Colour scale of the heightmap error maps, +-this; <= 0: the 99th percentile of |error| rounded
  // up to 1, 2 or 5 x 10^k (report_figures.py).
  double error_map_limit_m = 0.0;
  bool closure_table = false;  // the table lists every closure (else only the statistics)
  bool match_table = false;    // the table lists every matched pair (else per pair type)
  TrueCorrespondenceOptions lce;
  // Depth of the flat seabed of the LCE model: this when finite, else flatSeabedDepthM() with the
  // request's seabed raster if any and lce_default_altitude_m (the simulator's default altitude).
  double lce_seabed_depth_m = std::numeric_limits<double>::quiet_NaN();
  double lce_default_altitude_m = 18.0;
};

struct EstimateReport {
  EvalInput input;
  TrajectoryEvaluation evaluation;
  double improvement_vs_first_percent = std::numeric_limits<double>::quiet_NaN();
};

struct HeightmapReport {
  EvalInput input;
  HeightmapErrorResult result;
  std::string error_map_yaml;  // written files, empty when not written
  std::string error_map_png;
};

struct ClosureReport {
  std::string path;
  EvalInput dr;  // the DR trajectory the closures are compared with; path empty without one
  ClosureEvaluation evaluation;
};

struct LceEntry {
  std::string label;
  LandmarkConsistencyResult result;
};

struct LceReport {
  double seabed_depth_m = 0.0;
  std::string seabed_depth_source;
  TrueCorrespondences correspondences;
  LceEntry truth;  // the self-check
  std::vector<LceEntry> estimates;
};

struct EvalReport {
  EvalOptions options;
  std::string truth_path;
  Trajectory truth;
  double truth_distance_m = 0.0;
  std::vector<SurveyLine> lines;
  std::vector<EstimateReport> estimates;
  std::vector<HeightmapReport> heightmaps;
  bool has_closures = false;
  ClosureReport closures;
  bool has_lce = false;
  LceReport lce;
  std::string lce_skipped;  // why an optional LCE was not computed; empty otherwise
  bool has_matches = false;  // filled by evaluateMatchFile (sss-eval), not runEvaluation
  MatchFileEvaluation matches;
  std::vector<std::string> plots;  // figure files written
  std::string json_path;
};

// Reads every input and computes every metric. Fails with a message naming the file (and line)
// for bad or unusable input: unreadable or malformed files, an estimate with no pose in the
// truth's time span, a heightmap that does not overlap the seabed, --lce without survey lines.
sss::core::Status runEvaluation(const EvalRequest& request, const EvalOptions& options, EvalReport& report);

// Figures and error-map rasters of the request (plot_path, error_map_prefix); the figures drawn
// by report_figures.py (figure_script.hpp). Fails with a one-line message when a file cannot be
// written or figures were not drawn (no python3-matplotlib: the message says to run
// tools/setup-deps.sh); report.plots then lists only the PNGs drawn.
sss::core::Status writeFigures(const EvalRequest& request, EvalReport& report);

// The aligned terminal table: one row per estimate (ATE RMSE raw and aligned, horizontal ATE RMSE
// and max, horizontal aligned and gauge-free RMSE, RPE, improvement vs the first estimate), the
// gauge fit per estimate (rotation, scale, gauge and gauge-free error), per-line horizontal RMSE, heightmaps, closure
// errors per status (and per closure with options.closure_table), LCE per trajectory, match accuracy per
// pair type (and per pair with options.match_table).
std::string formatTable(const EvalReport& report);

// The JSON report described at the top of this file.
std::string reportJson(const EvalReport& report);

// A label usable in a file name: [A-Za-z0-9._-], others replaced by '_'.
std::string fileSafeLabel(const std::string& label);

// Rows of cells as aligned text columns: first column left-aligned, the others right-aligned.
std::string formatColumns(const std::vector<std::vector<std::string>>& rows);
// {"count", "rmse", "mean", "median", "max"} under key (NaN as null).
void writeErrorStatistics(Json& json, const std::string& key, const ErrorStatistics& stats);
// Stats of |error| + "bias" (mean signed error) under key.
void writeSignedStatistics(Json& json, const std::string& key, const SignedErrorStatistics& stats);
// {"along_m", "lateral_m", "depth_m", "heading_deg": signed stats, "horizontal_m": stats} under key.
void writeRelativePoseErrorStatistics(Json& json, const std::string& key, const RelativePoseErrorStatistics& stats);

}  // namespace sss::eval
