#include "pipeline/optimiser/consistent_set.hpp"

#include <algorithm>

namespace sss::optimiser {

std::vector<int> largestConsistentSet(const std::vector<std::vector<char>>& consistent,
                                      const std::vector<char>& previously_accepted) {
  const int n = static_cast<int>(consistent.size());
  auto agree = [&](int p, int q) {
    return p != q && q < static_cast<int>(consistent[p].size()) && consistent[p][q] != 0;
  };
  auto accepted = [&](int p) { return p < static_cast<int>(previously_accepted.size()) && previously_accepted[p] != 0; };
  std::vector<int> degree(n, 0);
  for (int p = 0; p < n; ++p)
    for (int q = 0; q < n; ++q) degree[p] += agree(p, q) ? 1 : 0;
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
      if (v == seed || !agree(seed, v)) continue;
      bool with_all = true;
      for (int member : clique) with_all = with_all && agree(member, v);
      if (with_all) clique.push_back(v);
    }
    int clique_accepted = 0;
    for (int member : clique) clique_accepted += accepted(member) ? 1 : 0;
    if (clique.size() > best.size() || (clique.size() == best.size() && clique_accepted > best_accepted)) {
      best = clique;
      best_accepted = clique_accepted;
    }
  }
  return best;
}

}  // namespace sss::optimiser
