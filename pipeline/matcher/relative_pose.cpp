// Relative pose of a subframe pair (paper Sec. "Subframe Pose Estimation", eqs. (1)-(4), Alg. 1):
// Ceres problem over T_a_b and one landmark per correspondence, inside a RANSAC loop.
#include "pipeline/matcher/relative_pose.hpp"

#include "pipeline/core/georeference.hpp"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <sstream>

namespace sss::matcher {
namespace {

using sss::core::Pose;
using Clock = std::chrono::steady_clock;

// One side-scan bin seen from one ping: the sonar pose in the centre body frame of its subframe.
struct BinObservation {
  Pose T_centre_sonar;
  double slant_range_m = 0.0;
  int side = 1;  // +1 starboard (+y of the sonar), -1 port
};

struct Measurement {
  BinObservation a;
  BinObservation b;
  Eigen::Vector3d landmark_init_a;  // flat-seabed geo-reference in A (frame a)
  Eigen::Vector3d down_a;           // world down in frame a
  double seabed_depth_a_m = 0.0;    // down_a . x of the seabed under A's ping (frame a)
  double range_sigma_m = 0.0;       // of both slant ranges (rangeSigmasFromPeaks)
  double peak_curvature_col = 0.0;  // of the match's ZNCC peak across range (0: not measured)
};

// Each match's slant-range sigma from the sharpness of its ZNCC peak across range: a match located
// by a sharp peak has a smaller range error than one on a flat peak (curvature k, sigma ~ 1/sqrt(k),
// the Gauss-Newton precision of a peak's position). Relative to the pair's median curvature, so the
// median match keeps range_sigma_m and the closure's overall scale (and covariance_scale) holds;
// within [min, max] of range_sigma_m so no match dominates or vanishes. Matches without a measured
// curvature keep range_sigma_m.
void rangeSigmasFromPeaks(std::vector<Measurement>& measurements, const RelativePoseOptions& options) {
  for (Measurement& m : measurements) m.range_sigma_m = options.range_sigma_m;
  if (!options.range_sigma_from_peak) return;
  std::vector<double> curvatures;
  for (const Measurement& m : measurements)
    if (m.peak_curvature_col > 0.0) curvatures.push_back(m.peak_curvature_col);
  if (curvatures.size() < 2) return;
  auto middle = curvatures.begin() + static_cast<std::ptrdiff_t>(curvatures.size() / 2);
  std::nth_element(curvatures.begin(), middle, curvatures.end());
  const double median = *middle;
  if (!(median > 0.0)) return;
  for (Measurement& m : measurements) {
    if (!(m.peak_curvature_col > 0.0)) continue;
    const double factor = std::sqrt(median / m.peak_curvature_col);
    m.range_sigma_m = options.range_sigma_m * std::clamp(factor, options.peak_sigma_min_factor, options.peak_sigma_max_factor);
  }
}

// The pose of a fractional row: slerp/lerp between the neighbouring pings.
std::optional<std::pair<Pose, double>> pingAt(const std::vector<Pose>& poses, const std::vector<double>& altitude_m,
                                              double row) {
  const int n = static_cast<int>(poses.size());
  if (!(row >= 0.0) || row > n - 1) return std::nullopt;
  const int i0 = std::min(static_cast<int>(std::floor(row)), n - 1);
  const int i1 = std::min(i0 + 1, n - 1);
  const double f = row - i0;
  return std::make_pair(sss::core::interpolate(poses[i0], poses[i1], f),
                        (1.0 - f) * altitude_m[i0] + f * altitude_m[i1]);
}

// Rotates/translates a double point of T by a Jet-typed point: R * p + t.
template <typename T>
Eigen::Matrix<T, 3, 1> inverseTransform(const Pose& pose, const Eigen::Matrix<T, 3, 1>& p) {
  const Eigen::Matrix3d Rt = pose.rotation.toRotationMatrix().transpose();
  return Rt.cast<T>() * (p - pose.translation.cast<T>());
}

// paper eq. (1): z = (|pi(x)|, (1,0,0) . pi(x)), whitened by eq. (4): sigma_r and r * alpha.
template <typename T>
void binResidual(const Eigen::Matrix<T, 3, 1>& p_sonar, double slant_range_m, double range_sigma_m,
                 double plane_sigma_m, T* residual) {
  residual[0] = (p_sonar.norm() - T(slant_range_m)) / T(range_sigma_m);
  residual[1] = p_sonar.x() / T(plane_sigma_m);
}

// A's bin: A's centre is the fixed frame, so only the landmark is a parameter.
struct BinResidualA {
  BinObservation obs;
  double range_sigma_m, plane_sigma_m;
  template <typename T>
  bool operator()(const T* landmark, T* residual) const {
    const Eigen::Matrix<T, 3, 1> x(landmark[0], landmark[1], landmark[2]);
    binResidual<T>(inverseTransform<T>(obs.T_centre_sonar, x), obs.slant_range_m, range_sigma_m, plane_sigma_m,
                   residual);
    return true;
  }
};

// B's bin: T_a_b = anchor * Exp(delta) with delta = [dt, dr] (our boxPlus), then B's ping moves
// rigidly with B's centre (paper eq. (2): T_c_b of the ping is DR and fixed).
struct BinResidualB {
  BinObservation obs;
  const Pose* anchor;
  double range_sigma_m, plane_sigma_m;
  template <typename T>
  bool operator()(const T* delta, const T* landmark, T* residual) const {
    const Eigen::Matrix<T, 3, 1> x(landmark[0], landmark[1], landmark[2]);
    Eigen::Matrix<T, 3, 1> y = inverseTransform<T>(*anchor, x);
    y -= Eigen::Matrix<T, 3, 1>(delta[0], delta[1], delta[2]);
    const T minus_dr[3] = {-delta[3], -delta[4], -delta[5]};
    Eigen::Matrix<T, 3, 1> z;
    ceres::AngleAxisRotatePoint(minus_dr, y.data(), z.data());
    binResidual<T>(inverseTransform<T>(obs.T_centre_sonar, z), obs.slant_range_m, range_sigma_m, plane_sigma_m,
                   residual);
    return true;
  }
};

// Seabed prior: the landmark lies on the seabed under A's ping (sonar depth + altitude). This is
// what makes the lateral offset between two lines observable.
struct SeabedResidual {
  Eigen::Vector3d down_a;
  double depth_m, sigma_m;
  template <typename T>
  bool operator()(const T* landmark, T* residual) const {
    residual[0] = (T(down_a.x()) * landmark[0] + T(down_a.y()) * landmark[1] + T(down_a.z()) * landmark[2] -
                   T(depth_m)) /
                  T(sigma_m);
    return true;
  }
};

// paper eq. (3), second term: boxMinus(T_a_b, T_a_b_dr) whitened with L^-1, Sigma_t = L L^T.
struct OdometryResidual {
  const Pose* anchor;
  Pose dr;
  Eigen::Matrix<double, 6, 6> sqrt_information;
  template <typename T>
  bool operator()(const T* delta, T* residual) const {
    Eigen::Matrix<T, 6, 1> e;
    // Translation: R_dr^T (t_anchor + R_anchor dt - t_dr).
    const Eigen::Matrix3d R_anchor = anchor->rotation.toRotationMatrix();
    const Eigen::Matrix<T, 3, 1> dt(delta[0], delta[1], delta[2]);
    const Eigen::Matrix<T, 3, 1> t = anchor->translation.cast<T>() + R_anchor.cast<T>() * dt;
    e.template head<3>() = inverseTransform<T>(dr, t);
    // Rotation: Log(R_dr^T R_anchor Exp(dr)).
    const Eigen::Quaterniond q_fixed = dr.rotation.conjugate() * anchor->rotation;
    const T qf[4] = {T(q_fixed.w()), T(q_fixed.x()), T(q_fixed.y()), T(q_fixed.z())};
    T q_delta[4], q[4];
    ceres::AngleAxisToQuaternion(delta + 3, q_delta);
    ceres::QuaternionProduct(qf, q_delta, q);
    if (q[0] < T(0)) {
      for (T& c : q) c = -c;
    }
    T angle_axis[3];
    ceres::QuaternionToAngleAxis(q, angle_axis);
    e(3) = angle_axis[0];
    e(4) = angle_axis[1];
    e(5) = angle_axis[2];
    Eigen::Map<Eigen::Matrix<T, 6, 1>> whitened(residual);
    whitened = sqrt_information.cast<T>() * e;
    return true;
  }
};

Pose applyDelta(const Pose& anchor, const double* delta) {
  sss::core::Vector6d d;
  for (int i = 0; i < 6; ++i) d(i) = delta[i];
  return sss::core::boxPlus(anchor, d);
}

struct Solved {
  Pose T_a_b;
  std::vector<Eigen::Vector3d> landmarks;
  double final_cost = 0.0;
  double range_cost = 0.0;  // mean squared whitened residual over A and B bins
  double plane_cost = 0.0;
  bool usable = false;
  std::optional<sss::core::Matrix6d> covariance;        // model-based: Ceres, the assumed sigmas
  std::optional<sss::core::Matrix6d> robust_covariance; // cluster-robust sandwich (from residuals)
  sss::core::Vector6d per_seabed_offset = sss::core::Vector6d::Zero();
  sss::core::Vector6d per_seabed_tilt = sss::core::Vector6d::Zero();
  sss::core::Vector6d per_range_bias = sss::core::Vector6d::Zero();  // see ClusterRobust
  int clusters = 0;
};

// Cluster-robust ("sandwich") covariance of the pose at the solution (anchor = solution, delta 0).
// Ceres' covariance, H^-1, assumes every match independent with the sigmas of the options. Dense
// matches are neither: neighbours share texture pixels and, above all, the same seabed-model error
// (relief the plane does not hold, a shadow seen from the other side), so their errors move
// together. The sandwich H^-1 M H^-1 takes the spread from the residuals themselves: M sums, per
// cluster of matches on the same patch of seabed, the outer product of the cluster's total
// gradient (landmarks eliminated). A cluster that pulls the pose one way and another that pulls
// it the other way (near range against far range over relief) make the direction they disagree
// in weak; matches that agree better than the sigmas assumed make it tighter. The DR prior is one
// more cluster with its model information. G / (G - 1): the small-sample correction (CR1).
struct ClusterRobust {
  sss::core::Matrix6d covariance = sss::core::Matrix6d::Zero();
  // How far the pose moves per metre the seabed under the matches is higher than the seabed prior
  // says, all landmarks alike (d pose / d depth offset, tangent [dt, dr]). Relief between two lines
  // moves every match the same way, so no spread between clusters shows it; see seabedReliefSigma.
  sss::core::Vector6d per_seabed_offset = sss::core::Vector6d::Zero();
  // The same per unit slope of the seabed along A's track (offset (x - mean x) per landmark).
  sss::core::Vector6d per_seabed_tilt = sss::core::Vector6d::Zero();
  // How far the pose moves per metre every matched pixel lies nearer both sonars than the landmark
  // (a common relief range bias, RelativePoseOptions::range_bias_sigma_m).
  sss::core::Vector6d per_range_bias = sss::core::Vector6d::Zero();
  int clusters = 0;
  bool ok = false;
};

ClusterRobust clusterRobustCovariance(const std::vector<Measurement>& measurements, const std::vector<int>& subset,
                                      const std::vector<Eigen::Vector3d>& landmarks, const Pose* anchor,
                                      const Pose& dr, const Eigen::Matrix<double, 6, 6>& sqrt_information,
                                      const RelativePoseOptions& options, bool robust) {
  using Matrix6d = sss::core::Matrix6d;
  using Vector6d = sss::core::Vector6d;
  ClusterRobust out;
  const double zero_delta[6] = {0, 0, 0, 0, 0, 0};
  const double cluster_m = options.covariance_cluster_m;
  std::map<std::pair<long, long>, Vector6d> gradient_by_cluster;
  Matrix6d information = Matrix6d::Zero();
  Vector6d seabed_offset_gradient = Vector6d::Zero();  // d (reduced gradient) / d (prior depth offset)
  Vector6d seabed_tilt_gradient = Vector6d::Zero();    // d (reduced gradient) / d (prior slope along x)
  Vector6d range_bias_gradient = Vector6d::Zero();     // d (reduced gradient) / d (common range bias)
  double mean_along_m = 0.0;
  for (size_t i = 0; i < subset.size(); ++i) mean_along_m += landmarks[i].x() / static_cast<double>(subset.size());
  std::unique_ptr<ceres::LossFunction> loss;
  if (robust && options.robust_loss_scale > 0.0) loss = std::make_unique<ceres::CauchyLoss>(options.robust_loss_scale);
  // sqrt(rho'(|r|^2)): the iteratively reweighted least-squares weight of a robustified block.
  auto weight = [&](const double* r, int size) {
    if (!loss) return 1.0;
    double s = 0.0;
    for (int k = 0; k < size; ++k) s += r[k] * r[k];
    double rho[3];
    loss->Evaluate(s, rho);
    return std::sqrt(std::max(rho[1], 0.0));
  };
  for (size_t i = 0; i < subset.size(); ++i) {
    const Measurement& m = measurements[subset[i]];
    // Rows: A's range and plane, B's range and plane, the seabed prior.
    Eigen::Matrix<double, 5, 1> r = Eigen::Matrix<double, 5, 1>::Zero();
    Eigen::Matrix<double, 5, 6> J_pose = Eigen::Matrix<double, 5, 6>::Zero();
    Eigen::Matrix<double, 5, 3> J_landmark = Eigen::Matrix<double, 5, 3>::Zero();
    // d r / d bias: both range rows are (|p| - (range + bias)) / sigma, times their robust weight.
    Eigen::Matrix<double, 5, 1> J_bias = Eigen::Matrix<double, 5, 1>::Zero();
    const double* x = landmarks[i].data();
    {
      ceres::AutoDiffCostFunction<BinResidualA, 2, 3> cost(
          new BinResidualA{m.a, m.range_sigma_m, m.a.slant_range_m * options.beam_width_rad});
      Eigen::Matrix<double, 2, 3, Eigen::RowMajor> J_l;
      double* jacobians[1] = {J_l.data()};
      const double* parameters[1] = {x};
      if (!cost.Evaluate(parameters, r.data(), jacobians)) return out;
      const double w = weight(r.data(), 2);
      r.segment<2>(0) *= w;
      J_landmark.block<2, 3>(0, 0) = w * J_l;
      J_bias(0) = -w / m.range_sigma_m;
    }
    {
      ceres::AutoDiffCostFunction<BinResidualB, 2, 6, 3> cost(
          new BinResidualB{m.b, anchor, m.range_sigma_m, m.b.slant_range_m * options.beam_width_rad});
      Eigen::Matrix<double, 2, 6, Eigen::RowMajor> J_p;
      Eigen::Matrix<double, 2, 3, Eigen::RowMajor> J_l;
      double* jacobians[2] = {J_p.data(), J_l.data()};
      const double* parameters[2] = {zero_delta, x};
      if (!cost.Evaluate(parameters, r.data() + 2, jacobians)) return out;
      const double w = weight(r.data() + 2, 2);
      r.segment<2>(2) *= w;
      J_pose.block<2, 6>(2, 0) = w * J_p;
      J_landmark.block<2, 3>(2, 0) = w * J_l;
      J_bias(2) = -w / m.range_sigma_m;
    }
    if (options.use_seabed_prior) {
      const SeabedResidual seabed{m.down_a, m.seabed_depth_a_m, options.seabed_sigma_m};
      seabed(x, r.data() + 4);
      J_landmark.row(4) = m.down_a.transpose() / options.seabed_sigma_m;
    }
    // Eliminate the landmark (its own Schur complement): the pose information and gradient this
    // match carries once its landmark is free to move.
    const Eigen::Matrix3d A_ll = J_landmark.transpose() * J_landmark;
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(A_ll);
    if (ldlt.info() != Eigen::Success || !(A_ll.determinant() > 0.0)) return out;
    const Eigen::Matrix<double, 6, 3> A_pl = J_pose.transpose() * J_landmark;
    information += J_pose.transpose() * J_pose - A_pl * ldlt.solve(A_pl.transpose());
    const Vector6d gradient = J_pose.transpose() * r - A_pl * ldlt.solve(J_landmark.transpose() * r);
    range_bias_gradient += J_pose.transpose() * J_bias - A_pl * ldlt.solve(J_landmark.transpose() * J_bias);
    // The seabed row is (down . x - depth - offset) / sigma and does not involve the pose.
    if (options.use_seabed_prior) {
      const Vector6d per_offset = A_pl * ldlt.solve(m.down_a) / (options.seabed_sigma_m * options.seabed_sigma_m);
      seabed_offset_gradient += per_offset;
      seabed_tilt_gradient += (landmarks[i].x() - mean_along_m) * per_offset;
    }
    // Without clusters (cluster_m 0: only the seabed sensitivity is wanted) every match is one cell.
    const std::pair<long, long> cell =
        cluster_m > 0.0 ? std::pair<long, long>{static_cast<long>(std::floor(landmarks[i].x() / cluster_m)),
                                                static_cast<long>(std::floor(landmarks[i].y() / cluster_m))}
                        : std::pair<long, long>{0, 0};
    auto [it, inserted] = gradient_by_cluster.try_emplace(cell, Vector6d::Zero());
    it->second += gradient;
  }
  // The DR prior: its information, as a cluster of its own whose covariance is known.
  Matrix6d prior_information;
  {
    ceres::AutoDiffCostFunction<OdometryResidual, 6, 6> cost(new OdometryResidual{anchor, dr, sqrt_information});
    Eigen::Matrix<double, 6, 1> r;
    Eigen::Matrix<double, 6, 6, Eigen::RowMajor> J;
    double* jacobians[1] = {J.data()};
    const double* parameters[1] = {zero_delta};
    if (!cost.Evaluate(parameters, r.data(), jacobians)) return out;
    prior_information = J.transpose() * J;
  }
  information += prior_information;
  const Eigen::LLT<Matrix6d> bread(information);
  if (bread.info() != Eigen::Success) return out;
  out.per_seabed_offset = -bread.solve(seabed_offset_gradient);
  out.per_seabed_tilt = -bread.solve(seabed_tilt_gradient);
  out.per_range_bias = -bread.solve(range_bias_gradient);
  out.clusters = static_cast<int>(gradient_by_cluster.size());
  if (out.clusters < 2) return out;
  Matrix6d meat = Matrix6d::Zero();
  for (const auto& entry : gradient_by_cluster) meat += entry.second * entry.second.transpose();
  meat *= static_cast<double>(out.clusters) / (out.clusters - 1);
  meat += prior_information;
  // In the coordinates where the model covariance H^-1 is the identity, the sandwich is the meat
  // itself: its eigenvalues are how much wider (or narrower) than the model each direction is.
  // A few clusters estimate the mean inflation well but not every direction: G cluster gradients
  // span at most G - 1 directions, so some come out far too small (a known small-sample bias of
  // the sandwich). No direction is taken narrower than the mean inflation.
  const Matrix6d L_inverse = bread.matrixL().solve(Matrix6d::Identity());
  Matrix6d meat_whitened = L_inverse * meat * L_inverse.transpose();
  meat_whitened = 0.5 * (meat_whitened + meat_whitened.transpose());
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(meat_whitened);
  if (eigen.info() != Eigen::Success) return out;
  const double mean_inflation = eigen.eigenvalues().mean();
  const Vector6d inflation = eigen.eigenvalues().cwiseMax(mean_inflation);
  const Matrix6d whitened_covariance = eigen.eigenvectors() * inflation.asDiagonal() * eigen.eigenvectors().transpose();
  out.covariance = L_inverse.transpose() * whitened_covariance * L_inverse;
  out.covariance = 0.5 * (out.covariance + out.covariance.transpose());
  out.ok = out.covariance.allFinite();
  return out;
}

// Builds and solves eq. (3) over the given measurements; optionally the pose covariance, taken
// after re-anchoring at the solution so that delta = 0 is exactly our [dt, dr] tangent there.
// `robust`: the Cauchy loss on the bin residuals (the final refinement; a RANSAC hypothesis is
// six matches started from DR, metres from the truth, where a robust loss would stall).
Solved solve(const std::vector<Measurement>& measurements, const std::vector<int>& subset, const Pose& initial,
             const Pose& dr, const Eigen::Matrix<double, 6, 6>& sqrt_information, const RelativePoseOptions& options,
             int max_iterations, double max_seconds, bool with_covariance, bool robust) {
  Pose anchor = initial;
  double delta[6] = {0, 0, 0, 0, 0, 0};
  std::vector<Eigen::Vector3d> landmarks;
  landmarks.reserve(subset.size());
  for (int k : subset) landmarks.push_back(measurements[k].landmark_init_a);

  ceres::Problem::Options problem_options;
  problem_options.enable_fast_removal = false;
  ceres::Problem problem(problem_options);
  problem.AddParameterBlock(delta, 6);
  for (size_t i = 0; i < subset.size(); ++i) {
    const Measurement& m = measurements[subset[i]];
    double* x = landmarks[i].data();
    auto loss = [&]() -> ceres::LossFunction* {
      return robust && options.robust_loss_scale > 0.0 ? new ceres::CauchyLoss(options.robust_loss_scale) : nullptr;
    };
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<BinResidualA, 2, 3>(new BinResidualA{
                                 m.a, m.range_sigma_m, m.a.slant_range_m * options.beam_width_rad}),
                             loss(), x);
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<BinResidualB, 2, 6, 3>(new BinResidualB{
                                 m.b, &anchor, m.range_sigma_m, m.b.slant_range_m * options.beam_width_rad}),
                             loss(), delta, x);
    if (options.use_seabed_prior) {
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<SeabedResidual, 1, 3>(
                                   new SeabedResidual{m.down_a, m.seabed_depth_a_m, options.seabed_sigma_m}),
                               nullptr, x);
    }
  }
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<OdometryResidual, 6, 6>(new OdometryResidual{&anchor, dr, sqrt_information}),
      nullptr, delta);

  ceres::Solver::Options solver_options;
  // Landmarks are the Schur-eliminated block (paper: LM); the pose block is 6x6.
  solver_options.linear_solver_type = subset.size() > 50 ? ceres::SPARSE_SCHUR : ceres::DENSE_SCHUR;
  solver_options.max_num_iterations = max_iterations;
  solver_options.max_solver_time_in_seconds = std::max(max_seconds, 1e-3);
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  // The lateral/depth direction is a long shallow valley (constrained only through the seabed
  // prior): the default relative tolerances stop short of its bottom.
  solver_options.function_tolerance = 1e-10;
  solver_options.parameter_tolerance = 1e-10;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);

  Solved out;
  out.usable = summary.IsSolutionUsable();
  out.final_cost = summary.final_cost;
  out.T_a_b = applyDelta(anchor, delta);
  out.landmarks = landmarks;
  if (!subset.empty()) {
    double range_sum = 0.0, plane_sum = 0.0;
    for (size_t i = 0; i < subset.size(); ++i) {
      const Measurement& m = measurements[subset[i]];
      double r[2];
      BinResidualA{m.a, m.range_sigma_m, m.a.slant_range_m * options.beam_width_rad}(landmarks[i].data(), r);
      range_sum += r[0] * r[0];
      plane_sum += r[1] * r[1];
      BinResidualB{m.b, &anchor, m.range_sigma_m, m.b.slant_range_m * options.beam_width_rad}(
          delta, landmarks[i].data(), r);
      range_sum += r[0] * r[0];
      plane_sum += r[1] * r[1];
    }
    out.range_cost = range_sum / (2.0 * subset.size());
    out.plane_cost = plane_sum / (2.0 * subset.size());
  }
  if (with_covariance && out.usable) {
    anchor = out.T_a_b;  // functors read the anchor through a pointer
    std::fill(delta, delta + 6, 0.0);
    ceres::Covariance::Options covariance_options;
    covariance_options.algorithm_type = ceres::SPARSE_QR;
    ceres::Covariance covariance(covariance_options);
    const std::vector<std::pair<const double*, const double*>> blocks = {{delta, delta}};
    if (covariance.Compute(blocks, &problem)) {
      sss::core::Matrix6d c;
      covariance.GetCovarianceBlock(delta, delta, c.data());  // row-major; symmetric anyway
      out.covariance = 0.5 * (c + c.transpose());
    }
    // The sandwich when asked for; the pose's sensitivity to a common seabed offset and to a common
    // range bias whenever the relief terms will use them (whichever covariance they are added to).
    if (options.covariance_cluster_m > 0.0 || (options.use_seabed_prior && options.seabed_relief_covariance) ||
        options.range_bias_covariance) {
      const ClusterRobust cluster_robust =
          clusterRobustCovariance(measurements, subset, landmarks, &anchor, dr, sqrt_information, options, robust);
      out.per_seabed_offset = cluster_robust.per_seabed_offset;
      out.per_seabed_tilt = cluster_robust.per_seabed_tilt;
      out.per_range_bias = cluster_robust.per_range_bias;
      if (options.covariance_cluster_m > 0.0) {
        out.clusters = cluster_robust.clusters;
        if (cluster_robust.ok) out.robust_covariance = cluster_robust.covariance;
      }
    }
  }
  return out;
}

