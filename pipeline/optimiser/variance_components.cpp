// Variance-component estimation, see variance_components.hpp.
//
// The redundancy needs tr(A_f N^-1 A_f^T) for every factor f, so only the blocks of N^-1 that pair
// the factor's own variables: a sparse LDL^T of N, then for each variable block b the six columns
// N^-1 E_b, from which the blocks (c, b) of the factors touching b are kept. Cost: one sparse
// solve with 6 right-hand sides per block, memory of one column block; no dense N^-1 (a
// mission-long graph has thousands of blocks).
#include "pipeline/optimiser/variance_components.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>

namespace sss::optimiser {

namespace {
constexpr int kBlock = 6;
}

double VarianceComponent::varianceFactor() const {
  // Below a thousandth of a row the group is absorbed: the ratio would be noise over nothing.
  if (!(redundancy > 1e-3)) return std::numeric_limits<double>::quiet_NaN();
  return square_sum / redundancy;
}

bool estimateVarianceComponents(const std::vector<WhitenedFactor>& factors, int num_blocks, int num_groups,
                                std::vector<VarianceComponent>& components) {
  components.assign(std::max(num_groups, 0), VarianceComponent{});
  if (num_blocks <= 0) return false;
  for (const WhitenedFactor& f : factors) {
    if (f.jacobian.cols() != kBlock * static_cast<int>(f.blocks.size()) || f.jacobian.rows() != f.residual.size())
      return false;
    for (int b : f.blocks)
      if (b < 0 || b >= num_blocks) return false;
    if (!f.jacobian.allFinite() || !f.residual.allFinite()) return false;
  }

  // N = sum A^T A.
  const int dim = kBlock * num_blocks;
  std::vector<Eigen::Triplet<double>> triplets;
  for (const WhitenedFactor& f : factors) {
    const Eigen::MatrixXd ata = f.jacobian.transpose() * f.jacobian;
    for (size_t p = 0; p < f.blocks.size(); ++p)
      for (size_t q = 0; q < f.blocks.size(); ++q)
        for (int i = 0; i < kBlock; ++i)
          for (int j = 0; j < kBlock; ++j)
            triplets.emplace_back(kBlock * f.blocks[p] + i, kBlock * f.blocks[q] + j,
                                  ata(kBlock * static_cast<int>(p) + i, kBlock * static_cast<int>(q) + j));
  }
  Eigen::SparseMatrix<double> normal(dim, dim);
  normal.setFromTriplets(triplets.begin(), triplets.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(normal);
  if (ldlt.info() != Eigen::Success) return false;
  if (!(ldlt.vectorD().array() > 0.0).all()) return false;

  // Per factor, the blocks of N^-1 among its own variables, filled one column block at a time.
  std::vector<Eigen::MatrixXd> covariance(factors.size());
  std::vector<std::vector<std::pair<int, int>>> touching(num_blocks);  // block -> (factor, position)
  for (size_t f = 0; f < factors.size(); ++f) {
    const int width = kBlock * static_cast<int>(factors[f].blocks.size());
    if (factors[f].group < 0 || factors[f].group >= num_groups) continue;
    covariance[f] = Eigen::MatrixXd::Zero(width, width);
    for (size_t p = 0; p < factors[f].blocks.size(); ++p)
      touching[factors[f].blocks[p]].emplace_back(static_cast<int>(f), static_cast<int>(p));
  }
  Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(dim, kBlock);
  for (int b = 0; b < num_blocks; ++b) {
    if (touching[b].empty()) continue;
    unit.setZero();
    unit.middleRows(kBlock * b, kBlock).setIdentity();
    const Eigen::MatrixXd columns = ldlt.solve(unit);  // N^-1 E_b
    if (ldlt.info() != Eigen::Success || !columns.allFinite()) return false;
    for (const auto& [f, p] : touching[b])
      for (size_t q = 0; q < factors[f].blocks.size(); ++q)
        covariance[f].block(kBlock * static_cast<int>(q), kBlock * p, kBlock, kBlock) =
            columns.middleRows(kBlock * factors[f].blocks[q], kBlock);
  }

  for (size_t f = 0; f < factors.size(); ++f) {
    const WhitenedFactor& factor = factors[f];
    if (factor.group < 0 || factor.group >= num_groups) continue;
    VarianceComponent& c = components[factor.group];
    const int rows = static_cast<int>(factor.residual.size());
    const double absorbed = (factor.jacobian * covariance[f] * factor.jacobian.transpose()).trace();
    ++c.factors;
    c.rows += rows;
    c.square_sum += factor.residual.squaredNorm();
    c.redundancy += std::clamp(rows - absorbed, 0.0, static_cast<double>(rows));
  }
  return true;
}

}  // namespace sss::optimiser
