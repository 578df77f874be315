// Loop-closure accuracy against ground truth: each closure's relative pose (B's subframe centre in
// A's body frame, and B's heading relative to A) against the truth's, and the same for DR's.
#pragma once

#include "tools/eval/trajectory_io.hpp"
#include "tools/eval/trajectory_metrics.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace sss::eval {

// One row of loop_closures.csv (tools/process/offline_runner.cpp writeClosuresCsv).
struct ClosureRecord {
  int line = 0;  // in the file, for messages
  int64_t subframe_id_a = 0;
  int64_t subframe_id_b = 0;
  int round = -1;            // association round, -1 without the column
  std::string status;        // accepted | rejected | superseded | pending; "unknown" without the column
  std::string rejection;     // none | chi_square_gate | ...; "" without the column
  int64_t utime_a_us = 0;    // the two subframe centre times
  int64_t utime_b_us = 0;
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();  // dx, dy, dz: B's centre in A's body frame
  double heading_rad = 0.0;                                 // dheading: heading of T_a_b's rotation
  // The closure's own horizontal covariance (cov_xx_m2, cov_xy_m2, cov_yy_m2: B's centre in A's
  // frame), when the file has the columns.
  bool has_covariance = false;
  Eigen::Matrix2d horizontal_covariance_m2 = Eigen::Matrix2d::Zero();
  // Its 1-sigma along track (x) and across (y); NaN without the covariance.
  double sigmaM(int axis) const {
    return has_covariance ? std::sqrt(std::max(0.0, horizontal_covariance_m2(axis, axis)))
                          : std::numeric_limits<double>::quiet_NaN();
  }
};

// Header line first (columns found by name in any order, extra columns ignored; needed:
// subframe_id_a, subframe_id_b, utime_a_us, utime_b_us, dx_m, dy_m, dz_m, dheading_rad; optional:
// round, status, rejection, cov_xx_m2 + cov_xy_m2 + cov_yy_m2), then one closure per line; '#' and
// blank lines are skipped. Fails with "FILE:LINE: ..." on the first problem.
sss::core::Status readClosureCsv(const std::string& path, std::vector<ClosureRecord>& closures);

// The relative pose of B in A as a closure states it: translation in A's body frame (FRD) and the
// heading (yaw) of R_a^T R_b.
struct RelativePoseXyzHeading {
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();
  double heading_rad = 0.0;
};
RelativePoseXyzHeading relativePose(const sss::core::Pose& T_world_a, const sss::core::Pose& T_world_b);

// Estimate - truth, in A's body frame: x along track, y lateral (+ starboard), z depth (+ down);
// heading wrapped to (-pi, pi].
struct RelativePoseError {
  double along_m = 0.0;
  double lateral_m = 0.0;
  double depth_m = 0.0;
  double heading_rad = 0.0;
};
RelativePoseError relativePoseError(const RelativePoseXyzHeading& estimate, const RelativePoseXyzHeading& truth);

struct ClosureError {
  ClosureRecord closure;
  bool has_truth = false;  // the truth covers both centre times
  RelativePoseXyzHeading truth;
  RelativePoseError closure_error;  // the closure's relative pose - the truth's
  bool has_dr = false;              // a DR trajectory was given and covers both times
  RelativePoseError dr_error;       // DR's relative pose - the truth's
  // Normalised estimation error squared of the horizontal error under the closure's covariance
  // (2 dof: about 2 on average when the covariance is consistent); NaN without one.
  double horizontal_nees = std::numeric_limits<double>::quiet_NaN();
};

// Statistics of one signed error component: of its absolute value, plus the mean signed value.
struct SignedErrorStatistics {
  ErrorStatistics abs;
  double bias = std::numeric_limits<double>::quiet_NaN();
};

struct RelativePoseErrorStatistics {
  SignedErrorStatistics along_m;
  SignedErrorStatistics lateral_m;
  SignedErrorStatistics depth_m;
  SignedErrorStatistics heading_deg;
  ErrorStatistics horizontal_m;  // |(along, lateral)|
};
RelativePoseErrorStatistics relativePoseErrorStatistics(const std::vector<RelativePoseError>& errors);

// The closures of one status (accepted, rejected, ...) that the truth covers.
struct ClosureGroup {
  std::string status;
  size_t count = 0;
  RelativePoseErrorStatistics closure;
  RelativePoseErrorStatistics dr;  // over the closures DR covers (count 0 without DR)
  size_t nees_count = 0;           // closures with a covariance
  double mean_horizontal_nees = std::numeric_limits<double>::quiet_NaN();
};

struct ClosureEvaluation {
  std::vector<ClosureError> closures;  // in file order
  size_t without_truth = 0;            // centre times outside the truth (or in a gap): no error
  size_t without_dr = 0;               // with truth, but DR given and not covering both times
  std::vector<ClosureGroup> groups;    // accepted, rejected, superseded, pending, others: those present
};

// Truth (and DR, when dr is not null) are interpolated at the centre times (poseAtTime with
// max_gap_s).
ClosureEvaluation evaluateClosures(const std::vector<ClosureRecord>& closures, const Trajectory& truth,
                                   const Trajectory* dr, double max_gap_s);

}  // namespace sss::eval
