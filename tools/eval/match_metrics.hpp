// Correspondence accuracy against the simulator's ray-cast truth: end-point error of every match
// in pixels of the matching image, the fraction within 2 px, and recall (issue 9: matching).
#pragma once

#include <vector>

#include "pipeline/matcher/dense_matcher.hpp"
#include "tools/sim/simulated_survey.hpp"

namespace sss::eval {

struct MatchEvaluation {
  long matches = 0;
  long evaluated = 0;   // matches whose A pixel has a true B pixel
  long within_2px = 0;
  long matchable = 0;   // stride-grid valid A pixels whose true B pixel is valid with a full patch
  double mean_error_px = 0.0;
  double withinFraction() const { return evaluated ? double(within_2px) / evaluated : 0.0; }
  double recall() const { return matchable ? double(within_2px) / matchable : 0.0; }
};

// Errors are measured in pixels of the matching image: rows = pings, columns = `decimation`
// canonical bins (match columns are full-resolution). Recall counts matchable pixels on every
// `recall_step`-th node of the matching stride grid (bounded ray casts) and scales back.
MatchEvaluation evaluateMatches(const sss::sim::SimulatedSurvey& survey, const sss::subframe::Subframe& a,
                                const sss::subframe::Subframe& b,
                                const std::vector<sss::matcher::Correspondence>& matches, int stride, int decimation,
                                int recall_step = 4);

}  // namespace sss::eval
