// Checkpoint of the sliding-window pose graph: versioned text (doubles round-trip exactly),
// an FNV-1a checksum line, written to a temporary file, fsync'ed and renamed into place (see
// checkpoint_io.hpp). The optimiser's own checkpoint embeds checkpointText().
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "pipeline/core/state_file.hpp"
#include "pipeline/optimiser/checkpoint_io.hpp"
#include "pipeline/optimiser/pose_graph.hpp"
#include "pipeline/optimiser/pose_manifold.hpp"

namespace sss::optimiser {

using sss::core::Matrix6d;
using sss::core::Pose;

namespace {

constexpr const char* kMagic = "sss-pose-graph-checkpoint";
// 2 adds the variance factors; a version 1 file (before them) restores with factors of 1.
// 3 adds the separation bias; older files restore without one (0, not applied).
// 4 adds the absolute fixes; older files restore without any.
// 5 adds the DR calibration; older files restore without one (not estimated).
// 6 adds when the calibration was last estimated and whether the DVL scale was part of it; older
// files re-estimate it at the next update and take the scale as estimated with the rest.
// 7 adds the INS's start accuracy (the first node's anchor); older files restore without it.
constexpr int kVersion = 7;
constexpr size_t kMaxFileBytes = size_t{1} << 31;  // 2 GiB: far above any mission

using checkpoint::TextReader;
using checkpoint::TextWriter;

}  // namespace

std::string SlidingWindowPoseGraph::checkpointText() const {
  TextWriter w;
  w.word(kMagic);
  w.integer(kVersion);
  w.endLine();
  w.word("state");
  w.integer(static_cast<int64_t>(nodes_.size()));
  w.integer(static_cast<int64_t>(closures_.size()));
  w.integer(first_active_);
  w.integer(pcm_horizon_start_);
  w.integer(update_utime_us_);
  w.integer(frozen_newest_accepted_utime_us_);
  w.integer(newest_accepted_closure_utime_us_);
  w.endLine();
  for (const Node& n : nodes_) {
    w.word("node");
    w.integer(n.id);
    w.integer(n.utime_us);
    w.real(n.distance_m);
    w.pose(n.dr);
    w.pose(n.estimate);
    w.integer(n.has_covariance ? 1 : 0);
    w.matrix(n.covariance);
    w.matrix(n.conditional_covariance);
    w.endLine();
  }
  for (const Closure& c : closures_) {
    const LoopClosure& l = c.record.closure;
    w.word("closure");
    w.integer(l.subframe_id_a);
    w.integer(l.subframe_id_b);
    w.integer(l.association_round);
    w.integer(l.num_inliers);
    w.real(l.total_cost);
    w.pose(l.T_a_b);
    w.matrix(l.covariance);
    w.integer(static_cast<int>(c.record.status));
    w.integer(static_cast<int>(c.record.rejection));
    w.integer(c.record.marginalised ? 1 : 0);
    w.integer(c.gate_checked ? 1 : 0);
    w.endLine();
  }
  w.word("prior");
  w.integer(static_cast<int64_t>(prior_.nodes.size()));
  w.integer(static_cast<int64_t>(prior_.residual.size()));
  for (int n : prior_.nodes) w.integer(n);
  for (const Pose& p : prior_.linearisation) w.pose(p);
  w.matrix(prior_.jacobian);
  w.matrix(prior_.residual);
  w.endLine();
  const PoseGraphCounters& k = counters_;
  w.word("counters");
  for (uint64_t v : {k.nodes_added, k.nodes_refused, k.nodes_marginalised, k.closures_received, k.closures_refused,
                     k.closures_pending, k.closures_accepted, k.closures_rejected_gate,
                     k.closures_rejected_inconsistent, k.closures_rejected_no_support, k.closures_superseded,
                     k.closures_withdrawn_after_marginalisation, k.updates, k.full_smoothings, k.solver_failures})
    w.unsignedInteger(v);
  w.real(k.last_update_s);
  w.real(k.last_solve_s);
  w.integer(k.last_iterations);
  w.endLine();
  const VarianceFactors& v = variance_factors_;
  w.word("weights");
  w.real(v.closure);
  w.real(v.odometry);
  w.real(v.closure_redundancy);
  w.real(v.odometry_redundancy);
  w.real(v.odometry_strain);
  w.integer(v.closures);
  w.integer(v.iterations);
  w.endLine();
  const SeparationBias& b = separation_bias_;
  w.word("separation_bias");
  w.real(b.estimate_m);
  w.real(b.tested_m);
  w.real(b.sigma_m);
  w.integer(b.significant ? 1 : 0);
  w.integer(b.applied ? 1 : 0);
  w.integer(b.closures);
  w.endLine();
  w.word("fixes");
  w.integer(static_cast<int64_t>(fixes_.size()));
  w.integer(newest_accepted_fix_utime_us_);
  for (uint64_t v : {fix_counters_.received, fix_counters_.refused, fix_counters_.accepted, fix_counters_.rejected_gate})
    w.unsignedInteger(v);
  w.endLine();
  for (const Fix& f : fixes_) {
    const AbsoluteFix& x = f.record.fix;
    w.word("fix");
    w.integer(x.utime_us);
    w.word(x.source == "usbl" ? "usbl" : "gnss");
    w.matrix(x.position_ne_m);
    w.matrix(x.covariance_m2);
    w.matrix(x.dr_position_m);
    w.real(x.dr_distance_m);
    w.integer(static_cast<int>(f.record.status));
    w.integer(f.node);
    w.real(f.record.innovation_chi2);
    w.endLine();
  }
  const DrCalibration& c = calibration_;
  w.word("calibration");
  w.integer(c.estimated ? 1 : 0);
  for (double v : {c.dvl_scale, c.heading_bias_rad, c.heading_cos_rad, c.heading_sin_rad}) w.real(v);
  for (int i = 0; i < 4; ++i) w.real(c.sigma(i));
  w.integer(calibration_utime_us_);
  w.integer(c.scale_estimated ? 1 : 0);
  w.endLine();
  w.word("anchor");
  w.real(first_node_ins_sigma_ne_m_(0));
  w.real(first_node_ins_sigma_ne_m_(1));
  w.endLine();
  const WindowStats& s = window_stats_;
  w.word("window");
  for (int v : {s.active_nodes, s.variable_blocks, s.constant_blocks, s.residual_blocks, s.prior_nodes, s.prior_rows,
                s.pcm_candidates})
    w.integer(v);
  w.endLine();
  return std::move(w.text());
}

Status SlidingWindowPoseGraph::saveCheckpoint(const std::string& path) const {
  std::string text = checkpointText();
  checkpoint::appendChecksum(text);
  const Status written = sss::core::writeFileAtomically(path, text);
  if (!written) return Status::error("checkpoint " + written.message);
  return Status::success();
}

Status SlidingWindowPoseGraph::loadCheckpoint(const std::string& path) {
  const sss::core::Result<std::string> read = checkpoint::readChecked(path, kMaxFileBytes);
  if (!read) return Status::error("checkpoint " + path + ": " + read.message() + "; graph left unchanged");
  const Status restored = restoreCheckpointText(read.value());
  if (!restored.ok) return Status::error("checkpoint " + path + ": " + restored.message + "; graph left unchanged");
  return restored;
}

Status SlidingWindowPoseGraph::restoreCheckpointText(const std::string& text) {
  auto fail = [](const std::string& why) { return Status::error(why); };
  TextReader r(text);
  int64_t version = 0;
  if (!r.expect(kMagic)) return fail("not a pose-graph checkpoint");
  if (!r.integer(version)) return fail("bad version field");
  if (version < 1 || version > kVersion)
    return fail("version " + std::to_string(version) + " not supported (expected 1 to " + std::to_string(kVersion) +
                ")");

  SlidingWindowPoseGraph g(options_);
  int64_t num_nodes = 0, num_closures = 0, first_active = 0, horizon = 0;
  if (!r.expect("state") || !r.integer(num_nodes) || !r.integer(num_closures) || !r.integer(first_active) ||
      !r.integer(horizon) || !r.integer(g.update_utime_us_) || !r.integer(g.frozen_newest_accepted_utime_us_) ||
      !r.integer(g.newest_accepted_closure_utime_us_))
    return fail("bad state record");
  if (num_nodes < 0 || static_cast<uint64_t>(num_nodes) > r.remainingRecords(90) || num_closures < 0 ||
      static_cast<uint64_t>(num_closures) > r.remainingRecords(50) || first_active < 0 || first_active > num_nodes ||
      horizon < 0 || horizon > num_closures)
    return fail("inconsistent counts in the state record");
  g.first_active_ = static_cast<int>(first_active);
  g.pcm_horizon_start_ = static_cast<int>(horizon);

  g.nodes_.reserve(static_cast<size_t>(num_nodes));
  for (int64_t i = 0; i < num_nodes; ++i) {
    Node n;
    int has_covariance = 0;
    if (!r.expect("node") || !r.integer(n.id) || !r.integer(n.utime_us) || !r.finite(n.distance_m) || !r.pose(n.dr) ||
        !r.pose(n.estimate) || !r.boundedInt(has_covariance, 0, 1) || !r.matrix6(n.covariance) ||
        !r.matrix6(n.conditional_covariance))
      return fail("bad node record " + std::to_string(i));
    n.has_covariance = has_covariance == 1;
    if (g.index_of_.count(n.id)) return fail("duplicate node id " + std::to_string(n.id));
    if (!g.nodes_.empty() && (n.utime_us <= g.nodes_.back().utime_us || n.distance_m < g.nodes_.back().distance_m - 1e-6))
      return fail("node " + std::to_string(n.id) + " is out of time or distance order");
    g.setupDerived(n, g.nodes_.empty() ? nullptr : &g.nodes_.back());
    g.index_of_[n.id] = static_cast<int>(g.nodes_.size());
    g.nodes_.push_back(std::move(n));
  }
  g.closures_.reserve(static_cast<size_t>(num_closures));
  for (int64_t i = 0; i < num_closures; ++i) {
    Closure c;
    LoopClosure& l = c.record.closure;
    int status = 0, rejection = 0, marginalised = 0, gate_checked = 0;
    if (!r.expect("closure") || !r.integer(l.subframe_id_a) || !r.integer(l.subframe_id_b) ||
        !r.boundedInt(l.association_round, std::numeric_limits<int>::min(), std::numeric_limits<int>::max()) ||
        !r.boundedInt(l.num_inliers, std::numeric_limits<int>::min(), std::numeric_limits<int>::max()) ||
        !r.real(l.total_cost) || !r.pose(l.T_a_b) || !r.matrix6(l.covariance) || !r.boundedInt(status, 0, 3) ||
        !r.boundedInt(rejection, 0, 3) || !r.boundedInt(marginalised, 0, 1) || !r.boundedInt(gate_checked, 0, 1))
      return fail("bad closure record " + std::to_string(i));
    const auto a = g.index_of_.find(l.subframe_id_a), b = g.index_of_.find(l.subframe_id_b);
    if (a == g.index_of_.end() || b == g.index_of_.end() || a->second == b->second)
      return fail("closure record " + std::to_string(i) + " refers to unknown nodes");
    if (!sqrtInformation(l.covariance, c.sqrt_information))
      return fail("closure record " + std::to_string(i) + " has a covariance that is not positive definite");
    c.a = a->second;
    c.b = b->second;
    c.record.status = static_cast<ClosureStatus>(status);
    c.record.rejection = static_cast<ClosureRejection>(rejection);
    c.record.marginalised = marginalised == 1;
    c.gate_checked = gate_checked == 1;
    const int index = static_cast<int>(g.closures_.size());
    g.latest_for_pair_[std::minmax(l.subframe_id_a, l.subframe_id_b)] = index;
    g.nodes_[c.a].closures.push_back(index);
    g.nodes_[c.b].closures.push_back(index);
    g.closures_.push_back(std::move(c));
  }
  int64_t prior_nodes = 0, prior_rows = 0;
  if (!r.expect("prior") || !r.integer(prior_nodes) || !r.integer(prior_rows)) return fail("bad prior record");
  if (prior_nodes < 0 || prior_nodes > num_nodes - first_active || prior_rows < 0 || prior_rows > 6 * prior_nodes ||
      (prior_nodes > 0 && prior_rows == 0) ||
      static_cast<uint64_t>(prior_rows) * static_cast<uint64_t>(6 * prior_nodes + 1) > r.remainingRecords(1))
    return fail("inconsistent prior size");
  for (int64_t i = 0; i < prior_nodes; ++i) {
    int node = 0;
    if (!r.boundedInt(node, first_active, num_nodes - 1) || (!g.prior_.nodes.empty() && node <= g.prior_.nodes.back()))
      return fail("bad prior node list");
    g.prior_.nodes.push_back(node);
  }
  for (int64_t i = 0; i < prior_nodes; ++i) {
    Pose p;
    if (!r.pose(p)) return fail("bad prior linearisation point");
    g.prior_.linearisation.push_back(p);
  }
  Eigen::MatrixXd residual;
  if (!r.matrix(g.prior_.jacobian, static_cast<int>(prior_rows), static_cast<int>(6 * prior_nodes)) ||
      !r.matrix(residual, static_cast<int>(prior_rows), 1))
    return fail("bad prior matrices");
  g.prior_.residual = residual.col(0);
  if (prior_nodes == 0) g.prior_ = Prior();

  PoseGraphCounters& k = g.counters_;
  if (!r.expect("counters")) return fail("bad counters record");
  for (uint64_t* v : {&k.nodes_added, &k.nodes_refused, &k.nodes_marginalised, &k.closures_received,
                      &k.closures_refused, &k.closures_pending, &k.closures_accepted, &k.closures_rejected_gate,
                      &k.closures_rejected_inconsistent, &k.closures_rejected_no_support, &k.closures_superseded,
                      &k.closures_withdrawn_after_marginalisation, &k.updates, &k.full_smoothings, &k.solver_failures})
    if (!r.unsignedInteger(*v)) return fail("bad counters record");
  if (!r.real(k.last_update_s) || !r.real(k.last_solve_s) ||
      !r.boundedInt(k.last_iterations, -1, std::numeric_limits<int>::max()))
    return fail("bad counters record");
  if (version >= 2) {
    VarianceFactors& v = g.variance_factors_;
    if (!r.expect("weights") || !r.real(v.closure) || !r.real(v.odometry) || !r.real(v.closure_redundancy) ||
        !r.real(v.odometry_redundancy) || !r.real(v.odometry_strain) || !r.boundedInt(v.closures, 0, std::numeric_limits<int>::max()) ||
        !r.boundedInt(v.iterations, 0, std::numeric_limits<int>::max()))
      return fail("bad weights record");
    if (!(v.closure > 0.0) || !(v.odometry > 0.0) || !std::isfinite(v.closure) || !std::isfinite(v.odometry))
      return fail("weights record: variance factors must be finite and > 0");
  }
  if (version >= 3) {
    SeparationBias& b = g.separation_bias_;
    int significant = 0, applied = 0;
    if (!r.expect("separation_bias") || !r.real(b.estimate_m) || !r.real(b.tested_m) || !r.real(b.sigma_m) ||
        !r.boundedInt(significant, 0, 1) || !r.boundedInt(applied, 0, 1) ||
        !r.boundedInt(b.closures, 0, std::numeric_limits<int>::max()))
      return fail("bad separation_bias record");
    b.significant = significant == 1;
    if (!std::isfinite(b.estimate_m) || !std::isfinite(b.tested_m))
      return fail("separation_bias record: the bias must be finite");
    b.applied = applied == 1;
  }
  if (version >= 4) {
    int64_t num_fixes = 0;
    FixCounters& k4 = g.fix_counters_;
    if (!r.expect("fixes") || !r.integer(num_fixes) || !r.integer(g.newest_accepted_fix_utime_us_) ||
        !r.unsignedInteger(k4.received) || !r.unsignedInteger(k4.refused) || !r.unsignedInteger(k4.accepted) ||
        !r.unsignedInteger(k4.rejected_gate) || num_fixes < 0 ||
        static_cast<uint64_t>(num_fixes) > r.remainingRecords(20))
      return fail("bad fixes record");
    for (int64_t i = 0; i < num_fixes; ++i) {
      Fix f;
      AbsoluteFix& x = f.record.fix;
      std::string source;
      Eigen::MatrixXd position, covariance, dr_position;
      int status = 0, node = -1;
      if (!r.expect("fix") || !r.integer(x.utime_us) || !r.token(source) || !r.matrix(position, 2, 1) ||
          !r.matrix(covariance, 2, 2) || !r.matrix(dr_position, 3, 1) || !r.finite(x.dr_distance_m) ||
          !r.boundedInt(status, 0, 2) || !r.boundedInt(node, -1, num_nodes - 1) || !r.real(f.record.innovation_chi2))
        return fail("bad fix record " + std::to_string(i));
      if (source != "gnss" && source != "usbl") return fail("fix record " + std::to_string(i) + ": unknown source");
      x.source = source;
      x.position_ne_m = position.col(0);
      x.covariance_m2 = covariance;
      x.dr_position_m = dr_position.col(0);
      f.record.status = static_cast<FixStatus>(status);
      const Eigen::LLT<Eigen::Matrix2d> llt(x.covariance_m2);
      if (!x.position_ne_m.allFinite() || !x.dr_position_m.allFinite() || llt.info() != Eigen::Success)
        return fail("fix record " + std::to_string(i) + " is not finite or its covariance not positive definite");
      // Not stored: the same function of the fixes before it as when it arrived.
      f.record.information_weight = g.fixInformationWeight(x);
      if (node >= 0) {
        if (!g.tieFix(f, node)) return fail("fix record " + std::to_string(i) + " cannot be tied to its node");
        g.nodes_[node].fixes.push_back(static_cast<int>(g.fixes_.size()));
      }
      g.fixes_.push_back(std::move(f));
    }
  }
  if (version >= 5) {
    DrCalibration& c = g.calibration_;
    int estimated = 0;
    if (!r.expect("calibration") || !r.boundedInt(estimated, 0, 1) || !r.finite(c.dvl_scale) ||
        !r.finite(c.heading_bias_rad) || !r.finite(c.heading_cos_rad) || !r.finite(c.heading_sin_rad) ||
        !r.real(c.sigma(0)) || !r.real(c.sigma(1)) || !r.real(c.sigma(2)) || !r.real(c.sigma(3)))
      return fail("bad calibration record");
    if (!(c.dvl_scale > -0.5)) return fail("calibration record: the DVL scale must be > -0.5");
    int scale_estimated = estimated;
    if (version >= 6 && (!r.integer(g.calibration_utime_us_) || !r.boundedInt(scale_estimated, 0, 1)))
      return fail("bad calibration record (time, scale)");
    c.estimated = estimated == 1;
    c.scale_estimated = scale_estimated == 1;
  }
  if (version >= 7) {
    Eigen::Vector2d& sigma = g.first_node_ins_sigma_ne_m_;
    if (!r.expect("anchor") || !r.finite(sigma(0)) || !r.finite(sigma(1)) || sigma(0) < 0.0 || sigma(1) < 0.0)
      return fail("bad anchor record");
  }
  WindowStats& s = g.window_stats_;
  if (!r.expect("window")) return fail("bad window record");
  for (int* v : {&s.active_nodes, &s.variable_blocks, &s.constant_blocks, &s.residual_blocks, &s.prior_nodes,
                 &s.prior_rows, &s.pcm_candidates})
    if (!r.boundedInt(*v, 0, std::numeric_limits<int>::max())) return fail("bad window record");
  std::string extra;
  if (r.token(extra)) return fail("unexpected data after the window record");

  *this = std::move(g);
  return Status::success();
}

}  // namespace sss::optimiser
