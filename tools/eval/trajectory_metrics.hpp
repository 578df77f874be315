// Trajectory accuracy against ground truth: time association, SE(3) Umeyama alignment, absolute
// trajectory error (3D and horizontal, raw, aligned and gauge-free), relative pose error over
// distance windows, the error along the mission, and the ATE per survey line found in the truth.
#pragma once

#include "pipeline/core/pose.hpp"
#include "tools/eval/trajectory_io.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace sss::eval {

// Summary of a set of non-negative errors; NaN everywhere when count == 0.
struct ErrorStatistics {
  size_t count = 0;
  double rmse = std::numeric_limits<double>::quiet_NaN();
  double mean = std::numeric_limits<double>::quiet_NaN();
  double median = std::numeric_limits<double>::quiet_NaN();
  double max = std::numeric_limits<double>::quiet_NaN();
};
ErrorStatistics errorStatistics(std::vector<double> values);

// ---- time association ----------------------------------------------------------------------

struct AssociationOptions {
  // Truth is interpolated (slerp + linear) at each estimate time when the estimate time falls
  // between two truth samples at most max_interpolation_gap_s apart.
  bool interpolate_truth = true;
  double max_interpolation_gap_s = 1.0;
  // Otherwise (or outside the truth's time span) the nearest truth sample is used when it lies
  // within this tolerance; else the estimate pose is left unmatched.
  double max_time_difference_s = 0.02;
};

struct AssociatedPose {
  int64_t utime_us = 0;
  sss::core::Pose truth;     // T_world_body of the truth at utime_us
  sss::core::Pose estimate;  // T_world_body of the estimate at utime_us
};

struct Association {
  std::vector<AssociatedPose> pairs;  // in time order
  size_t exact = 0;                   // estimate time found in the truth
  size_t interpolated = 0;
  size_t nearest = 0;
  size_t unmatched = 0;
};

Association associate(const Trajectory& truth, const Trajectory& estimate, const AssociationOptions& options = {});

// The pose at utime_us, interpolated between the neighbouring samples when they are at most
// max_gap_s apart; the sample itself on an exact hit; nullopt outside the trajectory or in a gap.
std::optional<sss::core::Pose> poseAtTime(const Trajectory& trajectory, int64_t utime_us, double max_gap_s);

// ---- alignment -----------------------------------------------------------------------------

// Umeyama (1991) without scale: the rigid T minimising sum |target_i - T * source_i|^2. With one
// point the rotation is the identity; with collinear points the rotation about the line is the
// one SVD returns (any is optimal). nullopt when the inputs are empty or differ in length.
std::optional<sss::core::Pose> umeyamaAlignment(const std::vector<Eigen::Vector3d>& source,
                                                const std::vector<Eigen::Vector3d>& target);

// ---- survey lines --------------------------------------------------------------------------

// Line segmentation rule (on the truth's horizontal path, so it does not depend on the estimate):
//  1. turn rate at every sample = |course of the chord [s, s + w/2] - course of [s - w/2, s]| / (w/2)
//     with s the horizontal distance along the path and w = course_window_m (a circle of radius R
//     gives exactly 1/R);
//  2. samples with turn rate <= max_turn_rate_deg_per_m are steady; contiguous steady samples form
//     a candidate line;
//  3. a candidate is cut where its course (chord over w) departs from the course of its first w
//     metres by more than max_heading_change_deg (a slow curve is not one line);
//  4. lines shorter than min_line_length_m are dropped (turn fragments, manoeuvres).
// Defaults: a 20 m window and 0.15 deg/m exclude turns of radius below ~380 m, which covers AUV
// turns between lines (10-150 m) while the wobble of a line-following autopilot stays well below.
struct LineSegmentationOptions {
  double course_window_m = 20.0;
  double max_turn_rate_deg_per_m = 0.15;
  double max_heading_change_deg = 15.0;
  double min_line_length_m = 50.0;
};

struct SurveyLine {
  int index = 0;          // 0, 1, ... in time order
  size_t first_pose = 0;  // indices into the truth trajectory, inclusive
  size_t last_pose = 0;
  int64_t start_utime_us = 0;
  int64_t end_utime_us = 0;
  double length_m = 0.0;     // horizontal path length
  double heading_deg = 0.0;  // course from the first to the last pose, [0, 360) clockwise from north
};

std::vector<SurveyLine> segmentSurveyLines(const Trajectory& truth, const LineSegmentationOptions& options = {});

// ---- evaluation ----------------------------------------------------------------------------

