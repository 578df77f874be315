// Small simulated surveys for the matcher tests, rendered once per test binary; correspondences
// are evaluated against the truth with sss::eval::evaluateMatches.
#pragma once

#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pipeline/matcher/dense_matcher.hpp"
#include "tools/eval/match_metrics.hpp"
#include "tools/sim/simulated_survey.hpp"

namespace sss::matcher::test {

// Three 150 m lines 40 m apart: lines 0-1 and 1-2 are anti-parallel neighbours (40 m), lines 0-2
// are parallel (80 m), every pair overlapping (75 m range). Each line gives a 200-ping subframe
// and a shorter tail.
inline sss::sim::SimOptions threeLineOptions(bool textured = true) {
  sss::sim::SimOptions options;
  options.trajectory.lines = 3;
  options.trajectory.line_length_m = 150.0;
  options.trajectory.line_spacing_m = 40.0;
  options.seabed.enable_texture = textured;
  return options;
}

inline const sss::sim::SimulatedSurvey& threeLineSurvey(bool textured = true) {
  static std::map<bool, std::unique_ptr<sss::sim::SimulatedSurvey>> cache;
  auto& entry = cache[textured];
  if (!entry) entry = std::make_unique<sss::sim::SimulatedSurvey>(sss::sim::simulateSurvey(threeLineOptions(textured)));
  return *entry;
}

// The first full (200-ping) subframe of a line.
inline const sss::core::Subframe* fullSubframeOfLine(const sss::sim::SimulatedSurvey& survey, int line_id) {
  for (const auto& s : survey.subframes) {
    if (s.line_id == line_id && s.rows() == 200) return &s;
  }
  return nullptr;
}

// Subframe `id` of the three-line survey (0, 1 on line 0; 2, 3 on line 1; 4, 5 on line 2: full,
// tail) with line k's DR off by k * (2 m north, 1.5 m east) on top of the simulated drift.
inline sss::core::Subframe surveySubframe(int64_t id) {
  for (const sss::core::Subframe& candidate : threeLineSurvey().subframes) {
    if (candidate.id != id) continue;
    sss::core::Subframe s = candidate;
    for (auto& ping : s.pings) ping.T_world_body.translation += s.line_id * Eigen::Vector3d(2.0, 1.5, 0.0);
    return s;
  }
  throw std::runtime_error("no subframe " + std::to_string(id));
}

using sss::eval::evaluateMatches;
using sss::eval::MatchEvaluation;

}  // namespace sss::matcher::test
