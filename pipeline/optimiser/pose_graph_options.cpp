// Options of the sliding-window pose graph: validation and reading from the configuration.
#include "pipeline/optimiser/pose_graph.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace sss::optimiser {

// ---- options ----------------------------------------------------------------------------------

std::vector<std::string> validatePoseGraphOptions(const PoseGraphOptions& o) {
  std::vector<std::string> problems;
  auto positive = [&](double value, const char* name) {
    if (!(value > 0.0) || !std::isfinite(value)) problems.push_back(std::string(name) + " must be > 0");
  };
  auto nonNegative = [&](double value, const char* name) {
    if (!(value >= 0.0) || !std::isfinite(value)) problems.push_back(std::string(name) + " must be >= 0");
  };
  if (o.window_size < 2) problems.push_back("window_size must be >= 2");
  nonNegative(o.odometry_random_walk_m_per_sqrt_m, "odometry_random_walk_m_per_sqrt_m");
  nonNegative(o.odometry_drift_fraction, "odometry_drift_fraction");
  positive(o.odometry_min_sigma_m, "odometry_min_sigma_m");
  positive(o.odometry_depth_sigma_m, "odometry_depth_sigma_m");
  nonNegative(o.odometry_heading_random_walk_rad_per_sqrt_m, "odometry_heading_random_walk_rad_per_sqrt_m");
  positive(o.odometry_min_heading_sigma_rad, "odometry_min_heading_sigma_rad");
  positive(o.odometry_attitude_sigma_rad, "odometry_attitude_sigma_rad");
  nonNegative(o.absolute_depth_sigma_m, "absolute_depth_sigma_m");
  nonNegative(o.absolute_roll_pitch_sigma_rad, "absolute_roll_pitch_sigma_rad");
  nonNegative(o.absolute_heading_sigma_rad, "absolute_heading_sigma_rad");
  positive(o.first_node_sigma_m, "first_node_sigma_m");
  positive(o.first_node_sigma_rad, "first_node_sigma_rad");
  if (o.robust_loss != "cauchy" && o.robust_loss != "huber" && o.robust_loss != "none")
    problems.push_back("robust_loss must be one of cauchy, huber, none (got '" + o.robust_loss + "')");
  positive(o.robust_loss_scale, "robust_loss_scale");
  if (o.min_closure_inliers < 0) problems.push_back("min_closure_inliers must be >= 0");
  positive(o.gate_chi2, "gate_chi2");
  if (o.gate_min_accepted_closures < 0) problems.push_back("gate_min_accepted_closures must be >= 0");
  if (!(o.smoothed_gate_chi2 >= 0.0)) problems.push_back("smoothed_gate_chi2 must be >= 0 (0: off)");
  positive(o.pcm_chi2, "pcm_chi2");
  if (o.pcm_max_closures < 1) problems.push_back("pcm_max_closures must be >= 1");
  if (o.min_consistent_closures < 1) problems.push_back("min_consistent_closures must be >= 1");
  if (o.min_consistent_closures > o.pcm_max_closures)
    problems.push_back("min_consistent_closures must be <= pcm_max_closures");
  if (o.max_iterations < 1) problems.push_back("max_iterations must be >= 1");
  nonNegative(o.max_solver_time_s, "max_solver_time_s");
  if (o.full_smoothing_max_iterations < 1) problems.push_back("full_smoothing_max_iterations must be >= 1");
  if (o.closure_reweighting != "none" && o.closure_reweighting != "dr_bound" &&
      o.closure_reweighting != "variance_components")
    problems.push_back("closure_reweighting must be one of none, dr_bound, variance_components (got '" +
                       o.closure_reweighting + "')");
  if (o.variance_component_iterations < 1) problems.push_back("variance_component_iterations must be >= 1");
  if (!(o.separation_bias_sigma_m >= 0.0)) problems.push_back("separation_bias_sigma_m must be >= 0 (0: off)");
  if (!(o.separation_bias_min_lateral_m >= 0.0)) problems.push_back("separation_bias_min_lateral_m must be >= 0");
  if (!(o.separation_bias_significance >= 0.0))
    problems.push_back("separation_bias_significance must be >= 0 (sigmas; 0: always significant)");
  positive(o.fix_gate_chi2, "fix_gate_chi2");
  nonNegative(o.gnss_fix_correlation_s, "gnss_fix_correlation_s");
  nonNegative(o.usbl_fix_correlation_s, "usbl_fix_correlation_s");
  if (o.calibration != "auto" && o.calibration != "heading" && o.calibration != "always" && o.calibration != "never")
    problems.push_back("calibration must be one of auto, heading, always, never (got '" + o.calibration + "')");
  positive(o.calibration_scale_sigma, "calibration_scale_sigma");
  nonNegative(o.calibration_period_s, "calibration_period_s");
  nonNegative(o.calibrated_odometry_drift_fraction, "calibrated_odometry_drift_fraction");
  positive(o.calibration_heading_bias_sigma_rad, "calibration_heading_bias_sigma_rad");
  positive(o.calibration_heading_deviation_sigma_rad, "calibration_heading_deviation_sigma_rad");
  positive(o.variance_factor_min, "variance_factor_min");
  positive(o.variance_factor_max, "variance_factor_max");
  if (o.variance_factor_min > 1.0 || o.variance_factor_max < 1.0)
    problems.push_back("variance_factor_min must be <= 1 <= variance_factor_max (1: the configured covariance)");
  positive(o.degraded_after_s, "degraded_after_s");
  positive(o.nominal_speed_m_s, "nominal_speed_m_s");
  return problems;
}

