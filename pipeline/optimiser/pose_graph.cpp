// Sliding-window pose graph, see pose_graph.hpp. Checkpoint I/O is in pose_graph_checkpoint.cpp.
//
// Models (why, in short):
// - Odometry: the DR relative pose of consecutive subframe centres, covariance from the distance
//   travelled (PoseGraphOptions); paper eq. (6), first term.
// - INS absolute factors: depth, roll, pitch and heading of each node against its DR pose. They
//   are measured against absolute references and do not drift; without them a long chain of
//   adjacent-line closures (each with a little heading noise) steers the heading and so the position
//   further than the DR drifted (measured: 23 m after 60 lines with a perfect DR).
// - Closures: relative pose with the matcher's covariance under a Cauchy loss (paper eq. (6),
//   second term), admitted by a chi-square gate against the current estimate and a pairwise
//   consistency test (PCM, Mangelson et al. 2018) on DR cycles with a greedy maximum clique.
// - Window: nodes older than the newest window_size are marginalised with the Schur complement of
//   the Gauss-Newton system on the [dt, dr] tangent, linearised at the current estimate (robust
//   closures enter with their IRLS weight); the result is a dense prior r = r0 + J boxMinus(x, x_lin)
//   on the nodes they were connected to.
// - Closures to marginalised nodes: the old node is a constant at its estimate and the closure
//   covariance grows by that node's covariance given the window when it was marginalised
//   (H_mm^-1). The conditional, not the marginal covariance: what ties the old node to the
//   window's absolute pose (the DR chain, earlier closures) is already inside the prior, so adding
//   the old node's absolute (mission-long) drift would count it twice and leave an old-node
//   closure almost powerless. The price is that the old node does not follow later corrections
//   of the window; full smoothing re-solves everything.
#include "pipeline/optimiser/pose_graph.hpp"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "pipeline/optimiser/pose_manifold.hpp"
#include "pipeline/optimiser/variance_components.hpp"

