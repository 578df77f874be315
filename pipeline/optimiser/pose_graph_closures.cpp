// Closure decisions of the sliding-window pose graph: chi-square gate against the current
// estimate, pairwise consistency on DR cycles and the consistent set with the most independent
// closures (consistent_set.hpp).
#include "pipeline/optimiser/pose_graph.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "pipeline/optimiser/consistent_set.hpp"
#include "pipeline/optimiser/pose_graph_internal.hpp"
#include "pipeline/optimiser/pose_manifold.hpp"

namespace sss::optimiser {

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
  for (int p = 0; p < n; ++p) {
    for (int q = p + 1; q < n; ++q) {
      const std::pair<int, int> key(candidates[p], candidates[q]);
      auto it = pcm_cache_.find(key);
      if (it == pcm_cache_.end())
        it = pcm_cache_.emplace(key, pairConsistent(closures_[key.first], closures_[key.second])).first;
      consistent[p][q] = consistent[q][p] = it->second ? 1 : 0;
    }
  }
  std::vector<char> accepted(n, 0);
  for (int p = 0; p < n; ++p) accepted[p] = closures_[candidates[p]].record.status == ClosureStatus::kAccepted ? 1 : 0;
  std::vector<int> best;
  int support = 0;  // the evidence behind the best set: its closures, or those sharing no subframe
  if (options_.pcm_count_independent_subframes) {
    std::vector<std::pair<int, int>> subframes_of(n);
    for (int p = 0; p < n; ++p) subframes_of[p] = {closures_[candidates[p]].a, closures_[candidates[p]].b};
    best = mostIndependentConsistentSet(consistent, accepted, subframes_of);
    support = independentClosures(best, subframes_of);
  } else {
    best = largestConsistentSet(consistent, accepted);
    support = static_cast<int>(best.size());
  }
  const bool enough = support >= options_.min_consistent_closures;
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

}  // namespace sss::optimiser
