// The per-run report of sss-report: a simulated mission (truth) and the output folder of the
// offline runner (sss-process) -> DR vs SLAM metrics, index.html, report.md, metrics.json, figures.
//
// Inputs. MISSION_DIR (sss-sim --out): ground_truth.tum (required), seabed.yaml (heightmap errors),
// mosaic.yaml + mosaic.png (background of the trajectory map). RUN_DIR: slam.tum (required),
// dead_reckoning.tum (else MISSION_DIR's, with a note), loop_closures.csv, heightmap.yaml (SLAM) and
// heightmap_dr.yaml, mosaic_dr.yaml / mosaic_slam.yaml (+ .png), summary.json. A missing or
// unreadable optional input drops its section and adds a note; it never fails the report.
// Figures: drawn by report_figures.py (matplotlib) from OUT_DIR/figure_data/ (figures.json + .npy);
// the page, index.html, by report_page.py from OUT_DIR/figure_data/page.json. report.md (the same
// content as Markdown) and metrics.json are written here. Without python3-matplotlib the report has
// no figures, without python3 no index.html either; one note says why.
//
// metrics.json (schema "sss-report/1"; numbers that do not exist are null; stats = {"count",
// "rmse", "mean", "median", "max"}; improvement = (DR - SLAM) / DR * 100, positive = SLAM better):
// {
//   "schema", "title", "mission_dir", "run_dir", "out_dir", "verdict", "outcome": "better|worse|same",
//   "trajectory": {"truth_path", "truth_poses", "duration_s", "distance_m",
//                  "lines": [{"index", "length_m", "heading_deg"}], "rpe_window_m",
//                  "dr" | "slam": {"path", "poses", "matched", "ate_horizontal_m": stats,
//                      "ate_aligned_horizontal_m": stats, "ate_gauge_free_horizontal_m": stats (after the best
//                      rotation and scale about the estimate's start, no shift; AteResult), "gauge_free_scale",
//                      "gauge_free_rotation_deg", "ate_position_m": stats,
//                      "rpe_translation_percent", "rpe_rotation_deg" (means over the RPE window),
//                      "lines": [{"index", "horizontal_rmse_m"}]},
//                  "ate_horizontal_rmse_improvement_percent", "ate_aligned_horizontal_rmse_improvement_percent",
//                  "ate_gauge_free_horizontal_rmse_improvement_percent"},
//   "heightmap": null | {"seabed_path", "dr" | "slam": null | {"path", "mae_m", "rmse_m", "median_m", "max_m",
//                        "bias_m", "coverage_fraction", "compared_cells"}, "mae_improvement_percent"},
//   "closures": null | {"path", "accepted", "rejected", "pending", "superseded", "total",
//                       "rejection_reasons": {"chi_square_gate": n, ...}},
//   "closure_errors": null | {"accepted", "closure": errors, "dr": errors} (accepted closures' relative
//                     pose - the truth's and DR's - the truth's, in A's body frame; errors as in
//                     sss-eval's JSON, report.hpp),
//   "lce": null | {"seabed_depth_m", "seabed_depth_source", "correspondences", "truth_max_m" (self-check),
//                  "dr": stats, "slam": stats, "mean_improvement_percent"} (landmark consistency on
//                  correspondences made from the truth, as sss-eval --lce),
//   "run": null | {"pings", "subframes", "pairs_attempted", "closures_accepted", "closures_rejected",
//                  "wall_s", "mission_s", "real_time_factor", "peak_rss_mib"},
//   "notes": [...], "files": [...]
// }
#pragma once

#include "tools/eval/closure_metrics.hpp"
#include "tools/eval/figure_script.hpp"
#include "tools/eval/heightmap_metrics.hpp"
#include "tools/eval/landmark_consistency.hpp"
#include "tools/eval/trajectory_io.hpp"
#include "tools/eval/trajectory_metrics.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace sss::eval {

struct RunReportRequest {
  std::string mission_dir;  // sss-sim --out folder
  std::string run_dir;      // sss-process output folder
  std::string out_dir;      // created if missing
  std::string title;        // empty: "sss-slam run <run folder name>"
  FigureScriptOptions figures;  // the interpreter and the script that draw the PNGs
};

struct RunReportOptions {
  TrajectoryEvaluationOptions trajectory;
  double rpe_window_m = 100.0;     // the table shows the configured RPE window closest to this
  double same_change_percent = 2.0;  // |change| below this: "about the same" in the verdict
  TrueCorrespondenceOptions lce;     // landmark consistency error, as sss-eval --lce
  double lce_altitude_m = 18.0;      // flat seabed without seabed.yaml: truth median depth + this
};

// ---- loop_closures.csv ---------------------------------------------------------------------

struct LoopClosureRecord {
  int line = 0;                  // in the file, for messages
  std::string status;            // accepted | rejected | pending | superseded
  std::string rejection;         // none | chi_square_gate | inconsistent | no_support | "" (no column)
  Eigen::Vector2d centre_a_north_east_m = Eigen::Vector2d::Zero();  // under the final SLAM estimate
  Eigen::Vector2d centre_b_north_east_m = Eigen::Vector2d::Zero();
  std::string subframes;  // "A-B" (subframe_id_a, subframe_id_b), "" without those columns
  // The tie report (before_* / after_* columns): the closure's offset from DR's relative pose and
  // from the final estimate's, along, across, depth (m) and heading (rad).
  std::optional<Eigen::Vector4d> before, after;
};

