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
// outside it agrees with all its members (ranked by size or by independent closures).
TEST(ConsistentSet, ResultIsAlwaysAMaximalClique) {
  std::mt19937_64 rng(42);
  std::bernoulli_distribution edge(0.4);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 5 + trial % 20;
    Graph g = emptyGraph(n);
    for (int p = 0; p < n; ++p)
      for (int q = p + 1; q < n; ++q)
        if (edge(rng)) connect(g, p, q);
    std::uniform_int_distribution<int> subframe(0, n);
    std::vector<std::pair<int, int>> subframes_of(n);
    for (auto& ends : subframes_of) ends = {subframe(rng), n + 1 + subframe(rng)};
    for (const std::vector<int>& best : {largestConsistentSet(g, std::vector<char>(n, 0)),
                                         mostIndependentConsistentSet(g, std::vector<char>(n, 0), subframes_of)}) {
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
}

// Closures sharing a subframe count once: a star through one subframe is 1, two closures with four
// different subframes 2, a path of three closures 2 (greedy must not take the middle one first).
TEST(IndependentClosures, ClosuresThroughOneSubframeCountOnce) {
  EXPECT_EQ(independentClosures({}), 0);
  EXPECT_EQ(independentClosures({{24, 3}}), 1);
  EXPECT_EQ(independentClosures({{24, 3}, {24, 4}, {24, 5}}), 1);
  EXPECT_EQ(independentClosures({{3, 24}, {24, 4}}), 1);  // the shared subframe on either side
  EXPECT_EQ(independentClosures({{1, 10}, {2, 11}}), 2);
  EXPECT_EQ(independentClosures({{2, 3}, {1, 2}, {3, 4}}), 2);
  EXPECT_EQ(independentClosures({{1, 2}, {2, 3}, {1, 3}}), 1);  // a triangle of subframes
  EXPECT_EQ(independentClosures({{24, 3}, {24, 4}, {24, 5}, {30, 6}}), 2);
}

// On random small graphs the greedy count is a matching (never more than the true maximum, found
// here by brute force) and reaches the maximum whenever that is 2 or less.
TEST(IndependentClosures, IsAMatchingAndExactUpToTwo) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 300; ++trial) {
    const int subframes = 3 + trial % 6, closures = 1 + trial % 7;
    std::uniform_int_distribution<int> pick(0, subframes - 1);
    std::vector<std::pair<int, int>> ends;
    while (static_cast<int>(ends.size()) < closures) {
      const int a = pick(rng), b = pick(rng);
      if (a != b) ends.emplace_back(a, b);
    }
    int maximum = 0;
    for (int mask = 0; mask < (1 << closures); ++mask) {
      std::vector<int> seen;
      bool disjoint = true;
      for (int p = 0; p < closures; ++p) {
        if (!(mask & (1 << p))) continue;
        for (int v : {ends[p].first, ends[p].second}) {
          disjoint = disjoint && std::find(seen.begin(), seen.end(), v) == seen.end();
          seen.push_back(v);
        }
      }
      if (disjoint) maximum = std::max(maximum, __builtin_popcount(mask));
    }
    const int greedy = independentClosures(ends);
    EXPECT_LE(greedy, maximum) << "trial " << trial;
    EXPECT_GE(greedy, std::min(maximum, 2)) << "trial " << trial;
  }
}

// Four closures through subframe 24 agree with each other (they share its error); two closures of
// other subframes agree with each other but not with them. By size the four win; by independent
// evidence (1 against 2) the two do. Without the subframes both rankings are the same.
TEST(ConsistentSet, ASetHeldTogetherByOneSubframeLosesToIndependentClosures) {
  Graph g = emptyGraph(6);
  for (int p = 0; p < 4; ++p)
    for (int q = p + 1; q < 4; ++q) connect(g, p, q);
  connect(g, 4, 5);
  const std::vector<std::pair<int, int>> subframes_of{{24, 3}, {24, 4}, {24, 5}, {24, 6}, {30, 7}, {31, 8}};
  const std::vector<char> none(6, 0);
  EXPECT_EQ(sorted(largestConsistentSet(g, none)), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(sorted(mostIndependentConsistentSet(g, none, subframes_of)), (std::vector<int>{4, 5}));
  // Equal independent evidence: the larger set wins, even over a set accepted before.
  const std::vector<std::pair<int, int>> all_distinct{{1, 11}, {2, 12}, {3, 13}, {4, 14}, {5, 15}, {6, 16}};
  EXPECT_EQ(sorted(mostIndependentConsistentSet(g, none, all_distinct)), (std::vector<int>{0, 1, 2, 3}));
  const std::vector<std::pair<int, int>> two_each{{24, 3}, {25, 4}, {24, 5}, {25, 6}, {30, 7}, {31, 8}};
  EXPECT_EQ(sorted(mostIndependentConsistentSet(g, none, two_each)), (std::vector<int>{0, 1, 2, 3}));
  std::vector<char> accepted(6, 0);
  accepted[5] = 1;
  const std::vector<std::pair<int, int>> one_each{{24, 3}, {24, 4}, {24, 5}, {24, 6}, {30, 7}, {30, 8}};
  EXPECT_EQ(sorted(mostIndependentConsistentSet(g, accepted, one_each)), (std::vector<int>{0, 1, 2, 3}));
}

}  // namespace
}  // namespace sss::optimiser