// Hypothesis check (Alg. 1, HypothesisCheck): with the hypothesis fixed, each landmark is
// re-triangulated by a few Gauss-Newton steps on its own residuals (A and B bins, seabed prior),
// starting from A's flat-seabed geo-reference; the match is an inlier when that landmark's
// whitened cost is below the threshold squared (chi^2 with 2 dof, 1 without the seabed prior).
struct Score {
  double range_cost = 0.0;  // sum of squared whitened range residuals, truncated at the threshold
  double plane_cost = 0.0;  // the same for the plane residuals
  std::vector<int> inliers;
  std::vector<Eigen::Vector3d> landmarks;  // parallel to inliers: the fitted landmark (frame a)
};

struct BinInA {
  Eigen::Vector3d sonar, normal, starboard;  // sonar position, x axis and y axis in frame a
};

BinInA binInA(const Pose& T_a_sonar) {
  return {T_a_sonar.translation, T_a_sonar.rotation * Eigen::Vector3d::UnitX(),
          T_a_sonar.rotation * Eigen::Vector3d::UnitY()};
}

Score scoreHypothesis(const std::vector<Measurement>& measurements, const std::vector<int>& candidates,
                      const Pose& T_a_b, const RelativePoseOptions& options, const std::vector<char>* skip) {
  Score score;
  const double threshold2 = options.inlier_threshold_sigma * options.inlier_threshold_sigma;
  for (int k : candidates) {
    const Measurement& m = measurements[k];
    const BinInA bins[2] = {binInA(m.a.T_centre_sonar), binInA(T_a_b * m.b.T_centre_sonar)};
    const double ranges[2] = {m.a.slant_range_m, m.b.slant_range_m};
    Eigen::Vector3d x = m.landmark_init_a;
    Eigen::Matrix<double, 5, 1> r;
    Eigen::Matrix<double, 5, 3> J;
    const int rows = options.use_seabed_prior ? 5 : 4;
    auto evaluate = [&] {
      for (int o = 0; o < 2; ++o) {
        const Eigen::Vector3d d = x - bins[o].sonar;
        const double range = d.norm();
        const double plane_sigma = ranges[o] * options.beam_width_rad;
        r(2 * o) = (range - ranges[o]) / m.range_sigma_m;  // paper eq. (1), (4)
        J.row(2 * o) = d.transpose() / (range * m.range_sigma_m);
        r(2 * o + 1) = bins[o].normal.dot(d) / plane_sigma;
        J.row(2 * o + 1) = bins[o].normal.transpose() / plane_sigma;
      }
      r(4) = (m.down_a.dot(x) - m.seabed_depth_a_m) / options.seabed_sigma_m;
      J.row(4) = m.down_a.transpose() / options.seabed_sigma_m;
    };
    for (int iteration = 0; iteration < 3; ++iteration) {
      evaluate();
      const Eigen::MatrixXd Jt = J.topRows(rows).transpose();
      const Eigen::Matrix3d H = Jt * J.topRows(rows);
      x -= H.ldlt().solve(Jt * r.head(rows));
    }
    evaluate();
    const bool same_side = (x - bins[1].sonar).dot(bins[1].starboard) * m.b.side > 0.0;
    const double cost = r.head(rows).squaredNorm();
    if (same_side && cost < threshold2) {
      score.inliers.push_back(k);
      score.landmarks.push_back(x);
    }
    if (skip && (*skip)[k]) continue;
    score.range_cost += same_side ? std::min(r(0) * r(0) + r(2) * r(2), threshold2) : threshold2;
    score.plane_cost += same_side ? std::min(r(1) * r(1) + r(3) * r(3), threshold2) : threshold2;
  }
  return score;
}

}  // namespace