struct RpeOptions {
  std::vector<double> windows_m = {10.0, 50.0, 100.0};  // truth path length of each pair
  // A window may end at most this much past its nominal length (else the pair spans a data gap).
  double max_window_overshoot_fraction = 0.1;
};

struct TrajectoryEvaluationOptions {
  AssociationOptions association;
  RpeOptions rpe;
  LineSegmentationOptions lines;
};

struct AteResult {
  ErrorStatistics position_m;              // |p_est - p_truth|, raw
  ErrorStatistics horizontal_m;            // north/east part only, raw
  ErrorStatistics vertical_m;              // |down error|, raw
  ErrorStatistics rotation_deg;            // angle of R_truth^T R_est, raw
  ErrorStatistics aligned_position_m;      // after the SE(3) alignment
  ErrorStatistics aligned_horizontal_m;
  sss::core::Pose T_truth_estimate;        // the alignment: p_truth ~ T * p_est
  double alignment_rotation_deg = 0.0;     // angle of its rotation
  double alignment_heading_deg = 0.0;      // its heading (yaw) part, signed

  // Gauge-free: the horizontal error left after the best horizontal rotation and scale of the
  // estimate about its own first position. A constant heading bias turns a dead-reckoned path
  // about its start and a DVL scale factor stretches it; no relative measurement (loop closure,
  // landmark seen twice) can see either, so this is the part of the error side-scan can correct.
  // No translation is removed: DR starts where the vehicle is known to be.
  // Closed form over the pairs, with complex numbers n + i e (north, east):
  //   a_i = p_est_i - p_est_0, b_i = p_truth_i - p_est_0, z = sum(conj(a_i) b_i) / sum |a_i|^2,
  //   error_i = |b_i - z a_i| (z = 1 when every a_i is zero).
  // The fit is least squares, so raw^2 = gauge^2 + gauge_free^2 in RMSE (horizontal).
  ErrorStatistics gauge_free_horizontal_m;
  ErrorStatistics gauge_horizontal_m;   // |z a_i - a_i|: the raw error the rotation and scale explain
  double gauge_free_scale = 1.0;        // |z|: truth length / estimate length (a DVL reading 1 % long: ~0.99)
  // arg z in degrees: the heading turn that takes the estimate onto the truth, clockwise from north
  // positive like a heading (an estimate whose heading reads b too high gives ~ -b).
  double gauge_free_rotation_deg = 0.0;
};

// RPE over one window length (paper-independent, after Sturm et al. 2012 / KITTI): pairs (i, j)
// with truth path length from i to j >= window; E = (T_i^-1 T_j)^-1 (E_i^-1 E_j).
struct RpeResult {
  double window_m = 0.0;
  ErrorStatistics translation_percent;  // |t_E| / truth path length of the pair * 100
  ErrorStatistics translation_m;        // |t_E|
  ErrorStatistics rotation_deg;         // angle of R_E
};

// One sample per associated pose, for plots.
struct ErrorSample {
  int64_t utime_us = 0;
  double time_s = 0.0;        // since the first associated pose
  double distance_m = 0.0;    // truth path length since the first associated pose
  double position_m = 0.0;
  double horizontal_m = 0.0;
  double aligned_horizontal_m = 0.0;
  double gauge_free_horizontal_m = 0.0;  // after the gauge-free rotation and scale (AteResult)
  double along_track_m = 0.0;   // horizontal error along the truth's heading (+ ahead)
  double across_track_m = 0.0;  // and across it (+ starboard)
  int line = -1;                // survey line index, -1 outside lines
};

struct LineError {
  int line = 0;
  ErrorStatistics horizontal_m;
  ErrorStatistics position_m;
  ErrorStatistics aligned_horizontal_m;
};

struct TrajectoryEvaluation {
  bool ok = false;
  std::string error;  // why not ok (e.g. no estimate pose within the truth's time span)
  size_t estimate_poses = 0;
  Association association;  // pairs kept for inspection
  AteResult ate;
  std::vector<RpeResult> rpe;  // one per window, in the options' order
  std::vector<ErrorSample> series;
  std::vector<LineError> lines;  // one per truth line with at least one associated pose
};

TrajectoryEvaluation evaluateTrajectory(const Trajectory& truth, const Trajectory& estimate,
                                        const std::vector<SurveyLine>& truth_lines,
                                        const TrajectoryEvaluationOptions& options = {});

// Truth path length (3D) from the first pose to each pose.
std::vector<double> cumulativeDistanceM(const Trajectory& trajectory);

// Course (heading of motion) of a horizontal direction, [0, 360) degrees clockwise from north.
double courseDeg(const Eigen::Vector2d& north_east);

}  // namespace sss::eval
