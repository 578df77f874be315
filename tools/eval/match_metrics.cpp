// Correspondence accuracy against the simulator's ray-cast truth.
#include "tools/eval/match_metrics.hpp"

#include <cmath>

namespace sss::eval {

MatchEvaluation evaluateMatches(const sss::sim::SimulatedSurvey& survey, const sss::subframe::Subframe& a,
                                const sss::subframe::Subframe& b,
                                const std::vector<sss::matcher::Correspondence>& matches, int stride, int decimation,
                                int recall_step) {
  const sss::sim::SubframeTruth truth(*survey.mission);
  MatchEvaluation e;
  e.matches = static_cast<long>(matches.size());
  double error_sum = 0.0;
  for (const auto& m : matches) {
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
  long sampled = 0;
  const int step = stride * recall_step;
  const int half_patch = 6;  // a patch must fit inside B around the true pixel
  for (int r = 0; r < a.rows(); r += step) {
    for (int c = 0; c < a.cols(); c += step * decimation) {
      if (a.mask[static_cast<size_t>(r) * a.cols() + c] != 0) continue;
      const auto point = truth.seabedPoint(a, r, c);
      if (!point) continue;
      const auto pixel = truth.pixelOf(b, *point);
      if (!pixel) continue;
      const int br = static_cast<int>(std::lround(pixel->x())), bc = static_cast<int>(std::lround(pixel->y()));
      if (br < half_patch || bc < half_patch * decimation || br >= b.rows() - half_patch ||
          bc >= b.cols() - half_patch * decimation)
        continue;
      if (b.mask[static_cast<size_t>(br) * b.cols() + bc] != 0) continue;
      ++sampled;
    }
  }
  e.matchable = sampled * recall_step * recall_step;
  return e;
}

}  // namespace sss::eval
