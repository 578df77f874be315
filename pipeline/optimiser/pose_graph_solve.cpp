// Solving the sliding-window pose graph: window updates, full smoothing with calibration and
// variance components, marginalisation of the oldest node, covariances.
#include "pipeline/optimiser/pose_graph.hpp"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "pipeline/optimiser/pose_graph_internal.hpp"
#include "pipeline/optimiser/pose_manifold.hpp"
#include "pipeline/optimiser/variance_components.hpp"

namespace sss::optimiser {

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

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

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

bool SlidingWindowPoseGraph::separationWidened() const {
  // Only a shortening (tested_m > 0) is what feature faces seen from opposite sides do to closures;
  // closures that put the lines farther apart than DR point at DR (e.g. its scale on the turns).
  const bool wanted = options_.separation_bias_widen ||
                      (options_.separation_bias_widen_with_fixes && fix_counters_.accepted > 0 && scaleWanted());
  return wanted && separation_bias_.significant && !separation_bias_.applied &&
         separation_bias_.tested_m > 0.0 && std::isfinite(separation_bias_.sigma_m);
}

Matrix6d SlidingWindowPoseGraph::odometrySqrtInformation(int k, bool calibrated) const {
  const Node& node = nodes_[k];
  if (!calibrated || k == 0) return node.odometry_sqrt_information / std::sqrt(variance_factors_.odometry);
  Matrix6d sqrt_information;
  // The heading error is a variable of this solve; the scale only when something observes it. (The
  // estimate's scale_estimated flag still holds the previous solve's answer here.)
  const double along = scaleWanted() ? options_.calibrated_odometry_drift_fraction : options_.odometry_drift_fraction;
  sqrtInformation(odometryCovariance(options_, node.distance_m - nodes_[k - 1].distance_m, along,
                                     options_.calibrated_odometry_drift_fraction),
                  sqrt_information);
  return sqrt_information / std::sqrt(variance_factors_.odometry);
}

CalibratedOdometryError SlidingWindowPoseGraph::calibratedOdometry(int k, bool estimated) const {
  const Node& node = nodes_[k];
  CalibratedOdometryError error;
  error.measured = node.odometry;
  error.sqrt_information = odometrySqrtInformation(k, estimated);
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
  if (options_.calibration == "never") return false;
  return options_.calibration == "always" || options_.calibration == "heading" || fix_counters_.accepted > 0;
}

bool SlidingWindowPoseGraph::scaleWanted() const {
  return options_.calibration == "always" || (options_.calibration != "never" && fix_counters_.accepted > 0);
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
              ? CalibratedOdometryError::createEstimated(calibratedOdometry(f.index, true))
          : f.kind == FactorKind::kInsAbsolute
              ? CalibratedInsAbsoluteError::createEstimated(node.dr, insAbsoluteWeights(options_), dr_heading_rad)
              : CalibratedPosePriorError::create(node.dr, firstNodeSqrtInformation(options_, firstNodeHorizontalSigma()), dr_heading_rad);
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
    // Without fixes the scale is held at 0 by a prior a million times tighter than any data: closures
    // of parallel lines see it mostly through the turns' length, where it cannot be told from the
    // matcher's separation bias. (Not a SubsetManifold: Ceres' covariance in the tangent space of
    // one frees memory that another Eigen build allocated, under AddressSanitizer.)
    const double scale_sigma = scaleWanted() ? options_.calibration_scale_sigma : 1e-6 * options_.calibration_scale_sigma;
    const double sigmas[kCalibrationSize] = {scale_sigma, options_.calibration_heading_bias_sigma_rad,
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
    calibration_.scale_estimated = scaleWanted();
    if (!calibration_.scale_estimated) {  // held at 0 by its prior (to ~1e-14): say so exactly
      calibration_.dvl_scale = 0.0;
      calibration_.sigma(0) = std::numeric_limits<double>::quiet_NaN();
    }
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

std::vector<double> SlidingWindowPoseGraph::closureLeaveOneOutChi2(const std::vector<Factor>& factors) const {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> chi2(factors.size(), nan);
  const int n = static_cast<int>(nodes_.size()) - first_active_;
  if (n <= 0) return chi2;
  // The normal matrix of the whole problem, sparse (odometry chain plus closures), with each factor
  // as the solve weighs it (robust weights included).
  std::vector<LinearisedFactor> linearised(factors.size());
  std::vector<char> usable(factors.size(), 0);
  std::vector<Eigen::Triplet<double>> triplets;
  for (size_t i = 0; i < factors.size(); ++i) {
    LinearisedFactor& lf = linearised[i];
    if (!linearise(factors[i], lf)) continue;
    usable[i] = 1;
    for (size_t p = 0; p < lf.nodes.size(); ++p) {
      for (size_t q = 0; q < lf.nodes.size(); ++q) {
        const Matrix6d block = lf.jacobian.middleCols<6>(6 * static_cast<int>(p)).transpose() *
                               lf.jacobian.middleCols<6>(6 * static_cast<int>(q));
        const int row = 6 * (lf.nodes[p] - first_active_), col = 6 * (lf.nodes[q] - first_active_);
        for (int r = 0; r < 6; ++r)
          for (int c = 0; c < 6; ++c) triplets.emplace_back(row + r, col + c, block(r, c));
      }
    }
  }
  Eigen::SparseMatrix<double> normal(6 * n, 6 * n);
  normal.setFromTriplets(triplets.begin(), triplets.end());  // duplicates are summed
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(normal);
  if (ldlt.info() != Eigen::Success) return chi2;

  for (size_t i = 0; i < factors.size(); ++i) {
    const LinearisedFactor& lf = linearised[i];
    if (factors[i].kind != FactorKind::kClosure || !usable[i] || lf.nodes.size() != 2 || lf.robust_weight <= 0.0)
      continue;
    // K: the 12 x 12 covariance of the closure's two nodes under every factor.
    Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(6 * n, 12);
    for (int k = 0; k < 2; ++k)
      unit.block<6, 6>(6 * (lf.nodes[k] - first_active_), 6 * k).setIdentity();
    const Eigen::MatrixXd columns = ldlt.solve(unit);
    if (ldlt.info() != Eigen::Success) continue;
    Eigen::Matrix<double, 12, 12> k_ab;
    for (int k = 0; k < 2; ++k) k_ab.middleRows<6>(6 * k) = columns.middleRows<6>(6 * (lf.nodes[k] - first_active_));
    // Without the closure (Woodbury on its own rows, U = the weighted jacobian):
    // K_out = K + K U' (I - U K U')^-1 U K.
    const double w = lf.robust_weight;
    const Eigen::Matrix<double, 6, 12> u = lf.jacobian;  // weighted: w x the whitened jacobian
    const Matrix6d s_in = Matrix6d::Identity() - u * k_ab * u.transpose();
    const Eigen::LDLT<Matrix6d> s_in_ldlt(0.5 * (s_in + s_in.transpose()));
    if (s_in_ldlt.info() != Eigen::Success || s_in_ldlt.rcond() < 1e-12) continue;  // the closure alone holds them
    const Eigen::Matrix<double, 12, 12> k_out = k_ab + k_ab * u.transpose() * s_in_ldlt.solve(u * k_ab);
    // The unweighted whitened residual and jacobian; the solution without the closure moves its two
    // nodes by K_out A' w^2 r (linearised), so its innovation is r + A K_out A' w^2 r.
    const Eigen::Matrix<double, 6, 12> a = u / w;
    const Vector6d r = lf.residual / w;
    const Matrix6d g = a * k_out * a.transpose();
    const Vector6d innovation = r + w * w * g * r;
    const Matrix6d s_out = Matrix6d::Identity() + g;
    const Eigen::LDLT<Matrix6d> s_out_ldlt(0.5 * (s_out + s_out.transpose()));
    if (s_out_ldlt.info() != Eigen::Success) continue;
    chi2[i] = innovation.dot(s_out_ldlt.solve(innovation));
  }
  return chi2;
}

bool SlidingWindowPoseGraph::rejectClosuresTheSurveyDoesNotHold(std::vector<Factor>& factors, UpdateReport& report,
                                                               bool estimate_calibration) {
  if (options_.smoothed_gate_chi2 <= 0.0) return true;
  // One at a time, the worst first: an outlier pulls its neighbours' residuals up with it.
  for (;;) {
    int worst = -1;
    double worst_chi2 = options_.smoothed_gate_chi2;
    const std::vector<double> chi2 = closureLeaveOneOutChi2(factors);
    for (size_t i = 0; i < factors.size(); ++i) {
      if (std::isfinite(chi2[i]) && chi2[i] > worst_chi2) {
        worst_chi2 = chi2[i];
        worst = factors[i].index;
      }
    }
    if (worst < 0) return true;
    Closure& c = closures_[worst];
    c.record.marginalised = false;  // full smoothing re-derives the prior without it: nothing withdrawn
    setStatus(c, ClosureStatus::kRejected, ClosureRejection::kChiSquareGate);
    ++report.closures_decided;
    factors = allFactors();
    UpdateReport again;
    if (!solve(factors, options_.full_smoothing_max_iterations, again, false, estimate_calibration)) return false;
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

void SlidingWindowPoseGraph::marginaliseBeyondWindow() {
  while (static_cast<int>(nodes_.size()) - first_active_ > options_.window_size) {
    marginaliseOldest();
    ++counters_.nodes_marginalised;
  }
}

bool SlidingWindowPoseGraph::calibrationDue() const {
  if (options_.calibration_period_s <= 0.0 || nodes_.empty() || !calibrationWanted()) return false;
  if (calibration_utime_us_ < 0) return true;
  return 1e-6 * static_cast<double>(nodes_.back().utime_us - calibration_utime_us_) >= options_.calibration_period_s;
}

UpdateReport SlidingWindowPoseGraph::optimize() {
  const Clock::time_point start = Clock::now();
  UpdateReport report;
  if (nodes_.empty()) return report;
  if (calibrationDue()) {
    // The calibration changes every odometry edge, old and new: only a full smoothing can move it.
    report = smoothAll(false);
    marginaliseBeyondWindow();
    refreshCovariances();
    report.update_s = secondsSince(start);
    return report;
  }
  decideClosures(report);
  decideFixes(false);
  const std::vector<Factor> factors = windowFactors();
  refreshWindowStats(factors);
  solve(factors, options_.max_iterations, report);
  // Marginalise at the solution even after a failed solve: the window must stay bounded.
  marginaliseBeyondWindow();
  refreshCovariances();
  update_utime_us_ = nodes_.back().utime_us;
  report.update_s = secondsSince(start);
  ++counters_.updates;
  counters_.last_update_s = report.update_s;
  counters_.last_solve_s = report.solve_s;
  counters_.last_iterations = report.iterations;
  return report;
}

UpdateReport SlidingWindowPoseGraph::smoothAll(bool mission_ended) {
  const Clock::time_point start = Clock::now();
  UpdateReport report;
  if (nodes_.empty()) return report;
  decideClosures(report);
  decideFixes(mission_ended);
  // Every node is a variable: solve with the window boundary at the first node.
  const int boundary = first_active_;
  first_active_ = 0;
  std::vector<Factor> factors = allFactors();
  bool ok = true;
  const bool calibrate = calibrationWanted();
  if (calibrate) calibration_utime_us_ = nodes_.back().utime_us;
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
  if (ok) ok = rejectClosuresTheSurveyDoesNotHold(factors, report, calibrate);
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

}  // namespace sss::optimiser
