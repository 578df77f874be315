// Options of the relative-pose estimator: validation and the config file's keys. See relative_pose.hpp.
#include "pipeline/matcher/relative_pose.hpp"

#include <string>
#include <vector>

namespace sss::matcher {

std::vector<std::string> validateRelativePoseOptions(const RelativePoseOptions& o) {
  std::vector<std::string> problems;
  if (!(o.range_sigma_m > 0.0)) problems.push_back("range_sigma_m must be > 0");
  if (!(o.beam_width_rad > 0.0)) problems.push_back("beam_width_rad must be > 0");
  if (!(o.peak_sigma_min_factor > 0.0 && o.peak_sigma_min_factor <= 1.0 && o.peak_sigma_max_factor >= 1.0))
    problems.push_back("peak_sigma_min_factor must be in (0, 1] and peak_sigma_max_factor >= 1");
  if (!(o.seabed_sigma_m > 0.0)) problems.push_back("seabed_sigma_m must be > 0");
  if (o.ransac_subset < 3) problems.push_back("ransac_subset must be >= 3");
  if (o.ransac_iterations < 1) problems.push_back("ransac_iterations must be >= 1");
  if (o.ransac_score_sample < 1) problems.push_back("ransac_score_sample must be >= 1");
  if (o.max_correspondences < o.ransac_subset) problems.push_back("max_correspondences must be >= ransac_subset");
  if (!(o.inlier_threshold_sigma > 0.0)) problems.push_back("inlier_threshold_sigma must be > 0");
  if (!(o.robust_loss_scale >= 0.0)) problems.push_back("robust_loss_scale must be >= 0 (0: plain least squares)");
  if (o.min_inliers < 0) problems.push_back("min_inliers must be >= 0");
  if (o.min_inlier_fraction < 0.0 || o.min_inlier_fraction > 1.0) problems.push_back("min_inlier_fraction in [0, 1]");
  if (!(o.max_mean_cost > 0.0)) problems.push_back("max_mean_cost must be > 0");
  if (o.max_solver_iterations < 1) problems.push_back("max_solver_iterations must be >= 1");
  if (!(o.time_limit_s >= 0.0)) problems.push_back("time_limit_s must be >= 0 (0: no wall-clock cap)");
  if (!(o.covariance_cluster_m >= 0.0))
    problems.push_back("covariance_cluster_m must be >= 0 (0: Ceres' covariance with the assumed sigmas)");
  if (!(o.range_bias_sigma_m > 0.0)) problems.push_back("range_bias_sigma_m must be > 0");
  if (o.min_covariance_clusters < 2) problems.push_back("min_covariance_clusters must be >= 2");
  return problems;
}

void readRelativePoseOptions(sss::core::ConfigSection& section, RelativePoseOptions& options) {
  using sss::core::atLeast;
  using sss::core::greaterThan;
  using sss::core::inRange;
  section.optional("range_sigma_m", options.range_sigma_m, {greaterThan(0.0)});
  section.optional("beam_width_rad", options.beam_width_rad, {inRange(1e-5, 1.0)});
  section.optional("range_sigma_from_peak", options.range_sigma_from_peak);
  section.optional("peak_sigma_min_factor", options.peak_sigma_min_factor, {inRange(0.01, 1.0)});
  section.optional("peak_sigma_max_factor", options.peak_sigma_max_factor, {inRange(1.0, 100.0)});
  section.optional("seabed_sigma_m", options.seabed_sigma_m, {greaterThan(0.0)});
  section.optional("use_seabed_prior", options.use_seabed_prior);
  section.optional("ransac_subset", options.ransac_subset, {inRange(3, 100)});
  section.optional("ransac_iterations", options.ransac_iterations, {inRange(1, 100000)});
  section.optional("max_correspondences", options.max_correspondences, {inRange(3, 100000)});
  section.optional("ransac_score_sample", options.ransac_score_sample, {inRange(1, 1000000)});
  section.optional("inlier_threshold_sigma", options.inlier_threshold_sigma, {greaterThan(0.0)});
  section.optional("robust_loss_scale", options.robust_loss_scale, {sss::core::atLeast(0.0)});
  section.optional("min_inliers", options.min_inliers, {atLeast(0)});
  section.optional("min_inlier_fraction", options.min_inlier_fraction, {inRange(0.0, 1.0)});
  section.optional("max_mean_cost", options.max_mean_cost, {greaterThan(0.0)});
  section.optional("max_solver_iterations", options.max_solver_iterations, {inRange(1, 1000)});
  int seed = static_cast<int>(options.seed);
  section.optional("seed", seed, {atLeast(0)});
  section.optional("seabed_between_lines", options.seabed_between_lines);
  options.seed = static_cast<std::uint64_t>(seed);
  section.optional("time_limit_s", options.time_limit_s, {sss::core::atLeast(0.0)});
  section.optional("covariance_cluster_m", options.covariance_cluster_m, {sss::core::atLeast(0.0)});
  section.optional("min_covariance_clusters", options.min_covariance_clusters, {inRange(2, 100000)});
  section.optional("seabed_relief_covariance", options.seabed_relief_covariance);
  section.optional("seabed_tilt_covariance", options.seabed_tilt_covariance);
  section.optional("range_bias_covariance", options.range_bias_covariance);
  section.optional("range_bias_sigma_m", options.range_bias_sigma_m, {greaterThan(0.0)});
  if (options.max_correspondences < options.ransac_subset)
    section.addProblem("max_correspondences", std::to_string(options.max_correspondences),
                       "must be >= ransac_subset (" + std::to_string(options.ransac_subset) + ")");
}

}  // namespace sss::matcher