namespace sss::optimiser {

using sss::core::Matrix6d;
using sss::core::Pose;
using sss::core::Vector6d;
using Clock = std::chrono::steady_clock;

namespace {

// Zero-mean priors on the calibration block: x ./ sigma.
struct CalibrationPriorError {
  Eigen::Vector4d inverse_sigma;
  template <typename T>
  bool operator()(const T* x, T* residual) const {
    for (int i = 0; i < 4; ++i) residual[i] = x[i] * T(inverse_sigma(i));
    return true;
  }
};

// A Gaussian prior on a scalar parameter: (x - mean) / sigma.
struct ScalarPriorError {
  double mean, inverse_sigma;
  template <typename T>
  bool operator()(const T* x, T* residual) const {
    residual[0] = (x[0] - T(mean)) * T(inverse_sigma);
    return true;
  }
};

// The heading moments D_c = integral of (cos psi - cos psi_a) dp and D_s (sin) of the DR path between
// two nodes (CalibratedOdometryError). Only the end poses and the distance flown are known, so the
// path is taken as straight - arc - straight (a turn between lines): three unknowns (the two straight
// lengths and the radius) from the displacement and the distance, a linear system. Where that has no
// solution the moments are the trapezoid of the ends. Along a straight line both are zero.
void pathMoments(const Pose& a, const Pose& b, double distance_m, Eigen::Vector2d& moment_cos,
                 Eigen::Vector2d& moment_sin) {
  moment_cos.setZero();
  moment_sin.setZero();
  const double heading_a = sss::core::eulerFromQuaternion(a.rotation).heading_rad;
  const double heading_b = sss::core::eulerFromQuaternion(b.rotation).heading_rad;
  const Eigen::Vector2d displacement = (b.translation - a.translation).head<2>();
  const double turn = sss::core::wrapAngle(heading_b - heading_a);
  if (std::abs(turn) < 0.01) return;  // straight: (cos psi - cos psi_a) ~ 0 all along
  const auto unit = [](double psi) { return Eigen::Vector2d(std::cos(psi), std::sin(psi)); };
  constexpr int kSteps = 64;
  // Either turning direction for a near U-turn (wrapAngle cannot tell), the shorter one first.
  for (const double sign : {turn > 0.0 ? 1.0 : -1.0, turn > 0.0 ? -1.0 : 1.0}) {
    const double angle = sign * turn > 0.0 ? std::abs(turn) : 2.0 * M_PI - std::abs(turn);
    if (angle > M_PI + 0.3) continue;  // not a plausible single turn
    // Chord of a unit-radius arc, and the arc's moments per unit radius (midpoint rule).
    Eigen::Vector2d chord = Eigen::Vector2d::Zero(), arc_cos = Eigen::Vector2d::Zero(), arc_sin = Eigen::Vector2d::Zero();
    for (int k = 0; k < kSteps; ++k) {
      const double psi = heading_a + sign * angle * (k + 0.5) / kSteps;
      const Eigen::Vector2d step = unit(psi) * angle / kSteps;
      chord += step;
      arc_cos += (std::cos(psi) - std::cos(heading_a)) * step;
      arc_sin += (std::sin(psi) - std::sin(heading_a)) * step;
    }
    Eigen::Matrix3d system;
    system << unit(heading_a), unit(heading_b), chord, 1.0, 1.0, angle;
    const Eigen::Vector3d lengths = system.colPivHouseholderQr().solve(Eigen::Vector3d(displacement.x(), displacement.y(), distance_m));
    if (!lengths.allFinite() || lengths.minCoeff() < -0.05 * std::max(distance_m, 1.0)) continue;
    const double radius = std::max(lengths(2), 0.0), after = std::max(lengths(1), 0.0);
    moment_cos = radius * arc_cos + after * (std::cos(heading_b) - std::cos(heading_a)) * unit(heading_b);
    moment_sin = radius * arc_sin + after * (std::sin(heading_b) - std::sin(heading_a)) * unit(heading_b);
    return;
  }
  moment_cos = 0.5 * (std::cos(heading_b) - std::cos(heading_a)) * displacement;
  moment_sin = 0.5 * (std::sin(heading_b) - std::sin(heading_a)) * displacement;
}

// The marginal 1-sigma of each element of a parameter block of the solved problem (its covariance's
// diagonal); NaN where the covariance cannot be computed.
template <int N>
Eigen::Matrix<double, N, 1> marginalSigmas(ceres::Problem& problem, const double* block) {
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::SPARSE_QR;
  ceres::Covariance covariance(options);
  Eigen::Matrix<double, N, N, N == 1 ? Eigen::ColMajor : Eigen::RowMajor> c;
  c.setConstant(std::numeric_limits<double>::quiet_NaN());
  const std::vector<std::pair<const double*, const double*>> blocks = {{block, block}};
  if (covariance.Compute(blocks, &problem)) covariance.GetCovarianceBlock(block, block, c.data());
  Eigen::Matrix<double, N, 1> sigmas;
  for (int i = 0; i < N; ++i) sigmas(i) = c(i, i) >= 0.0 ? std::sqrt(c(i, i)) : std::numeric_limits<double>::quiet_NaN();
  return sigmas;
}

// Whitening of the first node's anchor.
Matrix6d firstNodeSqrtInformation(const PoseGraphOptions& o) {
  Vector6d inverse_sigma;
  const double m = 1.0 / o.first_node_sigma_m, r = 1.0 / o.first_node_sigma_rad;
  inverse_sigma << m, m, m, r, r, r;
  return inverse_sigma.asDiagonal();
}

// 1 / sigma of the INS absolute factor's depth, roll, pitch and heading (0: not used).
Eigen::Vector4d insAbsoluteWeights(const PoseGraphOptions& o) {
  auto weight = [](double sigma) { return sigma > 0.0 ? 1.0 / sigma : 0.0; };
  return Eigen::Vector4d(weight(o.absolute_depth_sigma_m), weight(o.absolute_roll_pitch_sigma_rad),
                         weight(o.absolute_roll_pitch_sigma_rad), weight(o.absolute_heading_sigma_rad));
}

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

bool finitePose(const Pose& pose) {
  return pose.translation.allFinite() && pose.rotation.coeffs().allFinite() &&
         std::abs(pose.rotation.norm() - 1.0) < 1e-3;
}

Pose normalisedPose(const Pose& pose) {
  Pose out = pose;
  out.rotation.normalize();
  return out;
}

}  // namespace

const char* closureRejectionName(ClosureRejection rejection) {
  switch (rejection) {
    case ClosureRejection::kNone: return "none";
    case ClosureRejection::kChiSquareGate: return "chi2_gate";
    case ClosureRejection::kInconsistent: return "inconsistent";
    case ClosureRejection::kNoSupport: return "no_support";
  }
  return "unknown";
}

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
  if (o.calibration != "auto" && o.calibration != "always" && o.calibration != "never")
    problems.push_back("calibration must be one of auto, always, never (got '" + o.calibration + "')");
  positive(o.calibration_scale_sigma, "calibration_scale_sigma");
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
  section.optional("absolute_depth_sigma_m", options.absolute_depth_sigma_m, {atLeast(0.0)});
  section.optional("absolute_roll_pitch_sigma_rad", options.absolute_roll_pitch_sigma_rad, {atLeast(0.0)});
  section.optional("absolute_heading_sigma_rad", options.absolute_heading_sigma_rad, {atLeast(0.0)});
  section.optional("first_node_sigma_m", options.first_node_sigma_m, {greaterThan(0.0)});
  section.optional("first_node_sigma_rad", options.first_node_sigma_rad, {greaterThan(0.0)});
  section.optional("robust_loss", options.robust_loss, {sss::core::oneOf({"cauchy", "huber", "none"})});
  section.optional("robust_loss_scale", options.robust_loss_scale, {greaterThan(0.0)});
  section.optional("min_closure_inliers", options.min_closure_inliers, {atLeast(0)});
  section.optional("gate_chi2", options.gate_chi2, {greaterThan(0.0)});
  section.optional("gate_min_accepted_closures", options.gate_min_accepted_closures, {atLeast(0)});
  section.optional("pcm_chi2", options.pcm_chi2, {greaterThan(0.0)});
  section.optional("pcm_max_closures", options.pcm_max_closures, {inRange(1, 10000)});
  section.optional("min_consistent_closures", options.min_consistent_closures, {atLeast(1)});
  section.optional("max_iterations", options.max_iterations, {inRange(1, 1000)});
  section.optional("max_solver_time_s", options.max_solver_time_s, {atLeast(0.0)});
  section.optional("full_smoothing_max_iterations", options.full_smoothing_max_iterations, {inRange(1, 10000)});
  section.optional("closure_reweighting", options.closure_reweighting,
                   {sss::core::oneOf({"none", "dr_bound", "variance_components"})});
  section.optional("variance_component_iterations", options.variance_component_iterations, {inRange(1, 100)});
  section.optional("separation_bias_sigma_m", options.separation_bias_sigma_m, {inRange(0.0, 100.0)});
  section.optional("separation_bias_min_lateral_m", options.separation_bias_min_lateral_m, {inRange(0.0, 10000.0)});
  section.optional("separation_bias_apply", options.separation_bias_apply);
  section.optional("separation_bias_significance", options.separation_bias_significance, {inRange(0.0, 100.0)});
  section.optional("fix_gate_chi2", options.fix_gate_chi2, {greaterThan(0.0)});
  section.optional("calibration", options.calibration, {sss::core::oneOf({"auto", "always", "never"})});
  section.optional("calibration_scale_sigma", options.calibration_scale_sigma, {inRange(1e-6, 0.5)});
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

// ---- construction and input -------------------------------------------------------------------

SlidingWindowPoseGraph::SlidingWindowPoseGraph(const PoseGraphOptions& options) : options_(options) {
  const std::vector<std::string> problems = validatePoseGraphOptions(options);
  if (!problems.empty()) {
    std::string text = "invalid PoseGraphOptions:";
    for (const std::string& p : problems) text += " " + p + ";";
    throw std::invalid_argument(text);
  }
}

Matrix6d SlidingWindowPoseGraph::odometryCovariance(const PoseGraphOptions& o, double distance_m) {
  return odometryCovariance(o, distance_m, o.odometry_drift_fraction);
}

Matrix6d SlidingWindowPoseGraph::odometryCovariance(const PoseGraphOptions& o, double distance_m, double drift_fraction) {
  const double d = std::max(distance_m, 0.0);
  const double horizontal = o.odometry_random_walk_m_per_sqrt_m * o.odometry_random_walk_m_per_sqrt_m * d +
                            (drift_fraction * d) * (drift_fraction * d) +
                            o.odometry_min_sigma_m * o.odometry_min_sigma_m;
  const double heading = o.odometry_heading_random_walk_rad_per_sqrt_m *
                             o.odometry_heading_random_walk_rad_per_sqrt_m * d +
                         o.odometry_min_heading_sigma_rad * o.odometry_min_heading_sigma_rad;
  const double attitude = o.odometry_attitude_sigma_rad * o.odometry_attitude_sigma_rad;
  Vector6d diagonal;
  diagonal << horizontal, horizontal, o.odometry_depth_sigma_m * o.odometry_depth_sigma_m, attitude, attitude, heading;
  return diagonal.asDiagonal();
}

void SlidingWindowPoseGraph::setupDerived(Node& node, const Node* previous) const {
  if (!previous) {
    node.odometry = Pose::identity();
    node.odometry_sqrt_information = Matrix6d::Identity();
    node.chain_prefix = Matrix6d::Zero();
    return;
  }
  node.odometry = sss::core::between(previous->dr, node.dr);
  pathMoments(previous->dr, node.dr, node.distance_m - previous->distance_m, node.moment_cos, node.moment_sin);
  const Matrix6d sigma = odometryCovariance(options_, node.distance_m - previous->distance_m);
  sqrtInformation(sigma, node.odometry_sqrt_information);  // diagonal and positive: cannot fail
  const Matrix6d ad = adjoint(node.dr);
  node.chain_prefix = previous->chain_prefix + ad * sigma * ad.transpose();
}

Status SlidingWindowPoseGraph::addNode(int64_t subframe_id, int64_t utime_us, const Pose& T_world_body_dr,
                                       double distance_travelled_m) {
  auto refuse = [&](const std::string& why) {
    ++counters_.nodes_refused;
    return Status::error("node " + std::to_string(subframe_id) + ": " + why);
  };
  if (!finitePose(T_world_body_dr)) return refuse("DR pose is not finite or its quaternion is not unit; node dropped");
  if (!std::isfinite(distance_travelled_m)) return refuse("distance travelled is not finite; node dropped");
  if (index_of_.count(subframe_id)) return refuse("duplicate subframe id; node dropped");
  if (!nodes_.empty()) {
    const Node& last = nodes_.back();
    if (utime_us <= last.utime_us)
      return refuse("utime " + std::to_string(utime_us) + " us is not after the previous node's " +
                    std::to_string(last.utime_us) + " us; nodes must arrive in time order");
    if (distance_travelled_m < last.distance_m - 1e-6)
      return refuse("distance travelled decreased from " + std::to_string(last.distance_m) + " m to " +
                    std::to_string(distance_travelled_m) + " m");
  }
  Node node;
  node.id = subframe_id;
  node.utime_us = utime_us;
  node.dr = normalisedPose(T_world_body_dr);
  node.distance_m = distance_travelled_m;
  const Node* previous = nodes_.empty() ? nullptr : &nodes_.back();
  setupDerived(node, previous);
  if (previous) {
    // Initial estimate: the previous estimate moved by the DR odometry; its covariance likewise.
    node.estimate = normalisedPose(previous->estimate * node.odometry);
    if (previous->has_covariance) {
      const Matrix6d ad = adjoint(node.odometry.inverse());
      node.covariance = ad * previous->covariance * ad.transpose() +
                        odometryCovariance(options_, node.distance_m - previous->distance_m);
      node.has_covariance = true;
    }
  } else {
    node.estimate = node.dr;
    Vector6d diagonal;
    const double sm = options_.first_node_sigma_m * options_.first_node_sigma_m;
    const double sr = options_.first_node_sigma_rad * options_.first_node_sigma_rad;
    diagonal << sm, sm, sm, sr, sr, sr;
    node.covariance = diagonal.asDiagonal();
    node.has_covariance = true;
  }
  index_of_[subframe_id] = static_cast<int>(nodes_.size());
  nodes_.push_back(std::move(node));
  ++counters_.nodes_added;
  return Status::success();
}

Status SlidingWindowPoseGraph::addLoopClosure(const LoopClosure& closure) {
  ++counters_.closures_received;
  const std::string name =
      "closure " + std::to_string(closure.subframe_id_a) + " -> " + std::to_string(closure.subframe_id_b) + ": ";
  auto refuse = [&](const std::string& why) {
    ++counters_.closures_refused;
    return Status::error(name + why);
  };
  const auto a = index_of_.find(closure.subframe_id_a);
  const auto b = index_of_.find(closure.subframe_id_b);
  if (a == index_of_.end())
    return refuse("subframe id " + std::to_string(closure.subframe_id_a) + " is unknown (no such node added)");
  if (b == index_of_.end())
    return refuse("subframe id " + std::to_string(closure.subframe_id_b) + " is unknown (no such node added)");
  if (a->second == b->second) return refuse("both ends are the same node");
  if (!finitePose(closure.T_a_b)) return refuse("T_a_b is not finite or its quaternion is not unit");
  Matrix6d sqrt_information;
  if (!sqrtInformation(closure.covariance, sqrt_information))
    return refuse("covariance is not finite, symmetric and positive definite");
  if (closure.num_inliers < options_.min_closure_inliers)
    return refuse(std::to_string(closure.num_inliers) + " inliers, fewer than min_closure_inliers (" +
                  std::to_string(options_.min_closure_inliers) + ")");

  const std::pair<int64_t, int64_t> key = std::minmax(closure.subframe_id_a, closure.subframe_id_b);
  const auto existing = latest_for_pair_.find(key);
  if (existing != latest_for_pair_.end()) {
    Closure& old = closures_[existing->second];
    if (closure.association_round < old.record.closure.association_round)
      return refuse("association round " + std::to_string(closure.association_round) + " is older than round " +
                    std::to_string(old.record.closure.association_round) + " already held for this pair");
    if (old.record.marginalised && old.record.status == ClosureStatus::kAccepted)
      return refuse("the pair's earlier closure is already marginalised; a second one would count the pair twice");
    setStatus(old, ClosureStatus::kSuperseded, ClosureRejection::kNone);
  }

  Closure c;
  c.record.closure = closure;
  c.record.closure.T_a_b = normalisedPose(closure.T_a_b);
  c.record.closure.covariance = 0.5 * (closure.covariance + closure.covariance.transpose());
  c.a = a->second;
  c.b = b->second;
  c.sqrt_information = sqrt_information;
  const int index = static_cast<int>(closures_.size());
  closures_.push_back(c);
  ++counters_.closures_pending;
  latest_for_pair_[key] = index;
  nodes_[c.a].closures.push_back(index);
  nodes_[c.b].closures.push_back(index);
  return Status::success();
}

Status SlidingWindowPoseGraph::addFix(const AbsoluteFix& fix) {
  ++fix_counters_.received;
  auto refuse = [&](const std::string& why) {
    ++fix_counters_.refused;
    return Status::error("fix at " + std::to_string(fix.utime_us) + " us: " + why);
  };
  if (!fix.position_ne_m.allFinite() || !fix.dr_position_m.allFinite() || !std::isfinite(fix.dr_distance_m))
    return refuse("position, DR position or distance is not finite; fix dropped");
  const Eigen::Matrix2d covariance = 0.5 * (fix.covariance_m2 + fix.covariance_m2.transpose());
  const Eigen::LLT<Eigen::Matrix2d> llt(covariance);
  if (!covariance.allFinite() || llt.info() != Eigen::Success || !(covariance.determinant() > 0.0))
    return refuse("covariance is not finite and positive definite; fix dropped");
  Fix f;
  f.record.fix = fix;
  f.record.fix.covariance_m2 = covariance;
  fixes_.push_back(std::move(f));
  return Status::success();
}

bool SlidingWindowPoseGraph::tieFix(Fix& f, int n) const {
  const Node& node = nodes_[n];
  f.node = n;
  f.record.subframe_id = node.id;
  f.p_body = node.dr.inverse() * f.record.fix.dr_position_m;
  // The DR between the node and the fix drifts like any odometry edge of that length.
  const double dr_variance =
      odometryCovariance(options_, std::abs(f.record.fix.dr_distance_m - node.distance_m))(0, 0);
  const Eigen::Matrix2d covariance = f.record.fix.covariance_m2 + dr_variance * Eigen::Matrix2d::Identity();
  const Eigen::LLT<Eigen::Matrix2d> llt(covariance);
  if (llt.info() != Eigen::Success) return false;
  f.sqrt_information = llt.matrixL().solve(Eigen::Matrix2d::Identity());
  return f.sqrt_information.allFinite();
}

void SlidingWindowPoseGraph::decideFixes(bool final) {
  if (nodes_.empty()) return;
  for (int index = 0; index < static_cast<int>(fixes_.size()); ++index) {
    Fix& f = fixes_[index];
    if (f.node < 0) {
      // The node nearest in time, once the fix lies between two nodes (or at the end of the mission).
      const int64_t t = f.record.fix.utime_us;
      const auto after = std::lower_bound(nodes_.begin(), nodes_.end(), t,
                                          [](const Node& n, int64_t time) { return n.utime_us < time; });
      if (after == nodes_.end() && !final) continue;
      int n = static_cast<int>(after - nodes_.begin());
      if (after == nodes_.end() || (n > 0 && t - nodes_[n - 1].utime_us < after->utime_us - t)) --n;
      n = std::clamp(n, 0, static_cast<int>(nodes_.size()) - 1);
      if (!tieFix(f, n)) {
        f.record.status = FixStatus::kRejected;  // cannot happen for a validated covariance
        continue;
      }
      nodes_[n].fixes.push_back(index);
    }
    if (f.record.status != FixStatus::kPending) continue;
    // Gate: innovation against the node's estimate carried to the fix, with the node's covariance.
    const Node& node = nodes_[f.node];
    const Eigen::Matrix3d rotation = node.estimate.rotation.toRotationMatrix();
    const Eigen::Vector2d predicted = (node.estimate * f.p_body).head<2>();
    const Eigen::Vector2d innovation = f.record.fix.position_ne_m - predicted;
    Eigen::Matrix<double, 2, 6> jacobian;  // d predicted / d [dt, dr] (right perturbation)
    Eigen::Matrix3d skew;
    skew << 0, -f.p_body.z(), f.p_body.y(), f.p_body.z(), 0, -f.p_body.x(), -f.p_body.y(), f.p_body.x(), 0;
    jacobian.leftCols<3>() = rotation.topRows<2>();
    jacobian.rightCols<3>() = -(rotation * skew).topRows<2>();
    const Eigen::Matrix2d fix_covariance = (f.sqrt_information.transpose() * f.sqrt_information).inverse();
    const Matrix6d node_covariance = node.has_covariance ? node.covariance : Matrix6d::Zero();
    const Eigen::Matrix2d s = jacobian * node_covariance * jacobian.transpose() + fix_covariance;
    f.record.innovation_chi2 = innovation.dot(s.ldlt().solve(innovation));
    const bool accepted = std::isfinite(f.record.innovation_chi2) && f.record.innovation_chi2 <= options_.fix_gate_chi2;
    f.record.status = accepted ? FixStatus::kAccepted : FixStatus::kRejected;
    ++(accepted ? fix_counters_.accepted : fix_counters_.rejected_gate);
    if (accepted) newest_accepted_fix_utime_us_ = std::max(newest_accepted_fix_utime_us_, f.record.fix.utime_us);
  }
}

void SlidingWindowPoseGraph::setStatus(Closure& c, ClosureStatus status, ClosureRejection rejection) {
  auto counter = [&](ClosureStatus s, ClosureRejection r) -> uint64_t* {
    switch (s) {
      case ClosureStatus::kPending: return &counters_.closures_pending;
      case ClosureStatus::kAccepted: return &counters_.closures_accepted;
      case ClosureStatus::kSuperseded: return &counters_.closures_superseded;
      case ClosureStatus::kRejected:
        if (r == ClosureRejection::kChiSquareGate) return &counters_.closures_rejected_gate;
        if (r == ClosureRejection::kNoSupport) return &counters_.closures_rejected_no_support;
        return &counters_.closures_rejected_inconsistent;
    }
    return nullptr;
  };
  if (c.record.status == status && c.record.rejection == rejection) return;
  if (c.record.marginalised && c.record.status == ClosureStatus::kAccepted && status != ClosureStatus::kAccepted)
    ++counters_.closures_withdrawn_after_marginalisation;
  uint64_t* from = counter(c.record.status, c.record.rejection);
  if (from && *from > 0) --*from;
  c.record.status = status;
  c.record.rejection = status == ClosureStatus::kRejected ? rejection : ClosureRejection::kNone;
  if (uint64_t* to = counter(status, c.record.rejection)) ++*to;
}

int64_t SlidingWindowPoseGraph::closureUtime(const Closure& c) const {
  return std::max(nodes_[c.a].utime_us, nodes_[c.b].utime_us);
}

// ---- factors ----------------------------------------------------------------------------------

bool SlidingWindowPoseGraph::useInsAbsolute() const {
  return options_.absolute_depth_sigma_m > 0.0 || options_.absolute_roll_pitch_sigma_rad > 0.0 ||
         options_.absolute_heading_sigma_rad > 0.0;
}

std::vector<SlidingWindowPoseGraph::Factor> SlidingWindowPoseGraph::windowFactors() const {
  std::vector<Factor> factors;
  const int n = static_cast<int>(nodes_.size());
  if (n == 0) return factors;
  if (first_active_ == 0) factors.push_back({FactorKind::kFirstNode, 0});
  if (!prior_.empty()) factors.push_back({FactorKind::kPrior, 0});
  if (useInsAbsolute())
    for (int k = first_active_; k < n; ++k) factors.push_back({FactorKind::kInsAbsolute, k});
  for (int k = first_active_ + 1; k < n; ++k) factors.push_back({FactorKind::kOdometry, k});
  // Closures through the active nodes' lists (bounded work), each once at its first active end.
  for (int k = first_active_; k < n; ++k) {
    for (int index : nodes_[k].closures) {
      const Closure& c = closures_[index];
      if (c.record.status != ClosureStatus::kAccepted || c.record.marginalised) continue;
      const int first_active_end = isActive(c.a) && isActive(c.b) ? std::min(c.a, c.b) : (isActive(c.a) ? c.a : c.b);
      if (first_active_end == k) factors.push_back({FactorKind::kClosure, index});
    }
    for (int index : nodes_[k].fixes)
      if (fixes_[index].record.status == FixStatus::kAccepted) factors.push_back({FactorKind::kFix, index});
  }
  return factors;
}

std::vector<SlidingWindowPoseGraph::Factor> SlidingWindowPoseGraph::allFactors() const {
  std::vector<Factor> factors;
  const int n = static_cast<int>(nodes_.size());
  if (n == 0) return factors;
  factors.push_back({FactorKind::kFirstNode, 0});
  if (useInsAbsolute())
    for (int k = 0; k < n; ++k) factors.push_back({FactorKind::kInsAbsolute, k});
  for (int k = 1; k < n; ++k) factors.push_back({FactorKind::kOdometry, k});
  for (int index = 0; index < static_cast<int>(closures_.size()); ++index)
    if (closures_[index].record.status == ClosureStatus::kAccepted) factors.push_back({FactorKind::kClosure, index});
  for (int index = 0; index < static_cast<int>(fixes_.size()); ++index)
    if (fixes_[index].record.status == FixStatus::kAccepted) factors.push_back({FactorKind::kFix, index});
  return factors;
}

std::vector<SlidingWindowPoseGraph::Factor> SlidingWindowPoseGraph::factorsTouching(int m) const {
  std::vector<Factor> factors;
  if (m == 0) factors.push_back({FactorKind::kFirstNode, 0});
  if (!prior_.empty()) factors.push_back({FactorKind::kPrior, 0});
  if (useInsAbsolute()) factors.push_back({FactorKind::kInsAbsolute, m});
  if (m + 1 < static_cast<int>(nodes_.size())) factors.push_back({FactorKind::kOdometry, m + 1});
  for (int index : nodes_[m].closures) {
    const Closure& c = closures_[index];
    if (c.record.status == ClosureStatus::kAccepted && !c.record.marginalised)
      factors.push_back({FactorKind::kClosure, index});
  }
  for (int index : nodes_[m].fixes)
    if (fixes_[index].record.status == FixStatus::kAccepted) factors.push_back({FactorKind::kFix, index});
  return factors;
}

std::vector<int> SlidingWindowPoseGraph::factorNodes(const Factor& f) const {
  switch (f.kind) {
    case FactorKind::kFirstNode: return {0};
    case FactorKind::kInsAbsolute: return {f.index};
    case FactorKind::kOdometry: return {f.index - 1, f.index};
    case FactorKind::kClosure: return {closures_[f.index].a, closures_[f.index].b};
    case FactorKind::kPrior: return prior_.nodes;
    case FactorKind::kFix: return {fixes_[f.index].node};
  }
  return {};
}

Matrix6d SlidingWindowPoseGraph::closureCovarianceInWindow(const Closure& c) const {
  Matrix6d sigma = variance_factors_.closure * c.record.closure.covariance;
  // e = boxMinus(T_a^-1 T_b, Z): a right perturbation d of T_a enters as -Ad(Z^-1) d, one of T_b
  // as d itself (to first order).
  if (!isActive(c.a)) {
    const Matrix6d ad = adjoint(c.record.closure.T_a_b.inverse());
    sigma += ad * nodes_[c.a].conditional_covariance * ad.transpose();
  }
  if (!isActive(c.b)) sigma += nodes_[c.b].conditional_covariance;
  return sigma;
}

Matrix6d SlidingWindowPoseGraph::closureSqrtInformation(const Closure& c) const {
  return c.sqrt_information / std::sqrt(variance_factors_.closure);
}

ceres::CostFunction* SlidingWindowPoseGraph::makeCost(const Factor& f) const {
  switch (f.kind) {
    case FactorKind::kFirstNode:
      return PosePriorError::create(firstNodePrior(), firstNodeSqrtInformation(options_));
    case FactorKind::kInsAbsolute: {
      const Eigen::Vector4d w = insAbsoluteWeights(options_);
      if (calibration_.estimated) {
        const Pose& dr = nodes_[f.index].dr;
        return CalibratedInsAbsoluteError::createHeld(
            dr, w, sss::core::eulerFromQuaternion(dr.rotation).heading_rad,
            Eigen::Vector3d(calibration_.heading_bias_rad, calibration_.heading_cos_rad, calibration_.heading_sin_rad));
      }
      return InsAbsoluteError::create(nodes_[f.index].dr, w);
    }
    case FactorKind::kOdometry:
      if (calibration_.estimated) return CalibratedOdometryError::createHeld(calibratedOdometry(f.index));
      return RelativePoseError::create(nodes_[f.index].odometry, odometrySqrtInformation(f.index, false));
    case FactorKind::kClosure: {
      const Closure& c = closures_[f.index];
      Matrix6d sqrt_information = closureSqrtInformation(c);
      if (!isActive(c.a) || !isActive(c.b)) {
        // Inflated covariance stays positive definite: a sum of a PD and a PSD matrix.
        Matrix6d inflated;
        if (sqrtInformation(closureCovarianceInWindow(c), inflated)) sqrt_information = inflated;
      }
      // The last estimate of the separation bias, held constant (a variable only at full smoothing).
      Pose measured = c.record.closure.T_a_b;
      measured.translation += separation_bias_.estimate_m * separationDirection(c);
      return RelativePoseError::create(measured, sqrt_information);
    }
    case FactorKind::kPrior:
      return new MarginalPriorCost(prior_.linearisation, prior_.jacobian, prior_.residual);
    case FactorKind::kFix: {
      const Fix& fix = fixes_[f.index];
      return PositionFixError::create(fix.p_body, fix.record.fix.position_ne_m, fix.sqrt_information);
    }
  }
  return nullptr;
}

ceres::LossFunction* SlidingWindowPoseGraph::makeLoss(const Factor& f) const {
  if (f.kind != FactorKind::kClosure && f.kind != FactorKind::kFix) return nullptr;
  if (options_.robust_loss == "cauchy") return new ceres::CauchyLoss(options_.robust_loss_scale);
  if (options_.robust_loss == "huber") return new ceres::HuberLoss(options_.robust_loss_scale);
  return nullptr;
}

bool SlidingWindowPoseGraph::linearise(const Factor& f, LinearisedFactor& out) const {
  const std::vector<int> nodes = factorNodes(f);
  std::vector<PoseParameters> parameters;
  parameters.reserve(nodes.size());
  for (int n : nodes) parameters.push_back(toParameters(nodes_[n].estimate));
  std::vector<const double*> blocks;
  for (const PoseParameters& p : parameters) blocks.push_back(p.data());

  std::unique_ptr<ceres::CostFunction> cost(makeCost(f));
  std::unique_ptr<ceres::LossFunction> loss(makeLoss(f));
  const int rows = cost->num_residuals();
  Eigen::VectorXd residual(rows);
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor>> ambient(
      nodes.size(), Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor>(rows, 7));
  std::vector<double*> jacobians;
  for (auto& j : ambient) jacobians.push_back(j.data());
  if (!cost->Evaluate(blocks.data(), residual.data(), jacobians.data())) return false;

  // Robust loss as iteratively reweighted least squares: scale by sqrt(rho'(s)) at this point.
  double weight = 1.0;
  if (loss) {
    double rho[3];
    loss->Evaluate(residual.squaredNorm(), rho);
    weight = std::sqrt(std::max(rho[1], 0.0));
  }
  out.nodes.clear();
  std::vector<int> columns;
  for (size_t i = 0; i < nodes.size(); ++i)
    if (isActive(nodes[i])) {
      out.nodes.push_back(nodes[i]);
      columns.push_back(static_cast<int>(i));
    }
  out.jacobian.resize(rows, 6 * static_cast<int>(out.nodes.size()));
  for (size_t k = 0; k < columns.size(); ++k) {
    const int i = columns[k];
    out.jacobian.middleCols<6>(6 * static_cast<int>(k)) = weight * ambient[i] * plusJacobian(parameters[i].data());
  }
  out.residual = weight * residual;
  return out.jacobian.allFinite() && out.residual.allFinite();
}

// ---- closure decisions ------------------------------------------------------------------------

Matrix6d SlidingWindowPoseGraph::chainCovariance(int from, int to) const {
  if (from == to) return Matrix6d::Zero();
  if (from < to) {
    // D = dr_from^-1 dr_to; its right-perturbation covariance is
    // sum_e Ad(dr_to^-1 dr_{e+1}) Sigma_e Ad(.)^T = Ad(dr_to^-1) (G_to - G_from) Ad(dr_to^-1)^T.
    const Matrix6d ad = adjoint(nodes_[to].dr.inverse());
    const Matrix6d sum = nodes_[to].chain_prefix - nodes_[from].chain_prefix;
    return ad * sum * ad.transpose();
  }
  // The inverse of D(to -> from): (D Exp(d))^-1 = D^-1 Exp(-Ad(D) d).
  const Matrix6d ad = adjoint(sss::core::between(nodes_[to].dr, nodes_[from].dr));
  return ad * chainCovariance(to, from) * ad.transpose();
}

bool SlidingWindowPoseGraph::pairConsistent(const Closure& i, const Closure& j) const {
  // Cycle a_i -> b_i (closure i) -> b_j (DR) -> a_j (closure j inverted) -> a_i (DR) = identity.
  const Pose& z_i = i.record.closure.T_a_b;
  const Pose& z_j = j.record.closure.T_a_b;
  const Pose a1 = z_i;
  const Pose a2 = sss::core::between(nodes_[i.b].dr, nodes_[j.b].dr);
  const Pose a3 = z_j.inverse();
  const Pose a4 = sss::core::between(nodes_[j.a].dr, nodes_[i.a].dr);
  const Matrix6d ad_zj = adjoint(z_j);
  const Matrix6d s1 = i.record.closure.covariance;
  const Matrix6d s2 = chainCovariance(i.b, j.b);
  const Matrix6d s3 = ad_zj * j.record.closure.covariance * ad_zj.transpose();
  const Matrix6d s4 = chainCovariance(j.a, i.a);
  // Each factor's right perturbation moves to the end of the product through Ad(rest^-1).
  const Pose rest3 = a4;
  const Pose rest2 = a3 * a4;
  const Pose rest1 = a2 * rest2;
  const Matrix6d t1 = adjoint(rest1.inverse()), t2 = adjoint(rest2.inverse()), t3 = adjoint(rest3.inverse());
  const Matrix6d s = t1 * s1 * t1.transpose() + t2 * s2 * t2.transpose() + t3 * s3 * t3.transpose() + s4;
  const Vector6d e = sss::core::boxMinus(a1 * rest1, Pose::identity());
  const Eigen::LDLT<Matrix6d> ldlt(s);
  if (ldlt.info() != Eigen::Success) return false;
  const double chi2 = e.dot(ldlt.solve(e));
  return std::isfinite(chi2) && chi2 <= options_.pcm_chi2;
}

bool SlidingWindowPoseGraph::passesGate(const Closure& c, const Eigen::MatrixXd& covariance,
                                        const std::vector<int>& slot) const {
  const Pose x = sss::core::between(nodes_[c.a].estimate, nodes_[c.b].estimate);
  const Vector6d e = sss::core::boxMinus(x, c.record.closure.T_a_b);
  // Old nodes: their covariance when they left the window, uncorrelated with the window: a looser,
  // conservative gate for them (PCM still checks them).
  auto block = [&](int p, int q) -> Matrix6d {
    if (isActive(p) && isActive(q))
      return covariance.block<6, 6>(6 * slot[p - first_active_], 6 * slot[q - first_active_]);
    if (p == q) return nodes_[p].covariance;
    return Matrix6d::Zero();
  };
  const Matrix6d j_a = -adjoint(x.inverse());
  const Matrix6d s_ab = block(c.a, c.b);
  const Matrix6d s = c.record.closure.covariance + j_a * block(c.a, c.a) * j_a.transpose() + block(c.b, c.b) +
                     j_a * s_ab + s_ab.transpose() * j_a.transpose();
  const Eigen::LDLT<Matrix6d> ldlt(0.5 * (s + s.transpose()));
  if (ldlt.info() != Eigen::Success) return true;  // cannot judge: leave it to PCM
  const double chi2 = e.dot(ldlt.solve(e));
  return std::isfinite(chi2) && chi2 <= options_.gate_chi2;
}

void SlidingWindowPoseGraph::decideClosures(UpdateReport& report) {
  const int m = static_cast<int>(closures_.size());
  auto eligible = [](const Closure& c) {
    return c.record.status == ClosureStatus::kPending || c.record.status == ClosureStatus::kAccepted ||
           (c.record.status == ClosureStatus::kRejected && c.record.rejection == ClosureRejection::kInconsistent);
  };

  // 1. Chi-square gate of the new closures against the current estimate, once it means something.
  std::vector<int> fresh;
  for (int index = pcm_horizon_start_; index < m; ++index)
    if (!closures_[index].gate_checked) fresh.push_back(index);
  if (!fresh.empty()) {
    const bool gate_active = counters_.closures_accepted >= static_cast<uint64_t>(options_.gate_min_accepted_closures);
    Eigen::MatrixXd covariance;
    std::vector<int> slot;
    const bool have_covariance = gate_active && computeWindowCovariance(covariance, slot);
    for (int index : fresh) {
      Closure& c = closures_[index];
      c.gate_checked = true;
      if (c.record.status != ClosureStatus::kPending || !have_covariance) continue;
      if (!passesGate(c, covariance, slot)) {
        setStatus(c, ClosureStatus::kRejected, ClosureRejection::kChiSquareGate);
        ++report.closures_decided;
      }
    }
  }

  // 2. Closures leaving the PCM horizon keep their decision; pending ones never found support.
  const int new_start = std::max(pcm_horizon_start_, m - options_.pcm_max_closures);
  for (int index = pcm_horizon_start_; index < new_start; ++index) {
    Closure& c = closures_[index];
    if (c.record.status == ClosureStatus::kPending) {
      setStatus(c, ClosureStatus::kRejected, ClosureRejection::kNoSupport);
      ++report.closures_decided;
    }
    if (c.record.status == ClosureStatus::kAccepted)
      frozen_newest_accepted_utime_us_ = std::max(frozen_newest_accepted_utime_us_, closureUtime(c));
  }
  if (new_start != pcm_horizon_start_) {
    for (auto it = pcm_cache_.begin(); it != pcm_cache_.end();)
      it = it->first.first < new_start ? pcm_cache_.erase(it) : std::next(it);
    pcm_horizon_start_ = new_start;
  }

  // 3. Pairwise consistency over the horizon and the largest mutually consistent set (greedy).
  std::vector<int> candidates;
  for (int index = pcm_horizon_start_; index < m; ++index)
    if (eligible(closures_[index])) candidates.push_back(index);
  const int n = static_cast<int>(candidates.size());
  std::vector<std::vector<char>> consistent(n, std::vector<char>(n, 0));
  std::vector<int> degree(n, 0);
  for (int p = 0; p < n; ++p) {
    for (int q = p + 1; q < n; ++q) {
      const std::pair<int, int> key(candidates[p], candidates[q]);
      auto it = pcm_cache_.find(key);
      if (it == pcm_cache_.end())
        it = pcm_cache_.emplace(key, pairConsistent(closures_[key.first], closures_[key.second])).first;
      consistent[p][q] = consistent[q][p] = it->second ? 1 : 0;
      if (it->second) {
        ++degree[p];
        ++degree[q];
      }
    }
  }
  auto accepted = [&](int p) { return closures_[candidates[p]].record.status == ClosureStatus::kAccepted; };
  std::vector<int> order(n);
  for (int p = 0; p < n; ++p) order[p] = p;
  std::stable_sort(order.begin(), order.end(), [&](int p, int q) {
    if (degree[p] != degree[q]) return degree[p] > degree[q];
    return accepted(p) && !accepted(q);  // prefer keeping earlier decisions on ties
  });
  std::vector<int> best;
  int best_accepted = -1;
  for (int seed : order) {
    if (degree[seed] + 1 < static_cast<int>(best.size())) continue;
    std::vector<int> clique{seed};
    for (int v : order) {
      if (v == seed || !consistent[seed][v]) continue;
      bool with_all = true;
      for (int member : clique) with_all = with_all && consistent[member][v];
      if (with_all) clique.push_back(v);
    }
    int clique_accepted = 0;
    for (int member : clique) clique_accepted += accepted(member) ? 1 : 0;
    if (clique.size() > best.size() || (clique.size() == best.size() && clique_accepted > best_accepted)) {
      best = clique;
      best_accepted = clique_accepted;
    }
  }
  const bool enough = static_cast<int>(best.size()) >= options_.min_consistent_closures;
  std::vector<char> in_best(n, 0);
  if (enough)
    for (int p : best) in_best[p] = 1;
  for (int p = 0; p < n; ++p) {
    Closure& c = closures_[candidates[p]];
    const ClosureStatus before = c.record.status;
    if (in_best[p]) {
      setStatus(c, ClosureStatus::kAccepted, ClosureRejection::kNone);
    } else if (enough) {
      setStatus(c, ClosureStatus::kRejected, ClosureRejection::kInconsistent);
    } else if (c.record.status != ClosureStatus::kAccepted) {
      setStatus(c, ClosureStatus::kPending, ClosureRejection::kNone);
    }
    if (c.record.status != before) ++report.closures_decided;
  }
  window_stats_.pcm_candidates = n;

  newest_accepted_closure_utime_us_ = frozen_newest_accepted_utime_us_;
  for (int index = pcm_horizon_start_; index < m; ++index)
    if (closures_[index].record.status == ClosureStatus::kAccepted)
      newest_accepted_closure_utime_us_ = std::max(newest_accepted_closure_utime_us_, closureUtime(closures_[index]));
}

// ---- solving ----------------------------------------------------------------------------------

Eigen::Vector3d SlidingWindowPoseGraph::separationDirection(const Closure& c) const {
  if (!(options_.separation_bias_sigma_m > 0.0)) return Eigen::Vector3d::Zero();
  const Pose& T_a_b = c.record.closure.T_a_b;
  // Parallel or anti-parallel lines: B's forward axis within 30 deg of A's, either way.
  const Eigen::Vector3d forward_b = T_a_b.rotation * Eigen::Vector3d::UnitX();
  const double cos_heading = forward_b.head<2>().normalized().x();
  if (!(std::abs(cos_heading) > std::cos(30.0 * M_PI / 180.0))) return Eigen::Vector3d::Zero();
  // B off to one side of A: the overlap lies between them and each looks at it from its own side.
  const double lateral_m = T_a_b.translation.y();
  if (!(std::abs(lateral_m) > options_.separation_bias_min_lateral_m)) return Eigen::Vector3d::Zero();
  return Eigen::Vector3d(0.0, lateral_m > 0.0 ? 1.0 : -1.0, 0.0);
}

Matrix6d SlidingWindowPoseGraph::odometrySqrtInformation(int k, bool calibrated) const {
  const Node& node = nodes_[k];
  if (!calibrated || k == 0) return node.odometry_sqrt_information / std::sqrt(variance_factors_.odometry);
  Matrix6d sqrt_information;
  sqrtInformation(odometryCovariance(options_, node.distance_m - nodes_[k - 1].distance_m,
                                     options_.calibrated_odometry_drift_fraction),
                  sqrt_information);
  return sqrt_information / std::sqrt(variance_factors_.odometry);
}

CalibratedOdometryError SlidingWindowPoseGraph::calibratedOdometry(int k) const {
  const Node& node = nodes_[k];
  CalibratedOdometryError error;
  error.measured = node.odometry;
  error.sqrt_information = odometrySqrtInformation(k, true);
  error.moment_cos = node.moment_cos;
  error.moment_sin = node.moment_sin;
  error.heading_a_rad = sss::core::eulerFromQuaternion(nodes_[k - 1].dr.rotation).heading_rad;
  error.heading_b_rad = sss::core::eulerFromQuaternion(node.dr.rotation).heading_rad;
  error.held = Eigen::Vector3d(calibration_.dvl_scale, calibration_.heading_cos_rad, calibration_.heading_sin_rad);
  return error;
}

Pose SlidingWindowPoseGraph::firstNodePrior() const {
  Pose prior = nodes_[0].dr;
  if (calibration_.estimated) {
    const double e = calibration_.headingErrorRad(sss::core::eulerFromQuaternion(prior.rotation).heading_rad);
    prior.rotation = (Eigen::Quaterniond(Eigen::AngleAxisd(-e, Eigen::Vector3d::UnitZ())) * prior.rotation).normalized();
  }
  return prior;
}

bool SlidingWindowPoseGraph::calibrationWanted() const {
  return options_.calibration == "always" || (options_.calibration == "auto" && fix_counters_.accepted > 0);
}

bool SlidingWindowPoseGraph::solve(const std::vector<Factor>& factors, int max_iterations, UpdateReport& report,
                                   bool estimate_separation_bias, bool estimate_calibration) {
  PoseManifold manifold;  // outlives the problem, which does not own it
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);

