// The candidates of a matching evaluation on a simulated survey: its full subframes (200 pings)
// with their footprints under DR, which the matcher benchmark and the matching tests pair up.
#pragma once

#include <vector>

#include "pipeline/core/subframe_types.hpp"
#include "pipeline/matcher/overlap.hpp"

namespace sss::sim {
struct SimulatedSurvey;
}

namespace sss::eval {

struct SurveyFootprints {
  std::vector<const sss::core::Subframe*> subframes;  // into the survey, which must outlive this
  std::vector<sss::matcher::Footprint> footprints;    // one per subframe
};

SurveyFootprints fullSubframeFootprints(const sss::sim::SimulatedSurvey& survey,
                                        const sss::matcher::OverlapOptions& overlap);

}  // namespace sss::eval
