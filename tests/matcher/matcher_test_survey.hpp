// Small simulated surveys for the matcher tests, rendered once per test binary, and the
// ground-truth evaluation of correspondences between two of their subframes.
#pragma once

#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "pipeline/matcher/dense_matcher.hpp"
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
inline const sss::subframe::Subframe* fullSubframeOfLine(const sss::sim::SimulatedSurvey& survey, int line_id) {
  for (const auto& s : survey.subframes) {
    if (s.line_id == line_id && s.rows() == 200) return &s;
  }
  return nullptr;
}

struct MatchEvaluation {
  long matches = 0;
  long evaluated = 0;         // matches whose A pixel has a true B pixel
  long within_2px = 0;
  long matchable = 0;         // stride-grid valid A pixels whose true B pixel is valid
  double mean_error_px = 0.0;
  double withinFraction() const { return evaluated ? double(within_2px) / evaluated : 0.0; }
  double recall() const { return matchable ? double(within_2px) / matchable : 0.0; }
};

// End-point error of every match against the ray-cast truth, in pixels of the matching image
// (rows = pings, columns = `decimation` canonical bins); recall over the matching stride grid
// (every `recall_step`-th grid pixel, to bound the ray casts).
inline MatchEvaluation evaluateMatches(const sss::sim::SimulatedSurvey& survey, const sss::subframe::Subframe& a,
                                       const sss::subframe::Subframe& b, const std::vector<Correspondence>& matches,
                                       int stride, int decimation, int recall_step = 4) {
  const sss::sim::SubframeTruth truth(*survey.mission);
  MatchEvaluation e;
  e.matches = static_cast<long>(matches.size());
  double error_sum = 0.0;
  for (const Correspondence& m : matches) {
    const auto point = truth.seabedPoint(a, static_cast<int>(std::lround(m.row_a)), m.col_a);
    if (!point) continue;
    const auto pixel = truth.pixelOf(b, *point);
    if (!pixel) continue;
    const double error = std::hypot(pixel->x() - m.row_b, (pixel->y() - m.col_b) / decimation);
    ++e.evaluated;
    error_sum += error;
    if (error <= 2.0) ++e.within_2px;
  }
  if (e.evaluated) e.mean_error_px = error_sum / static_cast<double>(e.evaluated);
  // Matchable A pixels, counted on a sparser grid and scaled back to the stride grid.
  long sampled = 0;
  const int step = stride * recall_step;
  for (int r = 0; r < a.rows(); r += step) {
    for (int c = 0; c < a.cols(); c += step * decimation) {
      if (a.mask[static_cast<size_t>(r) * a.cols() + c] != 0) continue;
      const auto point = truth.seabedPoint(a, r, c);
      if (!point) continue;
      const auto pixel = truth.pixelOf(b, *point);
      if (!pixel) continue;
      const int br = static_cast<int>(std::lround(pixel->x())), bc = static_cast<int>(std::lround(pixel->y()));
      if (br < 6 || bc < 6 * decimation || br >= b.rows() - 6 || bc >= b.cols() - 6 * decimation) continue;  // a full patch inside B
      if (b.mask[static_cast<size_t>(br) * b.cols() + bc] != 0) continue;
      ++sampled;
    }
  }
  e.matchable = sampled * recall_step * recall_step;
  return e;
}

}  // namespace sss::matcher::test
