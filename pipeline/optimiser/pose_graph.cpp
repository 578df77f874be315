// Sliding-window pose graph, see pose_graph.hpp: construction, input, factors and queries here;
// options in pose_graph_options.cpp, closure decisions in pose_graph_closures.cpp, the solves and
// marginalisation in pose_graph_solve.cpp, checkpoint I/O in pose_graph_checkpoint.cpp.
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
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "pipeline/optimiser/pose_graph_internal.hpp"
#include "pipeline/optimiser/pose_manifold.hpp"

namespace sss::optimiser {

namespace {

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
  return odometryCovariance(o, distance_m, o.odometry_drift_fraction, o.odometry_drift_fraction);
}

Matrix6d SlidingWindowPoseGraph::odometryCovariance(const PoseGraphOptions& o, double distance_m,
                                                    double along_drift_fraction, double cross_drift_fraction) {
  const double d = std::max(distance_m, 0.0);
  const double random = o.odometry_random_walk_m_per_sqrt_m * o.odometry_random_walk_m_per_sqrt_m * d +
                        o.odometry_min_sigma_m * o.odometry_min_sigma_m;
  // Forward (x): the DVL scale's drift; starboard (y): the heading error's.
  const double along = random + (along_drift_fraction * d) * (along_drift_fraction * d);
  const double cross = random + (cross_drift_fraction * d) * (cross_drift_fraction * d);
  const double heading = o.odometry_heading_random_walk_rad_per_sqrt_m *
                             o.odometry_heading_random_walk_rad_per_sqrt_m * d +
                         o.odometry_min_heading_sigma_rad * o.odometry_min_heading_sigma_rad;
  const double attitude = o.odometry_attitude_sigma_rad * o.odometry_attitude_sigma_rad;
  Vector6d diagonal;
  diagonal << along, cross, o.odometry_depth_sigma_m * o.odometry_depth_sigma_m, attitude, attitude, heading;
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
    const Matrix6d sqrt_information = firstNodeSqrtInformation(options_, firstNodeHorizontalSigma());
    node.covariance = (sqrt_information.transpose() * sqrt_information).inverse();
    node.has_covariance = true;
  }
  index_of_[subframe_id] = static_cast<int>(nodes_.size());
  nodes_.push_back(std::move(node));
  ++counters_.nodes_added;
  return Status::success();
}

Eigen::Vector2d SlidingWindowPoseGraph::firstNodeHorizontalSigma() const {
  Eigen::Vector2d sigma_ne_m = Eigen::Vector2d::Constant(options_.first_node_sigma_m);
  if (options_.first_node_sigma_from_ins) sigma_ne_m = sigma_ne_m.cwiseMax(first_node_ins_sigma_ne_m_);
  return sigma_ne_m;
}

Status SlidingWindowPoseGraph::setFirstNodeHorizontalSigma(double north_m, double east_m) {
  if (!(std::isfinite(north_m) && std::isfinite(east_m) && north_m >= 0.0 && east_m >= 0.0))
    return Status::error("the INS's start accuracy must be finite and >= 0 (north " + std::to_string(north_m) +
                         " m, east " + std::to_string(east_m) + " m); the anchor keeps first_node_sigma_m");
  // Once the first node has left the window its anchor is part of the marginalisation prior: a
  // different sigma now would make the window and the end-of-mission smoothing disagree.
  if (first_active_ > 0)
    return Status::error("the first node is already marginalised; its anchor can no longer change");
  first_node_ins_sigma_ne_m_ = Eigen::Vector2d(north_m, east_m);
  if (nodes_.size() == 1) {
    // A lone first node's covariance is its anchor's (every solve recomputes the covariances).
    const Matrix6d sqrt_information = firstNodeSqrtInformation(options_, firstNodeHorizontalSigma());
    nodes_[0].covariance = (sqrt_information.transpose() * sqrt_information).inverse();
  }
  return Status::success();
}

Status SlidingWindowPoseGraph::setOdometryDriftFraction(double fraction) {
  if (!(std::isfinite(fraction) && fraction >= 0.0))
    return Status::error("odometry drift fraction must be finite and >= 0 (" + std::to_string(fraction) +
                         "); the odometry keeps " + std::to_string(options_.odometry_drift_fraction));
  options_.odometry_drift_fraction = fraction;
  for (size_t k = 1; k < nodes_.size(); ++k) setupDerived(nodes_[k], &nodes_[k - 1]);
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
  f.record.information_weight = fixInformationWeight(fix);
  fixes_.push_back(std::move(f));
  return Status::success();
}

double SlidingWindowPoseGraph::fixInformationWeight(const AbsoluteFix& fix) const {
  const double tau_s = fix.source == "usbl" ? options_.usbl_fix_correlation_s : options_.gnss_fix_correlation_s;
  if (!(tau_s > 0.0)) return 1.0;
  // The nearest earlier fix of the same source (fixes arrive in time order per source; one that
  // arrives late is weighted against what came before it).
  int64_t previous_utime_us = std::numeric_limits<int64_t>::min();
  for (const Fix& other : fixes_)
    if (other.record.fix.source == fix.source && other.record.fix.utime_us <= fix.utime_us)
      previous_utime_us = std::max(previous_utime_us, other.record.fix.utime_us);
  if (previous_utime_us == std::numeric_limits<int64_t>::min()) return 1.0;
  // Gauss-Markov: the part of this fix's error not already in the previous one's. A repeated fix
  // of the same time adds nothing; the floor keeps its covariance finite.
  const double rho = std::exp(-1e-6 * static_cast<double>(fix.utime_us - previous_utime_us) / tau_s);
  return std::max((1.0 - rho) / (1.0 + rho), 1e-6);
}