  std::unordered_map<int, int> slot_of;
  std::vector<int> node_of_slot;
  std::vector<PoseParameters> parameters;
  parameters.reserve(nodes_.size() - first_active_ + 16);
  // Slots first so that the parameter storage does not move while blocks are added.
  for (const Factor& f : factors)
    for (int n : factorNodes(f))
      if (slot_of.emplace(n, static_cast<int>(node_of_slot.size())).second) node_of_slot.push_back(n);
  for (int n : node_of_slot) parameters.push_back(toParameters(nodes_[n].estimate));
  for (size_t s = 0; s < node_of_slot.size(); ++s) {
    problem.AddParameterBlock(parameters[s].data(), kPoseAmbientSize, &manifold);
    if (!isActive(node_of_slot[s])) problem.SetParameterBlockConstant(parameters[s].data());
  }
  // The separation bias as a variable: opposite-side closures take it as a third block, a zero-mean
  // prior of separation_bias_sigma_m holds it where DR cannot tell.
  double separation_bias_m = separation_bias_.estimate_m;
  int biased_closures = 0;
  // The DR calibration as a variable: odometry and INS factors take it as a block, zero-mean priors
  // hold what nothing observes.
  std::array<double, kCalibrationSize> calibration = {calibration_.dvl_scale, calibration_.heading_bias_rad,
                                                      calibration_.heading_cos_rad, calibration_.heading_sin_rad};
  for (const Factor& f : factors) {
    std::vector<double*> blocks;
    for (int n : factorNodes(f)) blocks.push_back(parameters[slot_of[n]].data());
    if (estimate_calibration && (f.kind == FactorKind::kOdometry || f.kind == FactorKind::kInsAbsolute ||
                                 f.kind == FactorKind::kFirstNode)) {
      blocks.push_back(calibration.data());
      const Node& node = nodes_[f.index];
      const double dr_heading_rad = sss::core::eulerFromQuaternion(node.dr.rotation).heading_rad;
      ceres::CostFunction* cost =
          f.kind == FactorKind::kOdometry
              ? CalibratedOdometryError::createEstimated(calibratedOdometry(f.index))
          : f.kind == FactorKind::kInsAbsolute
              ? CalibratedInsAbsoluteError::createEstimated(node.dr, insAbsoluteWeights(options_), dr_heading_rad)
              : CalibratedPosePriorError::create(node.dr, firstNodeSqrtInformation(options_), dr_heading_rad);
      problem.AddResidualBlock(cost, nullptr, blocks);
      continue;
    }
    // Full smoothing: every node is a variable, so the closure's own weight is the whole of it.
    if (estimate_separation_bias && f.kind == FactorKind::kClosure) {
      const Closure& c = closures_[f.index];
      const Eigen::Vector3d direction = separationDirection(c);
      if (direction.squaredNorm() > 0.0) {
        blocks.push_back(&separation_bias_m);
        problem.AddResidualBlock(
            BiasedRelativePoseError::create(c.record.closure.T_a_b, direction, closureSqrtInformation(c)),
            makeLoss(f), blocks);
        ++biased_closures;
        continue;
      }
    }
    problem.AddResidualBlock(makeCost(f), makeLoss(f), blocks);
  }
  if (estimate_separation_bias && biased_closures > 0) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ScalarPriorError, 1, 1>(
                                 new ScalarPriorError{0.0, 1.0 / options_.separation_bias_sigma_m}),
                             nullptr, &separation_bias_m);
  }
  const bool calibrating = estimate_calibration && problem.HasParameterBlock(calibration.data());
  if (calibrating) {
    const double sigmas[kCalibrationSize] = {options_.calibration_scale_sigma, options_.calibration_heading_bias_sigma_rad,
                                             options_.calibration_heading_deviation_sigma_rad,
                                             options_.calibration_heading_deviation_sigma_rad};
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<CalibrationPriorError, kCalibrationSize, kCalibrationSize>(
                                 new CalibrationPriorError{Eigen::Vector4d(1.0 / sigmas[0], 1.0 / sigmas[1],
                                                                           1.0 / sigmas[2], 1.0 / sigmas[3])}),
                             nullptr, calibration.data());
  }

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  if (ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE))
    solver_options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  else if (ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE))
    solver_options.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
  else
    solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = max_iterations;
  if (options_.max_solver_time_s > 0.0) solver_options.max_solver_time_in_seconds = options_.max_solver_time_s;
  solver_options.num_threads = 1;  // deterministic, and the machine's cores belong to the matcher
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;

  const Clock::time_point start = Clock::now();
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  report.solve_s = secondsSince(start);
  report.iterations = static_cast<int>(summary.iterations.size()) - 1;
  if (!summary.IsSolutionUsable() || !std::isfinite(summary.final_cost)) {
    report.ok = false;
    report.message = "solver failed (" + summary.message + "); keeping the previous estimate";
    ++counters_.solver_failures;
    return false;
  }
  for (size_t s = 0; s < node_of_slot.size(); ++s) {
    const int n = node_of_slot[s];
    if (!isActive(n)) continue;
    Pose pose = fromParameters(parameters[s].data());
    if (!finitePose(pose)) continue;
    nodes_[n].estimate = normalisedPose(pose);
  }
  window_stats_.residual_blocks = problem.NumResidualBlocks();
  if (estimate_separation_bias) {  // no stale figures from an earlier smoothing
    separation_bias_.closures = biased_closures;
    separation_bias_.tested_m = 0.0;
    separation_bias_.sigma_m = std::numeric_limits<double>::quiet_NaN();
  }
  if (calibrating && std::all_of(calibration.begin(), calibration.end(), [](double v) { return std::isfinite(v); })) {
    calibration_.estimated = true;
    calibration_.dvl_scale = calibration[0];
    calibration_.heading_bias_rad = calibration[1];
    calibration_.heading_cos_rad = calibration[2];
    calibration_.heading_sin_rad = calibration[3];
    calibration_.sigma = marginalSigmas<kCalibrationSize>(problem, calibration.data());
  }
  if (estimate_separation_bias && biased_closures > 0 && std::isfinite(separation_bias_m)) {
    separation_bias_.estimate_m = separation_bias_.tested_m = separation_bias_m;
    // Its sigma: the bias's marginal covariance (every node a variable at full smoothing).
    separation_bias_.sigma_m = marginalSigmas<1>(problem, &separation_bias_m)(0);
  }
  return true;
}

