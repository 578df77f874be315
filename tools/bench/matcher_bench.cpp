// sss-bench-matcher: speed and accuracy of the matcher on simulated subframe pairs. Renders a
// lawnmower survey (lines 40 m apart: neighbours anti-parallel, every second line parallel),
// adds 3 m along-track and 2 m lateral DR error between the two subframes of each overlapping
// full pair, runs dense matching + relative pose, and checks both against the ray-cast truth.
// Prints a line per pair, a summary, and as its last line one JSON object.
//   sss-bench-matcher [--lines N] [--line-length-m M] [--repeat K]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "pipeline/matcher/overlap.hpp"
#include "pipeline/matcher/pair_matcher.hpp"
#include "pipeline/subframe/georeference.hpp"
#include "tools/eval/match_metrics.hpp"
#include "tools/sim/simulated_survey.hpp"

namespace {

using sss::core::Pose;

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())))];
}

}  // namespace

int main(int argc, char** argv) {
  int lines = 3, repeat = 1;
  double line_length_m = 300.0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--lines" && i + 1 < argc) {
      lines = std::atoi(argv[++i]);
    } else if (arg == "--line-length-m" && i + 1 < argc) {
      line_length_m = std::atof(argv[++i]);
    } else if (arg == "--repeat" && i + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: %s [--lines N] [--line-length-m M] [--repeat K]\n", argv[0]);
      return arg == "--help" ? 0 : 2;
    }
  }
  sss::sim::SimOptions sim;
  sim.trajectory.lines = std::max(2, lines);
  sim.trajectory.line_length_m = line_length_m;
  sim.trajectory.line_spacing_m = 40.0;
  std::printf("rendering %d lines of %.0f m ...\n", sim.trajectory.lines, line_length_m);
  const sss::sim::SimulatedSurvey survey = sss::sim::simulateSurvey(sim);
  const sss::sim::SubframeTruth truth(*survey.mission);

  sss::matcher::PairMatcherOptions options;
  const sss::matcher::DenseMatcher dense(options.dense);
  sss::matcher::OverlapOptions overlap;
  std::vector<const sss::subframe::Subframe*> full;
  std::vector<sss::matcher::Footprint> footprints;
  for (const auto& s : survey.subframes) {
    if (s.rows() != 200) continue;
    full.push_back(&s);
    footprints.push_back(sss::matcher::computeFootprint(s, sss::subframe::drPoses(s), overlap));
  }

  std::vector<double> seconds, georef, kd, init, patchmatch, consistency, pose, along_err, lateral_err;
  long matches = 0, evaluated = 0, within = 0, matchable = 0, accepted = 0, pairs = 0;
  long parallel_pairs = 0, anti_pairs = 0;
  for (size_t i = 0; i < full.size(); ++i) {
    for (size_t j = i + 1; j < full.size(); ++j) {
      const auto& a = *full[i];
      const auto& b = *full[j];
      if (a.line_id == b.line_id) continue;
      const double area = sss::matcher::overlapAreaM2(footprints[i], footprints[j]);
      if (area < overlap.min_overlap_fraction * std::min(footprints[i].area_m2, footprints[j].area_m2)) continue;
      const bool parallel = (b.line_id - a.line_id) % 2 == 0;
      for (int k = 0; k < repeat; ++k) {
        const auto match = sss::matcher::matchPair(a, sss::subframe::drPoses(a), b, sss::sim::posesWithDrError(a, b, 3.0, 2.0), dense,
                                                   options);
        seconds.push_back(match.seconds);
        georef.push_back(match.georeference_s);
        kd.push_back(match.dense_timings.kd_tree_s);
        init.push_back(match.dense_timings.initialisation_s);
        patchmatch.push_back(match.dense_timings.patch_match_s);
        consistency.push_back(match.dense_timings.consistency_s);
        pose.push_back(match.pose.seconds);
        if (k > 0) continue;
        ++pairs;
        (parallel ? parallel_pairs : anti_pairs) += 1;
        const auto e =
            sss::eval::evaluateMatches(survey, a, b, match.matches, options.dense.stride, match.decimation);
        matches += e.matches;
        evaluated += e.evaluated;
        within += e.within_2px;
        matchable += e.matchable;
        const Eigen::Vector3d error = match.pose.T_a_b.translation - truth.trueRelativePose(a, b).translation;
        if (match.accepted) {
          ++accepted;
          along_err.push_back(std::abs(error.x()));
          lateral_err.push_back(std::abs(error.y()));
        }
        std::printf("pair %lld-%lld (%s, lines %d-%d): %.3f s (georef %.3f, kd %.3f, init %.3f, patchmatch %.3f, "
                    "consistency %.3f, pose %.3f); %ld matches, within 2 px %.3f, recall %.3f; %s, error along %.3f "
                    "lateral %.3f m\n",
                    (long long)a.id, (long long)b.id, parallel ? "parallel" : "anti-parallel", a.line_id, b.line_id,
                    match.seconds, match.georeference_s, match.dense_timings.kd_tree_s,
                    match.dense_timings.initialisation_s, match.dense_timings.patch_match_s,
                    match.dense_timings.consistency_s, match.pose.seconds, e.matches, e.withinFraction(), e.recall(),
                    match.accepted ? "accepted" : match.reason.c_str(), error.x(), error.y());
      }
    }
  }
  if (pairs == 0) {
    std::fprintf(stderr, "no overlapping full subframe pairs; use longer lines\n");
    return 1;
  }
  auto mean = [](const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / static_cast<double>(v.size());
  };
  const double within_fraction = evaluated ? double(within) / evaluated : 0.0;
  const double recall = matchable ? double(within) / matchable : 0.0;
  std::printf("%ld pairs (%ld parallel, %ld anti-parallel), %ld accepted; %.3f s per pair (p95 %.3f); breakdown: "
              "georeference %.3f, kd-tree %.3f, initialisation %.3f, PatchMatch %.3f, consistency %.3f, RANSAC+pose "
              "%.3f s; within 2 px %.3f, recall %.3f; |error| p95 along %.3f lateral %.3f m\n",
              pairs, parallel_pairs, anti_pairs, accepted, mean(seconds), percentile(seconds, 0.95), mean(georef),
              mean(kd), mean(init), mean(patchmatch), mean(consistency), mean(pose), within_fraction, recall,
              percentile(along_err, 0.95), percentile(lateral_err, 0.95));
  std::printf("{\"seconds_per_pair\": %.4f, \"seconds_p95\": %.4f, \"within_2px\": %.4f, \"recall\": %.4f, "
              "\"pairs\": %ld, \"parallel_pairs\": %ld, \"anti_parallel_pairs\": %ld, \"accepted\": %ld, "
              "\"georeference_s\": %.4f, \"kd_tree_s\": %.4f, \"initialisation_s\": %.4f, \"patch_match_s\": %.4f, "
              "\"consistency_s\": %.4f, \"relative_pose_s\": %.4f, \"along_error_p95_m\": %.4f, "
              "\"lateral_error_p95_m\": %.4f, \"matches_per_pair\": %ld, \"dr_error_m\": [3.0, 2.0]}\n",
              mean(seconds), percentile(seconds, 0.95), within_fraction, recall, pairs, parallel_pairs, anti_pairs,
              accepted, mean(georef), mean(kd), mean(init), mean(patchmatch), mean(consistency), mean(pose),
              percentile(along_err, 0.95), percentile(lateral_err, 0.95), matches / pairs);
  return 0;
}