bool SlidingWindowPoseGraph::tieFix(Fix& f, int n) const {
  const Node& node = nodes_[n];
  f.node = n;
  f.record.subframe_id = node.id;
  f.p_body = node.dr.inverse() * f.record.fix.dr_position_m;
  // The DR between the node and the fix drifts like any odometry edge of that length.
  const double dr_variance =
      odometryCovariance(options_, std::abs(f.record.fix.dr_distance_m - node.distance_m))(0, 0);
  const Eigen::Matrix2d dr_covariance = dr_variance * Eigen::Matrix2d::Identity();
  // The gate tests the fix against its own sigma; the solve takes the share of its information the
  // fixes before it did not already give (correlated errors, fixInformationWeight).
  f.gate_covariance = f.record.fix.covariance_m2 + dr_covariance;
  const Eigen::Matrix2d covariance = f.record.fix.covariance_m2 / f.record.information_weight + dr_covariance;
  const Eigen::LLT<Eigen::Matrix2d> llt(covariance);
  if (llt.info() != Eigen::Success) return false;
  f.sqrt_information = llt.matrixL().solve(Eigen::Matrix2d::Identity());
  return f.sqrt_information.allFinite() && f.gate_covariance.allFinite();
}

Eigen::Matrix2d SlidingWindowPoseGraph::calibrationDriftCovariance(int m, int n) const {
  // A DVL scale error s stretches every DR step; a heading error b + a_c cos psi + a_s sin psi turns
  // it (to starboard for a clockwise error). The chords between nodes stand for the path.
  Eigen::Matrix<double, 2, 4> sensitivity = Eigen::Matrix<double, 2, 4>::Zero();
  for (int k = std::max(m, 0) + 1; k <= n && k < static_cast<int>(nodes_.size()); ++k) {
    const Eigen::Vector2d step = (nodes_[k].dr.translation - nodes_[k - 1].dr.translation).head<2>();
    if (!(step.norm() > 0.0)) continue;
    const double heading_rad = std::atan2(step.y(), step.x());
    const Eigen::Vector2d turned(-step.y(), step.x());
    sensitivity.col(0) += step;
    sensitivity.col(1) += turned;
    sensitivity.col(2) += std::cos(heading_rad) * turned;
    sensitivity.col(3) += std::sin(heading_rad) * turned;
  }
  const Eigen::Vector4d prior(options_.calibration_scale_sigma, options_.calibration_heading_bias_sigma_rad,
                              options_.calibration_heading_deviation_sigma_rad,
                              options_.calibration_heading_deviation_sigma_rad);
  Eigen::Vector4d sigma = prior;
  if (calibration_.estimated) {
    for (int i = 0; i < 4; ++i)
      if (std::isfinite(calibration_.sigma(i))) sigma(i) = std::min(calibration_.sigma(i), prior(i));
  }
  return sensitivity * sigma.cwiseAbs2().asDiagonal() * sensitivity.transpose();
}

void SlidingWindowPoseGraph::decideFixes(bool final) {
  if (nodes_.empty()) return;
  // Nodes that fixes accepted before this pass tie down: their information is in the estimate (a fix
  // accepted in this pass is not yet, and the next one must not be gated against the old estimate
  // as if it were).
  std::vector<int> tied_nodes;
  for (const Fix& f : fixes_)
    if (f.record.status == FixStatus::kAccepted && f.node >= 0) tied_nodes.push_back(f.node);
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
    const Eigen::Matrix2d& fix_covariance = f.gate_covariance;
    const Matrix6d node_covariance = node.has_covariance ? node.covariance : Matrix6d::Zero();
    // Plus the systematic drift the held calibration leaves since the newest node an accepted fix
    // ties down (or the first node): the window's covariance grows with the square root of the
    // distance, a heading bias or DVL scale error linearly (GNSS at the dive and at the surfacing
    // alone was gated out after 5 km with 20 m of drift).
    int tied_down = 0;
    for (const int tied : tied_nodes)
      if (tied <= f.node) tied_down = std::max(tied_down, tied);
    const Eigen::Matrix2d s = jacobian * node_covariance * jacobian.transpose() + fix_covariance +
                              calibrationDriftCovariance(tied_down, f.node);
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
  if (separationWidened()) {
    // The residual's translation is in B's frame (T = T_hat Exp(d)); the direction is A's lateral.
    const Eigen::Vector3d direction = c.record.closure.T_a_b.rotation.inverse() * separationDirection(c);
    const double disputed_m2 = separation_bias_.tested_m * separation_bias_.tested_m +
                               separation_bias_.sigma_m * separation_bias_.sigma_m;
    sigma.topLeftCorner<3, 3>() += disputed_m2 * direction * direction.transpose();
  }
  return sigma;
}

Matrix6d SlidingWindowPoseGraph::closureSqrtInformation(const Closure& c) const {
  return c.sqrt_information / std::sqrt(variance_factors_.closure);
}

ceres::CostFunction* SlidingWindowPoseGraph::makeCost(const Factor& f) const {
  switch (f.kind) {
    case FactorKind::kFirstNode:
      return PosePriorError::create(firstNodePrior(), firstNodeSqrtInformation(options_, firstNodeHorizontalSigma()));
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
      if (calibration_.estimated) return CalibratedOdometryError::createHeld(calibratedOdometry(f.index, false));
      return RelativePoseError::create(nodes_[f.index].odometry, odometrySqrtInformation(f.index, false));
    case FactorKind::kClosure: {
      const Closure& c = closures_[f.index];
      Matrix6d sqrt_information = closureSqrtInformation(c);
      if (!isActive(c.a) || !isActive(c.b) || (separationWidened() && separationDirection(c).squaredNorm() > 0.0)) {
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
  out.robust_weight = weight;
  return out.jacobian.allFinite() && out.residual.allFinite();
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