void SlidingWindowPoseGraph::reweighFromResiduals(const std::vector<Factor>& factors, UpdateReport& report,
                                                  bool estimate_calibration) {
  enum Group { kClosures = 0, kOdometry = 1, kGroups = 2 };
  // With "none" one pass: the components are measured (DR's strain is a diagnostic), nothing changes.
  const bool reweigh = options_.closure_reweighting != "none";
  for (int iteration = 0; iteration < (reweigh ? options_.variance_component_iterations : 1); ++iteration) {
    // Whitened with the current factors (makeCost) and the robust weights at this estimate, so the
    // estimate is a correction of the current factor, and an outlying closure weighs as it does in
    // the solve.
    std::vector<WhitenedFactor> whitened;
    whitened.reserve(factors.size());
    for (const Factor& f : factors) {
      LinearisedFactor lf;
      if (!linearise(f, lf)) continue;
      const int group = f.kind == FactorKind::kClosure ? kClosures : f.kind == FactorKind::kOdometry ? kOdometry : -1;
      whitened.push_back({lf.nodes, std::move(lf.jacobian), std::move(lf.residual), group});
    }
    const VarianceFactors before = variance_factors_;
    std::vector<VarianceComponent> components;
    if (!estimateVarianceComponents(whitened, static_cast<int>(nodes_.size()), kGroups, components)) return;
    // A group the solution absorbs (no closures yet, or too few to disagree) keeps its factor.
    auto usable = [](const VarianceComponent& c) { return c.redundancy >= 1.0 && std::isfinite(c.varianceFactor()); };
    bool settled = true;
    auto scale = [&](double& factor, double ratio) {
      const double next = std::clamp(factor * ratio, options_.variance_factor_min, options_.variance_factor_max);
      settled = settled && std::abs(next / factor - 1.0) < 0.01;  // converges linearly: stop at 1 %
      factor = next;
    };
    const VarianceComponent& closures = components[kClosures];
    const VarianceComponent& odometry = components[kOdometry];
    if (!reweigh) {
      // measured only
    } else if (options_.closure_reweighting == "dr_bound") {
      // Only ever widens the closures, by what DR's residuals exceed their model.
      if (usable(odometry) && odometry.varianceFactor() > 1.0) scale(variance_factors_.closure, odometry.varianceFactor());
    } else {
      if (usable(closures)) scale(variance_factors_.closure, closures.varianceFactor());
      if (usable(odometry)) scale(variance_factors_.odometry, odometry.varianceFactor());
    }
    variance_factors_.closure_redundancy = closures.redundancy;
    variance_factors_.odometry_redundancy = odometry.redundancy;
    variance_factors_.odometry_strain = odometry.varianceFactor();
    variance_factors_.closures = closures.factors;
    if (!reweigh) return;
    ++variance_factors_.iterations;
    if (settled) return;
    UpdateReport again;
    if (!solve(factors, options_.full_smoothing_max_iterations, again, separation_bias_.applied, estimate_calibration)) {
      variance_factors_ = before;  // the estimate stays the last good one, and so do its weights
      return;
    }
    report.iterations += again.iterations;
    report.solve_s += again.solve_s;
  }
}