namespace {

// Relief of the seabed at the scale of a subframe, from the altimetry both lines recorded: the
// seabed under each ping (sonar depth + altitude) about a straight line fitted along the
// subframe, RMS over both. The seabed prior is a plane between the two lines' nadirs; relief of
// this size between them shifts all landmarks alike and, through the ranges, the lateral offset.
double seabedReliefSigma(const RelativePoseInput& input) {
  double sum_squares = 0.0;
  int count = 0;
  auto addLine = [&](const std::vector<Pose>& poses, const std::vector<double>& altitude_m) {
    const int n = static_cast<int>(poses.size());
    if (n < 3) return;
    Eigen::MatrixXd design(n, 2);
    Eigen::VectorXd depth(n);
    for (int i = 0; i < n; ++i) {
      design(i, 0) = 1.0;
      design(i, 1) = i;
      depth(i) = poses[i].translation.z() + altitude_m[i];
    }
    const Eigen::VectorXd residual = depth - design * design.colPivHouseholderQr().solve(depth);
    if (!residual.allFinite()) return;
    sum_squares += residual.squaredNorm();
    count += n - 2;
  };
  addLine(input.dr_poses_a, input.altitude_a_m);
  addLine(input.dr_poses_b, input.altitude_b_m);
  return count > 0 ? std::sqrt(sum_squares / count) : 0.0;
}

// How much the seabed under the matches may tilt along track against the prior: relief of the
// size both lines' altimetry shows about a straight line along the subframes (seabedReliefSigma),
// taken as a ramp over the subframe's length L, the shape of it that turns the pose: a ramp of RMS
// sigma over L has the slope sigma sqrt(12) / L. Relief at the scale of the subframe (an
// undulation of about its length) does turn closures between lines far apart this way; a flat or
// evenly sloping seabed costs nothing.
double seabedTiltSigma(const RelativePoseInput& input, double relief_sigma_m) {
  auto length = [](const std::vector<Pose>& poses) {
    double along_m = 0.0;
    for (size_t i = 1; i < poses.size(); ++i) along_m += (poses[i].translation - poses[i - 1].translation).head<2>().norm();
    return along_m;
  };
  const double length_m = 0.5 * (length(input.dr_poses_a) + length(input.dr_poses_b));
  return length_m > 1.0 ? relief_sigma_m * std::sqrt(12.0) / length_m : 0.0;
}

}  // namespace

