// Full subframes and their footprints, see survey_footprints.hpp.
#include "tools/eval/survey_footprints.hpp"

#include "pipeline/core/georeference.hpp"
#include "tools/sim/simulated_survey.hpp"

namespace sss::eval {

SurveyFootprints fullSubframeFootprints(const sss::sim::SimulatedSurvey& survey,
                                        const sss::matcher::OverlapOptions& overlap) {
  SurveyFootprints result;
  for (const sss::core::Subframe& subframe : survey.subframes) {
    if (subframe.rows() != 200) continue;  // a line's tail
    result.subframes.push_back(&subframe);
    result.footprints.push_back(sss::matcher::computeFootprint(subframe, sss::core::drPoses(subframe), overlap));
  }
  return result;
}

}  // namespace sss::eval