void SlidingWindowPoseGraph::marginaliseOldest() {
  const int m = first_active_;
  const std::vector<Factor> factors = factorsTouching(m);
  std::vector<LinearisedFactor> linearised;
  std::vector<int> kept;  // the other variable nodes, in ascending order
  for (const Factor& f : factors) {
    LinearisedFactor lf;
    if (!linearise(f, lf)) continue;  // a non-finite factor carries no usable information
    for (int n : lf.nodes)
      if (n != m) kept.push_back(n);
    linearised.push_back(std::move(lf));
  }
  std::sort(kept.begin(), kept.end());
  kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
  std::unordered_map<int, int> position{{m, 0}};
  for (size_t k = 0; k < kept.size(); ++k) position[kept[k]] = static_cast<int>(k) + 1;

  const int dim = 6 * (1 + static_cast<int>(kept.size()));
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(dim, dim);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(dim);
  for (const LinearisedFactor& lf : linearised) {
    for (size_t p = 0; p < lf.nodes.size(); ++p) {
      const int row = 6 * position[lf.nodes[p]];
      const auto jp = lf.jacobian.middleCols<6>(6 * static_cast<int>(p));
      g.segment<6>(row) += jp.transpose() * lf.residual;
      for (size_t q = 0; q < lf.nodes.size(); ++q) {
        const int col = 6 * position[lf.nodes[q]];
        h.block<6, 6>(row, col) += jp.transpose() * lf.jacobian.middleCols<6>(6 * static_cast<int>(q));
      }
    }
  }

  // Schur complement onto the kept nodes: H* = H_kk - H_km H_mm^-1 H_mk, g* = g_k - H_km H_mm^-1 g_m.
  const Matrix6d h_mm = 0.5 * (h.topLeftCorner<6, 6>() + h.topLeftCorner<6, 6>().transpose());
  const Eigen::LDLT<Matrix6d> ldlt(h_mm);
  Matrix6d h_mm_inverse = ldlt.solve(Matrix6d::Identity());
  if (ldlt.info() != Eigen::Success || !h_mm_inverse.allFinite())
    h_mm_inverse = Eigen::CompleteOrthogonalDecomposition<Matrix6d>(h_mm).pseudoInverse();
  nodes_[m].conditional_covariance = 0.5 * (h_mm_inverse + h_mm_inverse.transpose());

  Prior prior;
  if (!kept.empty()) {
    const int k = dim - 6;
    const Eigen::MatrixXd h_km = h.bottomLeftCorner(k, 6);
    Eigen::MatrixXd h_star = h.bottomRightCorner(k, k) - h_km * h_mm_inverse * h_km.transpose();
    h_star = 0.5 * (h_star + h_star.transpose());
    const Eigen::VectorXd g_star = g.tail(k) - h_km * h_mm_inverse * g.head<6>();
    // H* = V diag(l) V^T; J = diag(sqrt l) V^T and r0 = diag(1/sqrt l) V^T g* give
    // 0.5 |r0 + J d|^2 = 0.5 d^T H* d + g*^T d + const. Null directions (gauge) are dropped.
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(h_star);
    const Eigen::VectorXd lambda = eigen.eigenvalues();
    const double threshold = std::max(1e-12 * lambda.maxCoeff(), 1e-12);
    std::vector<int> keep;
    for (int i = 0; i < k; ++i)
      if (lambda(i) > threshold) keep.push_back(i);
    prior.jacobian.resize(static_cast<int>(keep.size()), k);
    prior.residual.resize(static_cast<int>(keep.size()));
    for (size_t r = 0; r < keep.size(); ++r) {
      const double s = std::sqrt(lambda(keep[r]));
      const Eigen::VectorXd v = eigen.eigenvectors().col(keep[r]);
      prior.jacobian.row(static_cast<int>(r)) = s * v.transpose();
      prior.residual(static_cast<int>(r)) = v.dot(g_star) / s;
    }
    if (!keep.empty()) {
      prior.nodes = kept;
      for (int n : kept) prior.linearisation.push_back(nodes_[n].estimate);
    }
  }
  prior_ = std::move(prior);
  for (const Factor& f : factors)
    if (f.kind == FactorKind::kClosure) closures_[f.index].record.marginalised = true;
  ++first_active_;
}