RelativePoseResult estimateRelativePose(const RelativePoseInput& input, const RelativePoseOptions& options) {
  const Clock::time_point start = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  RelativePoseResult result;
  auto reject = [&](const std::string& reason) {
    result.accepted = false;
    result.reason = reason;
    result.seconds = elapsed();
    return result;
  };

  const std::vector<std::string> option_problems = validateRelativePoseOptions(options);
  if (!option_problems.empty()) return reject("invalid options: " + option_problems.front());
  const int rows_a = static_cast<int>(input.dr_poses_a.size());
  const int rows_b = static_cast<int>(input.dr_poses_b.size());
  if (rows_a == 0 || rows_b == 0 || input.altitude_a_m.size() != input.dr_poses_a.size() ||
      input.altitude_b_m.size() != input.dr_poses_b.size() || input.centre_a < 0 || input.centre_a >= rows_a ||
      input.centre_b < 0 || input.centre_b >= rows_b || input.geometry.bins_per_side <= 0 || !(input.geometry.bin_size_m > 0.0)) {
    return reject("inconsistent input: poses, altitudes, centre rows or bin geometry do not agree; check the subframes");
  }
  Eigen::LLT<sss::core::Matrix6d> llt(input.dr_covariance_ab);
  if (llt.info() != Eigen::Success) return reject("dr_covariance_ab is not positive definite");
  const sss::core::Matrix6d L = llt.matrixL();
  const sss::core::Matrix6d sqrt_information = L.inverse();  // whitening: (L^-1 e) has unit covariance

  const Pose T_world_a = input.dr_poses_a[input.centre_a];
  const Pose T_world_bc = input.dr_poses_b[input.centre_b];
  const Pose T_a_world = T_world_a.inverse();
  const Pose T_a_b_dr = T_a_world * T_world_bc;
  const Eigen::Vector3d down_a = T_world_a.rotation.conjugate() * Eigen::Vector3d::UnitZ();

  // Per-correspondence geometry (paper eq. (2)); matches outside the images or without a seabed
  // intersection are skipped.
  std::vector<Measurement> measurements;
  std::vector<int> match_index;
  measurements.reserve(input.matches.size());
  for (size_t k = 0; k < input.matches.size(); ++k) {
    const Correspondence& c = input.matches[k];
    const auto ping_a = pingAt(input.dr_poses_a, input.altitude_a_m, c.row_a);
    const auto ping_b = pingAt(input.dr_poses_b, input.altitude_b_m, c.row_b);
    if (!ping_a || !ping_b) continue;
    const int last_column = input.geometry.columns() - 1;
    if (c.col_a < 0 || c.col_a > last_column || c.col_b < 0 || c.col_b > last_column)
      continue;
    const double g_a = input.geometry.signedGroundRangeM(c.col_a);
    const double g_b = input.geometry.signedGroundRangeM(c.col_b);
    const double h_a = ping_a->second, h_b = ping_b->second;
    Measurement m;
    const Pose T_world_sonar_a = ping_a->first * input.geometry.T_body_sonar;
    m.a.T_centre_sonar = T_a_world * T_world_sonar_a;
    m.a.slant_range_m = std::sqrt(g_a * g_a + h_a * h_a);
    m.a.side = g_a < 0.0 ? -1 : 1;
    m.b.T_centre_sonar = T_world_bc.inverse() * ping_b->first * input.geometry.T_body_sonar;
    m.b.slant_range_m = std::sqrt(g_b * g_b + h_b * h_b);
    m.b.side = g_b < 0.0 ? -1 : 1;
    const auto seabed = sss::core::georeferencePixel(input.geometry, ping_a->first, h_a, c.col_a);
    if (!seabed) continue;
    m.landmark_init_a = T_a_world * *seabed;
    m.down_a = down_a;
    // The seabed under A's ping (pressure depth + altitude: absolute, no horizontal DR error).
    m.seabed_depth_a_m = down_a.dot(m.a.T_centre_sonar.translation) + h_a;
    if (options.seabed_between_lines) {
      // The seabed is rarely level: on a 2 deg slope it is 1.4 m deeper 40 m across track than
      // under A. B's altimeter measured it under B's ping, so the prior follows the line from A's
      // nadir to B's nadir (u = 0 under A, 1 under B; extrapolated at most half-way beyond).
      const Eigen::Vector3d nadir_a = m.a.T_centre_sonar.translation + h_a * down_a;
      const Eigen::Vector3d sonar_b_in_a = T_a_world * (ping_b->first * input.geometry.T_body_sonar).translation;
      const Eigen::Vector3d nadir_b = sonar_b_in_a + h_b * down_a;
      const double depth_b = down_a.dot(nadir_b);
      Eigen::Vector3d across = nadir_b - nadir_a;
      across -= down_a * down_a.dot(across);  // horizontal
      const double length2 = across.squaredNorm();
      if (length2 > 1.0) {
        const double u = std::clamp((m.landmark_init_a - nadir_a).dot(across) / length2, -0.5, 1.5);
        m.seabed_depth_a_m += u * (depth_b - m.seabed_depth_a_m);
      }
    }
    m.peak_curvature_col = c.peak_curvature_col;
    measurements.push_back(m);
    match_index.push_back(static_cast<int>(k));
  }
  rangeSigmasFromPeaks(measurements, options);
  const int n = static_cast<int>(measurements.size());
  if (n < std::max(options.ransac_subset, options.min_inliers)) {
    std::ostringstream text;
    text << "only " << n << " usable correspondences (of " << input.matches.size() << "); need at least "
         << std::max(options.ransac_subset, options.min_inliers);
    return reject(text.str());
  }

  // paper Alg. 1: keep a hypothesis only if plane, range and optimisation costs all improve.
  std::mt19937_64 rng(options.seed);
  double best_plane = std::numeric_limits<double>::infinity();
  double best_range = best_plane, best_optimisation = best_plane;
  std::optional<Pose> best_pose;
  std::vector<char> in_subset(n, 0);
  std::vector<int> subset;
  // Hypotheses are scored on an even sample of the matches (bounded time); the RANSAC winner's
  // inliers are then re-scored on all of them.
  std::vector<int> all(n);
  for (int k = 0; k < n; ++k) all[k] = k;
  std::vector<int> score_sample;
  const int sample_size = std::min(n, options.ransac_score_sample);
  for (int i = 0; i < sample_size; ++i) score_sample.push_back(static_cast<int>(static_cast<long>(i) * n / sample_size));
  // Without a wall-clock cap (the default) the result depends only on the input and the seed.
  const bool capped = options.time_limit_s > 0.0;
  const double ransac_budget_s = capped ? 0.6 * options.time_limit_s : 1e9;
  const int hypothesis_iterations = std::max(5, options.max_solver_iterations / 4);
  for (int iteration = 0; iteration < options.ransac_iterations && (!capped || elapsed() < ransac_budget_s);
       ++iteration) {
    ++result.ransac_iterations_run;
    subset.clear();
    while (static_cast<int>(subset.size()) < options.ransac_subset) {
      const int k = std::uniform_int_distribution<int>(0, n - 1)(rng);
      if (!in_subset[k]) {
        in_subset[k] = 1;
        subset.push_back(k);
      }
    }
    const Solved hypothesis = solve(measurements, subset, T_a_b_dr, T_a_b_dr, sqrt_information, options,
                                    hypothesis_iterations, ransac_budget_s - elapsed(), false, false);
    if (hypothesis.usable) {
      const Score score = scoreHypothesis(measurements, score_sample, hypothesis.T_a_b, options, &in_subset);
      if (score.plane_cost < best_plane && score.range_cost < best_range && hypothesis.final_cost < best_optimisation) {
        best_plane = score.plane_cost;
        best_range = score.range_cost;
        best_optimisation = hypothesis.final_cost;
        best_pose = hypothesis.T_a_b;
      }
    }
    for (int k : subset) in_subset[k] = 0;
  }
  if (!best_pose) return reject("no RANSAC hypothesis converged");
  Pose pose = *best_pose;
  Score final_score = scoreHypothesis(measurements, all, pose, options, nullptr);
  std::vector<int> inliers = final_score.inliers;
  const int needed = std::max(options.min_inliers, options.ransac_subset);
  if (static_cast<int>(inliers.size()) < needed) {
    std::ostringstream text;
    text << "RANSAC found only " << inliers.size() << " geometrically consistent matches of " << n
         << " after " << result.ransac_iterations_run << " hypotheses; need " << needed
         << ": wrong pair or bad data association";
    result.T_a_b = pose;
    result.num_inliers = static_cast<int>(inliers.size());
    return reject(text.str());
  }

  // Final refinement on the inliers (evenly sampled down to max_correspondences), twice: the
  // second pass re-selects the inliers with the refined pose.
  auto sampleEvenly = [&](const std::vector<int>& candidates) {
    if (static_cast<int>(candidates.size()) <= options.max_correspondences) return candidates;
    std::vector<int> sampled;
    sampled.reserve(options.max_correspondences);
    for (int i = 0; i < options.max_correspondences; ++i)
      sampled.push_back(candidates[static_cast<size_t>(i) * candidates.size() / options.max_correspondences]);
    return sampled;
  };
  Solved refined;
  for (int pass = 0; pass < 2; ++pass) {
    if (static_cast<int>(inliers.size()) < options.ransac_subset) break;
    const std::vector<int> used = sampleEvenly(inliers);
    const double remaining_s = capped ? std::max(options.time_limit_s - elapsed(), 0.05) : 1e9;
    refined = solve(measurements, used, pose, T_a_b_dr, sqrt_information, options, options.max_solver_iterations,
                    pass == 0 ? 0.5 * remaining_s : remaining_s, pass == 1, true);
    if (!refined.usable) break;
    pose = refined.T_a_b;
    result.inlier_indices.clear();
    for (int k : used) result.inlier_indices.push_back(match_index[k]);
    result.landmarks_a = refined.landmarks;
    final_score = scoreHypothesis(measurements, all, pose, options, nullptr);
    inliers = final_score.inliers;
  }
  // Every inlier for the point cloud; the refined ones keep their jointly optimised landmark.
  std::map<int, Eigen::Vector3d> refined_landmark;
  for (size_t i = 0; i < result.inlier_indices.size() && i < result.landmarks_a.size(); ++i)
    refined_landmark[result.inlier_indices[i]] = result.landmarks_a[i];
  result.all_inlier_indices.reserve(inliers.size());
  result.all_inlier_landmarks_a.reserve(inliers.size());
  for (size_t i = 0; i < inliers.size(); ++i) {
    const int match = match_index[inliers[i]];
    const auto found = refined_landmark.find(match);
    result.all_inlier_indices.push_back(match);
    result.all_inlier_landmarks_a.push_back(found != refined_landmark.end() ? found->second : final_score.landmarks[i]);
  }

  result.T_a_b = pose;
  result.num_inliers = static_cast<int>(inliers.size());
  result.range_cost = refined.range_cost;
  result.plane_cost = refined.plane_cost;
  result.total_cost = refined.final_cost;
  if (refined.covariance) result.model_covariance = *refined.covariance;
  result.covariance_clusters = refined.clusters;
  const bool cluster_robust = options.covariance_cluster_m > 0.0;
  if (cluster_robust && refined.robust_covariance) result.covariance = *refined.robust_covariance;
  if (!cluster_robust && refined.covariance) result.covariance = *refined.covariance;
  // Relief between the lines: a common offset of the seabed under the matches moves the pose along
  // per_seabed_offset (mostly laterally), and no residual shows it; its size is the relief both
  // lines' altimetry recorded along the subframes. Added to whichever covariance is in use.
  if (options.use_seabed_prior && options.seabed_relief_covariance && (refined.robust_covariance || refined.covariance)) {
    result.seabed_relief_sigma_m = seabedReliefSigma(input);
    const double sigma = result.seabed_relief_sigma_m;
    result.relief_covariance = sigma * sigma * refined.per_seabed_offset * refined.per_seabed_offset.transpose();
    if (options.seabed_tilt_covariance) {
      result.seabed_tilt_sigma = seabedTiltSigma(input, sigma);
      const double tilt = result.seabed_tilt_sigma;
      result.relief_covariance += tilt * tilt * refined.per_seabed_tilt * refined.per_seabed_tilt.transpose();
    }
  }
  // Raised features' faces: every matched pixel nearer both sonars than the point both lines see
  // moves the pose along per_range_bias, and no residual shows it either (zero without a covariance).
  result.range_bias_sensitivity = refined.per_range_bias;
  if (options.range_bias_covariance) {
    const double b = options.range_bias_sigma_m;
    result.relief_covariance += b * b * refined.per_range_bias * refined.per_range_bias.transpose();
  }
  result.covariance += result.relief_covariance;

  std::ostringstream text;
  if (!refined.usable || !refined.covariance) {
    text << "final refinement failed (" << inliers.size() << " inliers): no usable solution or covariance";
  } else if (cluster_robust && refined.clusters < options.min_covariance_clusters) {
    text << "inliers on only " << refined.clusters << " seabed patches of " << options.covariance_cluster_m
         << " m (min_covariance_clusters " << options.min_covariance_clusters
         << "): too few independent looks to estimate the closure's uncertainty";
  } else if (cluster_robust && !refined.robust_covariance) {
    text << "cluster-robust covariance failed (singular information): the matches do not constrain the pose";
  } else if (result.num_inliers < options.min_inliers) {
    text << result.num_inliers << " inliers, below min_inliers " << options.min_inliers;
  } else if (result.num_inliers < options.min_inlier_fraction * n) {
    text << result.num_inliers << " inliers of " << n << " usable correspondences, below min_inlier_fraction "
         << options.min_inlier_fraction;
  } else if (result.range_cost > options.max_mean_cost || result.plane_cost > options.max_mean_cost) {
    text << "mean costs range " << result.range_cost << ", plane " << result.plane_cost << " above max_mean_cost "
         << options.max_mean_cost;
  }
  result.reason = text.str();
  result.accepted = result.reason.empty();
  result.seconds = elapsed();
  return result;
}

}  // namespace sss::matcher
