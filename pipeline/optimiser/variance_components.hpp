// Variance-component estimation for the pose graph: how much each group of factors (loop closures,
// DR odometry) is to be trusted, learnt from the residuals of the solution itself.
//
// After a weighted least-squares solve, a group k of whitened observations has the expected sum of
// squared residuals E[r_k^T r_k] = sigma_k^2 * redundancy_k, where sigma_k^2 is the factor by which
// its assumed covariances are off and redundancy_k = rows_k - tr(A_k N^-1 A_k^T) is the share of
// the group's rows the solution does not absorb (N = sum_j A_j^T A_j). So
// sigma_k^2 = r_k^T r_k / redundancy_k, applied to the group's covariances and iterated, is
// Förstner's estimator (Förstner 1979; Koch, "Parameter Estimation and Hypothesis Testing in
// Linear Models", sec. 3.6). Why here: the matcher's covariance has the right shape but not the
// right level on a seabed nobody calibrated it on (its errors are correlated within a pair), and
// the odometry model is a specification, not this vehicle's DR; only the disagreement between
// closures and DR across the whole graph shows the level.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace sss::optimiser {

// One whitened, linearised factor r + A dx around the current estimate; dx stacks 6-dof blocks.
struct WhitenedFactor {
  std::vector<int> blocks;   // variable block indices (0 .. num_blocks - 1), one 6-column slice each
  Eigen::MatrixXd jacobian;  // rows x 6 * blocks.size()
  Eigen::VectorXd residual;  // rows
  int group = -1;            // observation group; < 0: part of the system, its level not estimated
};

struct VarianceComponent {
  int factors = 0;
  int rows = 0;
  double square_sum = 0.0;  // sum of whitened r^T r over the group's factors
  double redundancy = 0.0;  // sum over the group of rows - tr(A N^-1 A^T), in [0, rows]
  // sigma^2 = square_sum / redundancy: the factor the group's covariances are off by; NaN when the
  // solution absorbs the group completely (no redundancy, nothing to learn).
  double varianceFactor() const;
};

// Components of the groups 0 .. num_groups - 1 (factors of other groups only shape N). False when N
// is not positive definite (a gauge left free) or an input is malformed (block out of range,
// jacobian of the wrong width).
bool estimateVarianceComponents(const std::vector<WhitenedFactor>& factors, int num_blocks, int num_groups,
                                std::vector<VarianceComponent>& components);

}  // namespace sss::optimiser