bool SlidingWindowPoseGraph::computeWindowCovariance(Eigen::MatrixXd& covariance, std::vector<int>& slot) const {
  const int n = static_cast<int>(nodes_.size()) - first_active_;
  if (n <= 0) return false;
  slot.resize(n);
  for (int i = 0; i < n; ++i) slot[i] = i;
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(6 * n, 6 * n);
  for (const Factor& f : windowFactors()) {
    LinearisedFactor lf;
    if (!linearise(f, lf)) continue;
    for (size_t p = 0; p < lf.nodes.size(); ++p) {
      const int row = 6 * (lf.nodes[p] - first_active_);
      for (size_t q = 0; q < lf.nodes.size(); ++q) {
        const int col = 6 * (lf.nodes[q] - first_active_);
        h.block<6, 6>(row, col) += lf.jacobian.middleCols<6>(6 * static_cast<int>(p)).transpose() *
                                   lf.jacobian.middleCols<6>(6 * static_cast<int>(q));
      }
    }
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (h + h.transpose()));
  if (llt.info() != Eigen::Success) return false;
  covariance = llt.solve(Eigen::MatrixXd::Identity(6 * n, 6 * n));
  return covariance.allFinite();
}

void SlidingWindowPoseGraph::refreshCovariances() {
  Eigen::MatrixXd covariance;
  std::vector<int> slot;
  if (!computeWindowCovariance(covariance, slot)) return;
  for (int n = first_active_; n < static_cast<int>(nodes_.size()); ++n) {
    const int s = slot[n - first_active_];
    const Matrix6d block = covariance.block<6, 6>(6 * s, 6 * s);
    nodes_[n].covariance = 0.5 * (block + block.transpose());
    nodes_[n].has_covariance = true;
  }
}