void readPoseGraphOptions(sss::core::ConfigSection& section, PoseGraphOptions& options) {
  using sss::core::atLeast;
  using sss::core::greaterThan;
  using sss::core::inRange;
  section.optional("window_size", options.window_size, {inRange(2, 10000)});
  section.optional("odometry_random_walk_m_per_sqrt_m", options.odometry_random_walk_m_per_sqrt_m, {atLeast(0.0)});
  section.optional("odometry_drift_fraction", options.odometry_drift_fraction, {inRange(0.0, 1.0)});
  section.optional("odometry_min_sigma_m", options.odometry_min_sigma_m, {greaterThan(0.0)});
  section.optional("odometry_depth_sigma_m", options.odometry_depth_sigma_m, {greaterThan(0.0)});
  section.optional("odometry_heading_random_walk_rad_per_sqrt_m", options.odometry_heading_random_walk_rad_per_sqrt_m,
                   {atLeast(0.0)});
  section.optional("odometry_min_heading_sigma_rad", options.odometry_min_heading_sigma_rad, {greaterThan(0.0)});
  section.optional("odometry_attitude_sigma_rad", options.odometry_attitude_sigma_rad, {greaterThan(0.0)});
  section.optional("odometry_drift_from_ins", options.odometry_drift_from_ins);
  InsDriftEstimatorOptions& drift = options.ins_drift;
  section.optional("ins_drift_min_distance_m", drift.min_distance_m, {inRange(1.0, 1e6)});
  section.optional("ins_drift_min_fraction", drift.min_fraction, {inRange(0.0, 1.0)});
  section.optional("ins_drift_max_fraction", drift.max_fraction, {inRange(0.0, 1.0)});
  if (drift.min_fraction > drift.max_fraction)
    section.addProblem("ins_drift_min_fraction", std::to_string(drift.min_fraction),
                       "must not exceed ins_drift_max_fraction (" + std::to_string(drift.max_fraction) + ")");
  section.optional("absolute_depth_sigma_m", options.absolute_depth_sigma_m, {atLeast(0.0)});
  section.optional("absolute_roll_pitch_sigma_rad", options.absolute_roll_pitch_sigma_rad, {atLeast(0.0)});
  section.optional("absolute_heading_sigma_rad", options.absolute_heading_sigma_rad, {atLeast(0.0)});
  section.optional("first_node_sigma_m", options.first_node_sigma_m, {greaterThan(0.0)});
  section.optional("first_node_sigma_rad", options.first_node_sigma_rad, {greaterThan(0.0)});
  section.optional("first_node_sigma_from_ins", options.first_node_sigma_from_ins);
  section.optional("robust_loss", options.robust_loss, {sss::core::oneOf({"cauchy", "huber", "none"})});
  section.optional("robust_loss_scale", options.robust_loss_scale, {greaterThan(0.0)});
  section.optional("min_closure_inliers", options.min_closure_inliers, {atLeast(0)});
  section.optional("gate_chi2", options.gate_chi2, {greaterThan(0.0)});
  section.optional("gate_min_accepted_closures", options.gate_min_accepted_closures, {atLeast(0)});
  section.optional("smoothed_gate_chi2", options.smoothed_gate_chi2, {atLeast(0.0)});
  section.optional("pcm_chi2", options.pcm_chi2, {greaterThan(0.0)});
  section.optional("pcm_max_closures", options.pcm_max_closures, {inRange(1, 10000)});
  section.optional("min_consistent_closures", options.min_consistent_closures, {atLeast(1)});
  section.optional("pcm_count_independent_subframes", options.pcm_count_independent_subframes);
  section.optional("max_iterations", options.max_iterations, {inRange(1, 1000)});
  section.optional("max_solver_time_s", options.max_solver_time_s, {atLeast(0.0)});
  section.optional("full_smoothing_max_iterations", options.full_smoothing_max_iterations, {inRange(1, 10000)});
  section.optional("closure_reweighting", options.closure_reweighting,
                   {sss::core::oneOf({"none", "dr_bound", "variance_components"})});
  section.optional("variance_component_iterations", options.variance_component_iterations, {inRange(1, 100)});
  section.optional("separation_bias_sigma_m", options.separation_bias_sigma_m, {inRange(0.0, 100.0)});
  section.optional("separation_bias_min_lateral_m", options.separation_bias_min_lateral_m, {inRange(0.0, 10000.0)});
  section.optional("separation_bias_apply", options.separation_bias_apply);
  section.optional("separation_bias_widen", options.separation_bias_widen);
  section.optional("separation_bias_widen_with_fixes", options.separation_bias_widen_with_fixes);
  section.optional("separation_bias_significance", options.separation_bias_significance, {inRange(0.0, 100.0)});
  section.optional("fix_gate_chi2", options.fix_gate_chi2, {greaterThan(0.0)});
  section.optional("gnss_fix_correlation_s", options.gnss_fix_correlation_s, {atLeast(0.0)});
  section.optional("usbl_fix_correlation_s", options.usbl_fix_correlation_s, {atLeast(0.0)});
  section.optional("calibration", options.calibration, {sss::core::oneOf({"auto", "heading", "always", "never"})});
  section.optional("calibration_scale_sigma", options.calibration_scale_sigma, {inRange(1e-6, 0.5)});
  section.optional("calibration_period_s", options.calibration_period_s, {inRange(0.0, 1e6)});
  section.optional("calibrated_odometry_drift_fraction", options.calibrated_odometry_drift_fraction, {inRange(0.0, 1.0)});
  section.optional("calibration_heading_bias_sigma_rad", options.calibration_heading_bias_sigma_rad, {inRange(1e-6, 0.5)});
  section.optional("calibration_heading_deviation_sigma_rad", options.calibration_heading_deviation_sigma_rad,
                   {inRange(1e-6, 0.5)});
  section.optional("variance_factor_min", options.variance_factor_min, {inRange(1e-6, 1.0)});
  section.optional("variance_factor_max", options.variance_factor_max, {inRange(1.0, 1e6)});
  section.optional("degraded_after_s", options.degraded_after_s, {greaterThan(0.0)});
  section.optional("nominal_speed_m_s", options.nominal_speed_m_s, {greaterThan(0.0)});
  if (options.min_consistent_closures > options.pcm_max_closures)
    section.addProblem("min_consistent_closures", std::to_string(options.min_consistent_closures),
                       "must be <= pcm_max_closures (" + std::to_string(options.pcm_max_closures) + ")");
}

}  // namespace sss::optimiser
