// Relative pose of a subframe pair from dense side-scan correspondences: range + fan-plane
// residuals, seabed depth prior, DR odometry prior, RANSAC as in the paper (Alg. 1), Ceres.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/core/config.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/core/subframe_types.hpp"
#include "pipeline/matcher/dense_matcher.hpp"

namespace sss::matcher {

struct RelativePoseOptions {
  double range_sigma_m = 0.1;       // sigma_r of a slant range (about a bin), paper eq. (4)
  double beam_width_rad = 0.0087;   // alpha: plane residual sigma = r * alpha, paper eq. (4)
  // Each match's range sigma scaled by its ZNCC peak's sharpness across range, relative to the
  // pair's median (Correspondence::peak_curvature_col; factor sqrt(median / curvature) kept within
  // [peak_sigma_min_factor, peak_sigma_max_factor]). false: range_sigma_m for every match. Off by
  // default: on 12 randomised missions it moved weight onto matches over relief, whose error is a
  // bias common to them, not noise (geometric mean SLAM/DR 0.704 -> 0.751; README).
  bool range_sigma_from_peak = false;
  double peak_sigma_min_factor = 0.5;
  double peak_sigma_max_factor = 3.0;
  // Landmark depth prior: the seabed under A's ping from altimetry (sonar depth + altitude).
  // Without it a lateral offset between two lines on a flat seabed is absorbed by landmark depths.
  double seabed_sigma_m = 0.3;
  bool use_seabed_prior = true;     // false only to demonstrate the unobservable lateral offset
  // The prior's depth varies linearly from the seabed under A's ping to the seabed under B's
  // (both from altimetry): a sloping seabed no longer biases the landmark depths, and through
  // them the lateral offset. false: level seabed at A's depth (the first version).
  bool seabed_between_lines = true;
  int ransac_subset = 6;            // paper: 6 correspondences per hypothesis
  int ransac_iterations = 200;      // paper: 200
  int ransac_score_sample = 300;    // matches each hypothesis is scored on (evenly sampled)
  int max_correspondences = 400;    // inliers used in the final refinement, sampled evenly
  double inlier_threshold_sigma = 3.0;
  // Cauchy loss on each match's range + plane residuals in the solves (whitened units; 0: plain
  // least squares, as the paper). Dense matches have heavy-tailed errors: shadows seen from the
  // other side and oblique trawl marks shift a patch by a pixel or more in a direction that varies
  // from pair to pair, and the RANSAC inlier band (3 sigma) keeps many of them; their mean biases
  // a least-squares pose, a Cauchy loss follows the bulk.
  double robust_loss_scale = 0.0;
  // Acceptance: inlier count and fraction, and the mean squared whitened range and plane
  // residuals of the final refinement (about 1 for a consistent model).
  int min_inliers = 30;
  double min_inlier_fraction = 0.3;
  double max_mean_cost = 2.5;
  int max_solver_iterations = 50;   // final refinement; hypotheses use a quarter of it
  std::uint64_t seed = 1;
  // Optional wall-clock cap (0 = none). The work is already bounded by the iteration counts above;
  // a cap makes the result depend on machine load, so offline runs and tests leave it at 0.
  // When set, RANSAC stops at 60 % of it and the refinement uses the rest.
  double time_limit_s = 0.0;
  // Closure covariance from the residuals (cluster-robust sandwich, see relative_pose.cpp): the
  // matches are grouped into square patches of seabed of this side (in A's centre frame), whose
  // errors are taken as independent of one another's; inside a patch they may all move together.
  // 20 m is twice the 10 m matching patch, so that matches of two clusters share no texture pixel.
  // 0 (default): Ceres' covariance, which takes every match as independent with the sigmas above
  // (PairMatcherOptions::covariance_scale then inflates it). Not the default yet: on randomised
  // missions the error common to a whole pair, which no spread inside the pair shows, is 3-8x the
  // cluster-robust sigma (README, "Closure covariance from the residuals").
  double covariance_cluster_m = 0.0;
  // Fewer patches than this: the spread between them says too little to be trusted (rejected).
  int min_covariance_clusters = 4;
  // Relief between the lines moves every landmark alike, which no spread between clusters shows:
  // the covariance also gets the pose's sensitivity to a common offset of the seabed under the
  // matches, times the seabed relief both lines' altimetry measured along their subframes (so a
  // closure over rough ground says its lateral direction is weak; a flat seabed costs nothing).
  // Added to Ceres' covariance as well as to the cluster-robust one (not scaled by
  // PairMatcherOptions::covariance_scale: it is a physical size). The relief the landmarks
  // themselves triangulate was tried as well: at the randomised missions' altitudes (7-27 m) the
  // seabed prior holds them and it never exceeded the altimetry's.
  bool seabed_relief_covariance = true;
  // The same for a tilt of the seabed along the strip both lines see: relief that rises along the
  // strip is a lateral ramp in the ranges, so a heading error of h k (1/g_a + 1/g_b), and at far
  // range an along-track error as well; nothing in the residuals shows it. Its size is the relief
  // the altimetry shows (as above) taken as a ramp over the subframe's length L: slope
  // sigma sqrt(12) / L. Not scaled by covariance_scale either.
  bool seabed_tilt_covariance = true;
  // Relief range bias: a raised feature (boulder, rock) shows each line the face turned towards it,
  // so the pixels a match pairs lie nearer each sonar than one point both lines see; their mean over
  // the pair's matches is a range bias common to the pair. Where the lines look at their overlap
  // from opposite sides it is a lateral offset (parallel lines come out closer together), and
  // nothing in the residuals shows it; between crossing lines it shortens the closure too. The
  // covariance gets the pose's sensitivity to such a bias times range_bias_sigma_m (not scaled by
  // PairMatcherOptions::covariance_scale: a physical size, like the seabed relief terms).
  bool range_bias_covariance = true;
  double range_bias_sigma_m = 0.3;
};

// Everything the estimator needs from the two subframes, in each subframe's own DR frame.
struct RelativePoseInput {
  std::vector<sss::core::Pose> dr_poses_a;  // T_world_body per ping (row) of A, DR
  std::vector<sss::core::Pose> dr_poses_b;
  std::vector<double> altitude_a_m;         // sonar height above the seabed per ping
  std::vector<double> altitude_b_m;
  int centre_a = 0;                         // row of each subframe's centre ping
  int centre_b = 0;
  // Ground-range axis and sonar mounting of both subframes (same vehicle and transform):
  // columns map to ground range through it, pixels to seabed points through georeferencePixel.
  sss::core::SubframeGeometry geometry;
  std::vector<Correspondence> matches;
  // Of the DR relative pose between the centre poses, tangent [dt, dr] (grows with distance).
  sss::core::Matrix6d dr_covariance_ab = sss::core::Matrix6d::Identity();
};

struct RelativePoseResult {
  bool accepted = false;
  std::string reason;                       // why rejected (empty when accepted)
  sss::core::Pose T_a_b;                    // B's centre body frame in A's centre body frame
  // [dt, dr] at T_a_b (boxPlus): cluster-robust (from the residuals) unless covariance_cluster_m is 0
  sss::core::Matrix6d covariance = sss::core::Matrix6d::Zero();
  sss::core::Matrix6d model_covariance = sss::core::Matrix6d::Zero();  // Ceres, the assumed sigmas
  int covariance_clusters = 0;              // seabed patches of the refined inliers (0 unless covariance_cluster_m > 0)
  double seabed_relief_sigma_m = 0.0;       // from both lines' altimetry (seabed_relief_covariance)
  double seabed_tilt_sigma = 0.0;           // slope along track, m per m (seabed_tilt_covariance)
  // The relief part of `covariance` (already in it): a caller that scales the model covariance
  // (PairMatcherOptions::covariance_scale) scales covariance - relief_covariance only.
  sss::core::Matrix6d relief_covariance = sss::core::Matrix6d::Zero();
  int num_inliers = 0;                      // among all matches, scored with the final pose
  double range_cost = 0.0;                  // mean squared whitened range residual (refinement)
  double plane_cost = 0.0;                  // mean squared whitened plane residual (refinement)
  // d T_a_b / d bias, tangent [dt, dr]: how far the pose moves when every matched pixel lies one
  // metre nearer both sonars (range_bias_covariance uses it). Zero when no covariance term needs
  // it (range_bias_covariance, seabed_relief_covariance and covariance_cluster_m all off).
  sss::core::Vector6d range_bias_sensitivity = sss::core::Vector6d::Zero();
  double total_cost = 0.0;                  // Ceres final cost of the refinement (0.5 sum r^2)
  std::vector<int> inlier_indices;          // into matches: the refined ones (<= max_correspondences)
  std::vector<Eigen::Vector3d> landmarks_a; // parallel to inlier_indices, in A's centre body frame
  // Every match consistent with the final pose (num_inliers of them), for the bathymetric point
  // cloud, with a landmark start for each: the refined landmark where there is one, else the
  // landmark fitted to the final pose (the inlier test's own Gauss-Newton), in A's centre frame.
  std::vector<int> all_inlier_indices;
  std::vector<Eigen::Vector3d> all_inlier_landmarks_a;
  int ransac_iterations_run = 0;
  double seconds = 0.0;
};

// Never throws for field data: bad input comes back as accepted == false with a reason.
RelativePoseResult estimateRelativePose(const RelativePoseInput& input, const RelativePoseOptions& options);

std::vector<std::string> validateRelativePoseOptions(const RelativePoseOptions& options);
void readRelativePoseOptions(sss::core::ConfigSection& section, RelativePoseOptions& options);

}  // namespace sss::matcher