void SlidingWindowPoseGraph::refreshWindowStats(const std::vector<Factor>& factors) {
  window_stats_.active_nodes = static_cast<int>(nodes_.size()) - first_active_;
  window_stats_.variable_blocks = window_stats_.active_nodes;
  std::vector<int> constants;
  for (const Factor& f : factors)
    for (int n : factorNodes(f))
      if (!isActive(n)) constants.push_back(n);
  std::sort(constants.begin(), constants.end());
  window_stats_.constant_blocks =
      static_cast<int>(std::unique(constants.begin(), constants.end()) - constants.begin());
  window_stats_.residual_blocks = static_cast<int>(factors.size());
  window_stats_.prior_nodes = static_cast<int>(prior_.nodes.size());
  window_stats_.prior_rows = static_cast<int>(prior_.residual.size());
}

UpdateReport SlidingWindowPoseGraph::optimize() {
  const Clock::time_point start = Clock::now();
  UpdateReport report;
  if (nodes_.empty()) return report;
  decideClosures(report);
  decideFixes(false);
  const std::vector<Factor> factors = windowFactors();
  refreshWindowStats(factors);
  solve(factors, options_.max_iterations, report);
  // Marginalise at the solution even after a failed solve: the window must stay bounded.
  while (static_cast<int>(nodes_.size()) - first_active_ > options_.window_size) {
    marginaliseOldest();
    ++counters_.nodes_marginalised;
  }
  refreshCovariances();
  update_utime_us_ = nodes_.back().utime_us;
  report.update_s = secondsSince(start);
  ++counters_.updates;
  counters_.last_update_s = report.update_s;
  counters_.last_solve_s = report.solve_s;
  counters_.last_iterations = report.iterations;
  return report;
}