struct LoopClosureCounts {
  size_t accepted = 0;
  size_t rejected = 0;
  size_t pending = 0;
  size_t superseded = 0;
  std::map<std::string, size_t> rejection_reasons;  // of the rejected closures
  size_t total() const { return accepted + rejected + pending + superseded; }
};

// Header line first (columns are found by name, in any order; extra columns are ignored; needed:
// status, north_a_m, east_a_m, north_b_m, east_b_m), then one closure per line; '#' lines and
// blank lines are skipped. Fails with "FILE:LINE: ..." on the first problem.
sss::core::Status readLoopClosures(const std::string& path, std::vector<LoopClosureRecord>& closures);
LoopClosureCounts countClosures(const std::vector<LoopClosureRecord>& closures);

// ---- summary.json --------------------------------------------------------------------------

struct RunSummary {
  static constexpr double kMissing = std::numeric_limits<double>::quiet_NaN();
  double pings = kMissing;
  double subframes = kMissing;
  double pairs_attempted = kMissing;
  double closures_accepted = kMissing;
  double closures_rejected = kMissing;
  double wall_s = kMissing;
  double mission_s = kMissing;
  double real_time_factor = kMissing;
  double peak_rss_mib = kMissing;
  // Survey products (optional blocks of summary.json; NaN / empty when absent).
  double covered_m2 = kMissing, fraction_seen_twice = kMissing;
  double fixes_fed = kMissing, fixes_accepted = kMissing, fixes_rejected = kMissing, fixes_rms_residual_m = kMissing;
  bool calibration_estimated = false;
  double dvl_scale = kMissing, dvl_scale_sigma = kMissing, heading_bias_rad = kMissing,
         heading_bias_sigma_rad = kMissing;
  std::string geotiff_crs;
  std::vector<std::string> geotiffs;
  std::vector<std::string> missing_keys;  // expected keys absent or not numbers
};

// Reads the JSON object (JSON is YAML flow, so yaml-cpp reads it). Fails with a message naming
// the file when it cannot be read or is not an object; absent keys only land in missing_keys.
sss::core::Status readRunSummary(const std::string& path, RunSummary& summary);

// ---- the report ----------------------------------------------------------------------------

enum class RunReportStatus {
  ok,
  bad_input,     // a required input is missing or unusable (sss-report exits 2)
  write_failed,  // an output could not be written (exit 1)
};

struct RunHeightmap {
  bool present = false;  // read and compared with the seabed
  std::string path;
  HeightmapErrorResult error;
};

struct RunReport {
  RunReportStatus status = RunReportStatus::ok;
  std::string error;  // when status != ok: names the file and what to do
  std::string title;
  std::string verdict;  // one sentence: did SLAM make the navigation better than DR?
  std::string outcome;  // "better", "worse" or "same" (horizontal ATE RMSE)
  std::vector<std::string> notes;  // missing or unusable optional inputs, figures not drawn

  std::string truth_path, dr_path, slam_path;
  // The truth's frame (its TUM header); the run's files are re-expressed in it when theirs differs.
  std::optional<sss::core::MissionOrigin> truth_origin;
  size_t truth_poses = 0;
  double duration_s = 0.0;
  double distance_m = 0.0;
  std::vector<SurveyLine> lines;
  TrajectoryEvaluation dr;
  TrajectoryEvaluation slam;
  size_t rpe_index = 0;  // into dr.rpe / slam.rpe: the window closest to options.rpe_window_m
  double rpe_window_m = std::numeric_limits<double>::quiet_NaN();
  double ate_improvement_percent = std::numeric_limits<double>::quiet_NaN();
  double aligned_ate_improvement_percent = std::numeric_limits<double>::quiet_NaN();
  double gauge_free_ate_improvement_percent = std::numeric_limits<double>::quiet_NaN();

  std::string seabed_path;  // empty when no seabed was read
  RunHeightmap heightmap_dr;
  RunHeightmap heightmap_slam;
  double heightmap_improvement_percent = std::numeric_limits<double>::quiet_NaN();  // of the MAE

  bool has_closures = false;
  std::string closures_path;
  std::vector<LoopClosureRecord> closures;
  LoopClosureCounts closure_counts;
  bool has_closure_errors = false;   // the accepted closures against the truth (and DR)
  size_t closure_errors_accepted = 0;
  RelativePoseErrorStatistics closure_errors;
  RelativePoseErrorStatistics closure_errors_dr;

  bool has_lce = false;
  double lce_seabed_depth_m = std::numeric_limits<double>::quiet_NaN();
  std::string lce_seabed_depth_source;
  size_t lce_correspondences = 0;
  double lce_truth_max_m = std::numeric_limits<double>::quiet_NaN();
  ErrorStatistics lce_dr;
  ErrorStatistics lce_slam;

  bool has_summary = false;
  RunSummary summary;

  std::vector<std::string> files;  // every file written, out_dir/NAME
  std::string index_html;          // out_dir/index.html, or report.md when the page could not be drawn
};

// Reads every input, computes the metrics and writes the report. Never throws for bad input.
RunReport writeRunReport(const RunReportRequest& request, const RunReportOptions& options = {});

// The short terminal table: horizontal ATE RMSE (raw, SE(3)-aligned, gauge-free) and LCE mean DR /
// SLAM / improvement, heightmap MAE, closures, real-time factor, the path of index.html.
std::string formatRunTable(const RunReport& report);

// metrics.json as described at the top of this file.
std::string runReportJson(const RunReport& report, const RunReportRequest& request);

}  // namespace sss::eval
