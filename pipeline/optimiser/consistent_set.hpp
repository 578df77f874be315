// The largest set of mutually consistent loop closures: a maximum clique of the pairwise
// consistency graph (PCM, Mangelson et al. 2018), found greedily. Pure function: the pose graph
// builds the graph from its closures' cycles with DR and applies the decision.
#pragma once

#include <vector>

namespace sss::optimiser {

// consistent[p][q] != 0: closures p and q agree (symmetric, the diagonal is ignored);
// previously_accepted[p]: p was accepted at the last decision (keeps decisions stable on ties).
// Greedy: from every vertex as a seed, in order of decreasing degree (previously accepted first
// on equal degree), the vertices consistent with all members so far are added in that order;
// seeds whose degree cannot beat the best set are skipped. The largest set wins, then the one with
// the most previously accepted members, then the first found. Returns the members' indices in the
// order they were added (seed first); empty for an empty graph.
std::vector<int> largestConsistentSet(const std::vector<std::vector<char>>& consistent,
                                      const std::vector<char>& previously_accepted);

}  // namespace sss::optimiser
