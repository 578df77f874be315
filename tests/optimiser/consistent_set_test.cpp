// The closure selection's maximum-clique search on hand-built consistency graphs.
#include "pipeline/optimiser/consistent_set.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace sss::optimiser {
namespace {

using Graph = std::vector<std::vector<char>>;

Graph emptyGraph(int n) { return Graph(n, std::vector<char>(n, 0)); }

void connect(Graph& g, int p, int q) { g[p][q] = g[q][p] = 1; }

std::vector<int> sorted(std::vector<int> v) {
  std::sort(v.begin(), v.end());
  return v;
}

bool mutuallyConsistent(const Graph& g, const std::vector<int>& set) {
  for (int p : set)
    for (int q : set)
      if (p != q && !g[p][q]) return false;
  return true;
}

TEST(ConsistentSet, EmptyGraphGivesEmptySetAndNoEdgesGiveOneClosure) {
  EXPECT_TRUE(largestConsistentSet({}, {}).empty());
  const std::vector<int> one = largestConsistentSet(emptyGraph(4), std::vector<char>(4, 0));
  EXPECT_EQ(one.size(), 1u);  // no pair agrees: any single closure is the largest set
}

// Eight true closures agree with one another; six false ones agree in pairs and with a few true
// ones (a wrong closure can be consistent with some right ones by chance).
TEST(ConsistentSet, FindsThePlantedSetAmongSpuriousAgreements) {
  Graph g = emptyGraph(14);
  for (int p = 0; p < 8; ++p)
    for (int q = p + 1; q < 8; ++q) connect(g, p, q);
  connect(g, 8, 9);
  connect(g, 10, 11);
  connect(g, 12, 13);
  connect(g, 8, 0);
  connect(g, 8, 1);
  connect(g, 9, 0);
  connect(g, 12, 3);
  const std::vector<int> best = largestConsistentSet(g, std::vector<char>(14, 0));
  EXPECT_EQ(sorted(best), (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_TRUE(mutuallyConsistent(g, best));
}

// Two disjoint sets of the same size: the one holding the earlier accepted closures is kept,
// whichever comes first (decisions do not flip back and forth between updates).
TEST(ConsistentSet, OnATieTheSetAcceptedBeforeIsKept) {
  Graph g = emptyGraph(6);
  connect(g, 0, 1);
  connect(g, 1, 2);
  connect(g, 0, 2);
  connect(g, 3, 4);
  connect(g, 4, 5);
  connect(g, 3, 5);
  std::vector<char> accepted(6, 0);
  accepted[4] = 1;
  EXPECT_EQ(sorted(largestConsistentSet(g, accepted)), (std::vector<int>{3, 4, 5}));
  accepted.assign(6, 0);
  accepted[1] = 1;
  EXPECT_EQ(sorted(largestConsistentSet(g, accepted)), (std::vector<int>{0, 1, 2}));
}

// On random graphs the answer is always mutually consistent, and it is maximal: no closure
// outside it agrees with all its members.
TEST(ConsistentSet, ResultIsAlwaysAMaximalClique) {
  std::mt19937_64 rng(42);
  std::bernoulli_distribution edge(0.4);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 5 + trial % 20;
    Graph g = emptyGraph(n);
    for (int p = 0; p < n; ++p)
      for (int q = p + 1; q < n; ++q)
        if (edge(rng)) connect(g, p, q);
    const std::vector<int> best = largestConsistentSet(g, std::vector<char>(n, 0));
    ASSERT_FALSE(best.empty());
    EXPECT_TRUE(mutuallyConsistent(g, best)) << "trial " << trial;
    for (int v = 0; v < n; ++v) {
      if (std::find(best.begin(), best.end(), v) != best.end()) continue;
      std::vector<int> grown = best;
      grown.push_back(v);
      EXPECT_FALSE(mutuallyConsistent(g, grown)) << "trial " << trial << ": " << v << " could join";
    }
  }
}

}  // namespace
}  // namespace sss::optimiser