UpdateReport SlidingWindowPoseGraph::fullSmoothing() {
  const Clock::time_point start = Clock::now();
  UpdateReport report;
  if (nodes_.empty()) return report;
  decideClosures(report);
  decideFixes(true);
  // Every node is a variable: solve with the window boundary at the first node.
  const int boundary = first_active_;
  first_active_ = 0;
  const std::vector<Factor> factors = allFactors();
  bool ok = true;
  const bool calibrate = calibrationWanted();
  const DrCalibration calibration_start = calibration_;
  if (options_.separation_bias_sigma_m > 0.0) {
    // The separation bias as a variable. Kept only when significant and asked for; otherwise the
    // graph is solved again from where it was, without it (its estimate stays as a diagnostic).
    std::vector<Pose> start;
    start.reserve(nodes_.size());
    for (const Node& n : nodes_) start.push_back(n.estimate);
    UpdateReport measured;
    const bool estimated = solve(factors, options_.full_smoothing_max_iterations, measured, true, calibrate);
    report.iterations += measured.iterations;
    report.solve_s += measured.solve_s;
    // sigma_m is NaN when no opposite-side closure was accepted or the covariance failed.
    separation_bias_.significant =
        estimated && std::abs(separation_bias_.tested_m) >= options_.separation_bias_significance * separation_bias_.sigma_m;
    separation_bias_.applied = separation_bias_.significant && options_.separation_bias_apply;
    if (!separation_bias_.applied) {
      for (size_t i = 0; i < nodes_.size(); ++i) nodes_[i].estimate = start[i];
      separation_bias_.estimate_m = 0.0;
      calibration_ = calibration_start;
      ok = solve(factors, options_.full_smoothing_max_iterations, report, false, calibrate);
    } else {
      ok = estimated;
    }
  } else {
    ok = solve(factors, options_.full_smoothing_max_iterations, report, false, calibrate);
  }
  if (ok) reweighFromResiduals(factors, report, calibrate);
  if (ok) {
    // Re-derive the window's prior at the smoothed estimate, eliminating the old nodes in order.
    prior_ = Prior();
    for (Closure& c : closures_) c.record.marginalised = false;
    while (first_active_ < boundary) marginaliseOldest();
  } else {
    first_active_ = boundary;
  }
  refreshWindowStats(windowFactors());
  refreshCovariances();
  update_utime_us_ = nodes_.back().utime_us;
  report.update_s = secondsSince(start);
  ++counters_.full_smoothings;
  counters_.last_update_s = report.update_s;
  counters_.last_solve_s = report.solve_s;
  counters_.last_iterations = report.iterations;
  return report;
}

// ---- queries ----------------------------------------------------------------------------------

std::optional<Pose> SlidingWindowPoseGraph::estimate(int64_t subframe_id) const {
  const auto it = index_of_.find(subframe_id);
  if (it == index_of_.end()) return std::nullopt;
  return nodes_[it->second].estimate;
}

std::optional<Matrix6d> SlidingWindowPoseGraph::covariance(int64_t subframe_id) const {
  const auto it = index_of_.find(subframe_id);
  if (it == index_of_.end() || !nodes_[it->second].has_covariance) return std::nullopt;
  return nodes_[it->second].covariance;
}

std::vector<NodeState> SlidingWindowPoseGraph::nodes() const {
  std::vector<NodeState> out;
  out.reserve(nodes_.size());
  for (size_t i = 0; i < nodes_.size(); ++i) {
    const Node& n = nodes_[i];
    out.push_back({n.id, n.utime_us, n.dr, n.estimate, n.distance_m, !isActive(static_cast<int>(i))});
  }
  return out;
}

std::optional<NodeState> SlidingWindowPoseGraph::newestNode() const {
  if (nodes_.empty()) return std::nullopt;
  const Node& n = nodes_.back();
  return NodeState{n.id, n.utime_us, n.dr, n.estimate, n.distance_m, !isActive(static_cast<int>(nodes_.size()) - 1)};
}

std::vector<ClosureRecord> SlidingWindowPoseGraph::closures() const {
  std::vector<ClosureRecord> out;
  out.reserve(closures_.size());
  for (const Closure& c : closures_) out.push_back(c.record);
  return out;
}

std::vector<FixRecord> SlidingWindowPoseGraph::fixes() const {
  std::vector<FixRecord> out;
  out.reserve(fixes_.size());
  for (const Fix& f : fixes_) {
    FixRecord record = f.record;
    if (f.node >= 0) record.residual_ne_m = record.fix.position_ne_m - (nodes_[f.node].estimate * f.p_body).head<2>();
    out.push_back(record);
  }
  return out;
}

Correction SlidingWindowPoseGraph::correctionAt(int64_t utime_us) const {
  Correction out;
  out.update_utime_us = update_utime_us_;
  out.accepted_closures = static_cast<int>(counters_.closures_accepted);
  if (nodes_.empty()) {
    out.covariance = 1e6 * Matrix6d::Identity();  // nothing known yet
    return out;
  }
  auto correctionOf = [&](const Node& n) { return n.estimate * n.dr.inverse(); };
  const auto after = std::lower_bound(nodes_.begin(), nodes_.end(), utime_us,
                                      [](const Node& n, int64_t t) { return n.utime_us < t; });
  const Node* reference = nullptr;
  double distance_m = 0.0;
  // DR speed of the nearest edge, to turn time outside the nodes into distance.
  auto speed = [&](size_t i, size_t j) {
    const double dt_s = 1e-6 * static_cast<double>(nodes_[j].utime_us - nodes_[i].utime_us);
    return dt_s > 0.0 ? (nodes_[j].distance_m - nodes_[i].distance_m) / dt_s : options_.nominal_speed_m_s;
  };
  if (after == nodes_.begin()) {
    reference = &nodes_.front();
    out.T_corrected_dr = correctionOf(*reference);
    const double v = nodes_.size() > 1 ? speed(0, 1) : options_.nominal_speed_m_s;
    distance_m = reference->distance_m - v * 1e-6 * static_cast<double>(reference->utime_us - utime_us);
  } else if (after == nodes_.end()) {
    reference = &nodes_.back();
    out.T_corrected_dr = correctionOf(*reference);
    const size_t last = nodes_.size() - 1;
    const double v = nodes_.size() > 1 ? speed(last - 1, last) : options_.nominal_speed_m_s;
    distance_m = reference->distance_m + v * 1e-6 * static_cast<double>(utime_us - reference->utime_us);
  } else {
    const Node& n1 = *after;
    const Node& n0 = *(after - 1);
    const double alpha = static_cast<double>(utime_us - n0.utime_us) / static_cast<double>(n1.utime_us - n0.utime_us);
    out.T_corrected_dr = sss::core::interpolate(correctionOf(n0), correctionOf(n1), alpha);
    reference = alpha <= 0.5 ? &n0 : &n1;
    distance_m = n0.distance_m + alpha * (n1.distance_m - n0.distance_m);
  }
  const Matrix6d node_covariance = reference->has_covariance ? reference->covariance : 1e6 * Matrix6d::Identity();
  out.covariance = node_covariance + odometryCovariance(options_, std::abs(distance_m - reference->distance_m));
  // Corrected by closures or fixes; degraded when the newest of them is old.
  const int64_t newest_closure_us = counters_.closures_accepted > 0 ? newest_accepted_closure_utime_us_ : -1;
  const int64_t newest_us = std::max(newest_closure_us, newest_accepted_fix_utime_us_);
  if (newest_us < 0) {
    out.status = CorrectionStatus::kDrOnly;
  } else {
    const double age_s = 1e-6 * static_cast<double>(utime_us - newest_us);
    out.status = age_s > options_.degraded_after_s ? CorrectionStatus::kDegraded : CorrectionStatus::kCorrected;
  }
  return out;
}

}  // namespace sss::optimiser
