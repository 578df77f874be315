#include "pipeline/optimiser/consistent_set.hpp"

#include <algorithm>
#include <map>
#include <set>

namespace sss::optimiser {

namespace {

// Greedy maximum clique; a candidate set replaces the best when worth(candidate) is larger
// (lexicographic, then the most previously accepted members, then the first found).
template <typename Worth>
std::vector<int> greedyClique(const std::vector<std::vector<char>>& consistent,
                              const std::vector<char>& previously_accepted, Worth worth) {
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
  std::pair<int, int> best_worth(0, 0);
  int best_accepted = -1;
  for (int seed : order) {
    // A clique holds at most degree + 1 members, and both worths are at most its size.
    if (!best.empty() && std::pair<int, int>(degree[seed] + 1, degree[seed] + 1) < best_worth) continue;
    std::vector<int> clique{seed};
    for (int v : order) {
      if (v == seed || !agree(seed, v)) continue;
      bool with_all = true;
      for (int member : clique) with_all = with_all && agree(member, v);
      if (with_all) clique.push_back(v);
    }
    int clique_accepted = 0;
    for (int member : clique) clique_accepted += accepted(member) ? 1 : 0;
    const std::pair<int, int> clique_worth = worth(clique);
    if (best.empty() || clique_worth > best_worth || (clique_worth == best_worth && clique_accepted > best_accepted)) {
      best = clique;
      best_worth = clique_worth;
      best_accepted = clique_accepted;
    }
  }
  return best;
}

}  // namespace

std::vector<int> largestConsistentSet(const std::vector<std::vector<char>>& consistent,
                                      const std::vector<char>& previously_accepted) {
  return greedyClique(consistent, previously_accepted, [](const std::vector<int>& set) {
    const int size = static_cast<int>(set.size());
    return std::pair<int, int>(size, size);
  });
}

std::vector<int> mostIndependentConsistentSet(const std::vector<std::vector<char>>& consistent,
                                              const std::vector<char>& previously_accepted,
                                              const std::vector<std::pair<int, int>>& subframes_of) {
  return greedyClique(consistent, previously_accepted, [&](const std::vector<int>& set) {
    return std::pair<int, int>(independentClosures(set, subframes_of), static_cast<int>(set.size()));
  });
}

int independentClosures(const std::vector<int>& members, const std::vector<std::pair<int, int>>& subframes_of) {
  std::vector<std::pair<int, int>> ends;
  for (int p : members)
    if (p >= 0 && p < static_cast<int>(subframes_of.size())) ends.push_back(subframes_of[p]);
  return independentClosures(ends);
}

int independentClosures(const std::vector<std::pair<int, int>>& subframes_of_closures) {
  std::map<int, int> closures_at;  // subframe -> closures through it
  for (const auto& [a, b] : subframes_of_closures) {
    ++closures_at[a];
    if (b != a) ++closures_at[b];
  }
  std::vector<int> order(subframes_of_closures.size());
  for (std::size_t p = 0; p < order.size(); ++p) order[p] = static_cast<int>(p);
  auto load = [&](int p) {
    const auto& [a, b] = subframes_of_closures[p];
    return closures_at[a] + closures_at[b];
  };
  std::stable_sort(order.begin(), order.end(), [&](int p, int q) { return load(p) < load(q); });
  std::set<int> used;
  int independent = 0;
  for (int p : order) {
    const auto& [a, b] = subframes_of_closures[p];
    if (used.count(a) || used.count(b)) continue;
    used.insert(a);
    used.insert(b);
    ++independent;
  }
  return independent;
}

}  // namespace sss::optimiser
