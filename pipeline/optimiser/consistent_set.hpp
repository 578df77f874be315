// The largest set of mutually consistent loop closures: a maximum clique of the pairwise
// consistency graph (PCM, Mangelson et al. 2018), found greedily. Pure function: the pose graph
// builds the graph from its closures' cycles with DR and applies the decision.
#pragma once

#include <utility>
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

// The same search, its sets ranked by independent evidence: subframes_of[p] holds closure p's two
// subframes (node indices), and a set's worth is independentClosures() of its members, then its
// size, then its previously accepted members. Closures through one subframe share that image's
// errors (a wrong along-track shift, relief misread as offset), so they agree with each other
// whatever the error is: a set held together only by them is one piece of evidence, not several.
std::vector<int> mostIndependentConsistentSet(const std::vector<std::vector<char>>& consistent,
                                              const std::vector<char>& previously_accepted,
                                              const std::vector<std::pair<int, int>>& subframes_of);

// How many of the given closures share no subframe with one another: a matching of the graph whose
// vertices are subframes and whose edges are closures, found greedily, the closures whose
// subframes carry the fewest other closures first. Exact up to 2 (a star of closures through one
// subframe gives 1); a lower bound of the largest such matching above.
int independentClosures(const std::vector<std::pair<int, int>>& subframes_of_closures);
// The same count for the members of a set, subframes_of holding every closure's two subframes.
int independentClosures(const std::vector<int>& members, const std::vector<std::pair<int, int>>& subframes_of);

}  // namespace sss::optimiser
