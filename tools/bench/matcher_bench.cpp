// sss-bench-matcher: speed and accuracy of the matcher on simulated subframe pairs. Renders a
// lawnmower survey (lines 40 m apart: neighbours anti-parallel, every second line parallel), or
// with --pattern cross the same followed by two crossing lines, adds 3 m along-track and 2 m
// lateral DR error (--dr-error-m ALONG,LATERAL) between the two subframes of each overlapping full pair, runs dense matching +
// relative pose, and checks both against the ray-cast truth. Pairs are typed by their centre
// headings (parallel, anti-parallel, crossing). Prints a line per pair, a summary, and as its last
// line one JSON object. --config FILE takes the matcher settings from a deployment file's matcher
// section (as sss-matcher reads them) instead of the built-in defaults.
//   sss-bench-matcher [--pattern lawnmower|cross] [--lines N] [--line-length-m M] [--line-spacing-m M]
//                     [--repeat K] [--config FILE] [--dr-error-m ALONG,LATERAL]
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "pipeline/transport/command_line.hpp"
#include "pipeline/core/config.hpp"
#include "pipeline/matcher/matcher_engine.hpp"
#include "pipeline/matcher/overlap.hpp"
#include "pipeline/matcher/pair_matcher.hpp"
#include "pipeline/core/georeference.hpp"
#include "tools/eval/match_metrics.hpp"
#include "tools/eval/survey_footprints.hpp"
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
  double line_length_m = 300.0, line_spacing_m = 40.0;
  std::string config_path;
  double dr_along_m = 3.0, dr_lateral_m = 2.0;
  std::string pattern = "lawnmower";
  std::vector<double> dr_error_m = {dr_along_m, dr_lateral_m};
  sss::cli::CommandLine command_line("sss-bench-matcher",
                                     "renders a simulated survey and times the matcher on every overlapping pair");
  command_line.add_option("--pattern", pattern, "survey pattern")
      ->check(CLI::IsMember({"lawnmower", "cross"}))
      ->capture_default_str();
  command_line.add_option("--lines", lines, "survey lines (at least 2)")->check(CLI::Range(2, 1000))
      ->capture_default_str();
  command_line.add_option("--line-length-m", line_length_m, "line length")->check(sss::cli::positive())
      ->capture_default_str();
  command_line.add_option("--line-spacing-m", line_spacing_m, "line spacing")->check(sss::cli::positive())
      ->capture_default_str();
  command_line.add_option("--repeat", repeat, "repeats of the whole run")->check(sss::cli::positive())
      ->capture_default_str();
  command_line.add_option("--config", config_path, "its matcher section (default: the built-in defaults)");
  command_line.add_option("--dr-error-m", dr_error_m, "ALONG,LATERAL DR error between the lines (3,2)")
      ->delimiter(',')
      ->expected(2)
      ->check(CLI::Range(-50.0, 50.0));
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  dr_along_m = dr_error_m[0], dr_lateral_m = dr_error_m[1];
  if (std::hypot(dr_along_m, dr_lateral_m) > 50.0) {
    std::fprintf(stderr, "sss-bench-matcher: --dr-error-m: at most 50 m in all\n");
    return 2;
  }
  sss::sim::SimOptions sim;
  sim.trajectory.lines = std::max(2, lines);
  sim.trajectory.line_length_m = line_length_m;
  sim.trajectory.line_spacing_m = line_spacing_m;
  sim.trajectory.pattern = pattern;
  std::printf("rendering %d lines of %.0f m%s ...\n", sim.trajectory.lines, line_length_m,
              pattern == "cross" ? " and 2 lines crossing them" : "");
  const sss::sim::SimulatedSurvey survey = sss::sim::simulateSurvey(sim);
  const sss::sim::SubframeTruth truth(*survey.mission);

  sss::matcher::PairMatcherOptions options;
  if (!config_path.empty()) {
    // The deployed matcher settings, read as sss-matcher reads them.
    sss::core::Config config = sss::core::Config::fromFile(config_path);
    sss::core::ConfigSection section = config.section("matcher");
    sss::matcher::MatcherEngineOptions engine;
    sss::matcher::readMatcherEngineOptions(section, engine);
    if (!config.ok()) {
      std::fprintf(stderr, "invalid configuration %s: %s\n", config_path.c_str(), config.problemReport().c_str());
      return 2;
    }
    options = engine.pair;
  }
  const sss::matcher::DenseMatcher dense(options.dense);
  const sss::matcher::OverlapOptions overlap;
  const sss::eval::SurveyFootprints candidates = sss::eval::fullSubframeFootprints(survey, overlap);
  const std::vector<const sss::core::Subframe*>& full = candidates.subframes;
  const std::vector<sss::matcher::Footprint>& footprints = candidates.footprints;

  std::vector<double> seconds, georef, kd, init, patchmatch, consistency, pose, along_err, lateral_err;
  long accepted = 0, pairs = 0;
  using sss::eval::PairType;
  sss::eval::MatchEvaluation total, by_type[sss::eval::kPairTypes];
  long pairs_by_type[sss::eval::kPairTypes] = {0, 0, 0};
  for (size_t i = 0; i < full.size(); ++i) {
    for (size_t j = i + 1; j < full.size(); ++j) {
      const auto& a = *full[i];
      const auto& b = *full[j];
      if (a.line_id == b.line_id) continue;
      const double area = sss::matcher::overlapAreaM2(footprints[i], footprints[j]);
      if (area < overlap.min_overlap_fraction * std::min(footprints[i].area_m2, footprints[j].area_m2)) continue;
      const PairType type = sss::eval::classifyPair(a, b);
      for (int k = 0; k < repeat; ++k) {
        const auto match = sss::matcher::matchPair(a, sss::core::drPoses(a), b, sss::sim::posesWithDrError(a, b, dr_along_m, dr_lateral_m), dense,
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
        ++pairs_by_type[static_cast<int>(type)];
        const auto e =
            sss::eval::evaluateMatches(survey, a, b, match.matches, options.dense.stride, match.decimation);
        total += e;
        by_type[static_cast<int>(type)] += e;
        const Eigen::Vector3d error = match.pose.T_a_b.translation - truth.trueRelativePose(a, b).translation;
        if (match.accepted) {
          ++accepted;
          along_err.push_back(std::abs(error.x()));
          lateral_err.push_back(std::abs(error.y()));
        }
        std::printf("pair %lld-%lld (%s, lines %d-%d): %.3f s (georef %.3f, kd %.3f, init %.3f, patchmatch %.3f, "
                    "consistency %.3f, pose %.3f); %ld matches, within 2 px %.3f, recall %.3f, EPE %.2f px; %s, "
                    "error along %.3f lateral %.3f m\n",
                    (long long)a.id, (long long)b.id, sss::eval::pairTypeName(type), a.line_id, b.line_id,
                    match.seconds, match.georeference_s, match.dense_timings.kd_tree_s,
                    match.dense_timings.initialisation_s, match.dense_timings.patch_match_s,
                    match.dense_timings.consistency_s, match.pose.seconds, e.matches, e.withinFraction(), e.recall(),
                    e.meanErrorPx(), match.accepted ? "accepted" : match.reason.c_str(), error.x(), error.y());
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
  const long parallel_pairs = pairs_by_type[0], anti_pairs = pairs_by_type[1], crossing_pairs = pairs_by_type[2];
  std::printf("%ld pairs (%ld parallel, %ld anti-parallel, %ld crossing), %ld accepted; %.3f s per pair (p95 %.3f); "
              "breakdown: georeference %.3f, kd-tree %.3f, initialisation %.3f, PatchMatch %.3f, consistency %.3f, "
              "RANSAC+pose %.3f s; within 2 px %.3f, recall %.3f, EPE %.2f px; |error| p95 along %.3f lateral %.3f m\n",
              pairs, parallel_pairs, anti_pairs, crossing_pairs, accepted, mean(seconds), percentile(seconds, 0.95),
              mean(georef), mean(kd), mean(init), mean(patchmatch), mean(consistency), mean(pose),
              total.withinFraction(), total.recall(), total.meanErrorPx(), percentile(along_err, 0.95),
              percentile(lateral_err, 0.95));
  // The machine-readable last line (nlohmann: a figure that is not finite is null, never an invalid nan).
  nlohmann::ordered_json figures;
  figures["seconds_per_pair"] = mean(seconds);
  figures["seconds_p95"] = percentile(seconds, 0.95);
  figures["within_2px"] = total.withinFraction();
  figures["recall"] = total.recall();
  figures["mean_error_px"] = total.meanErrorPx();
  figures["pairs"] = pairs;
  figures["parallel_pairs"] = parallel_pairs;
  figures["anti_parallel_pairs"] = anti_pairs;
  figures["crossing_pairs"] = crossing_pairs;
  figures["accepted"] = accepted;
  figures["georeference_s"] = mean(georef);
  figures["kd_tree_s"] = mean(kd);
  figures["initialisation_s"] = mean(init);
  figures["patch_match_s"] = mean(patchmatch);
  figures["consistency_s"] = mean(consistency);
  figures["relative_pose_s"] = mean(pose);
  figures["along_error_p95_m"] = percentile(along_err, 0.95);
  figures["lateral_error_p95_m"] = percentile(lateral_err, 0.95);
  figures["matches_per_pair"] = total.matches / pairs;
  for (int t = 0; t < sss::eval::kPairTypes; ++t) {
    const auto& e = by_type[t];
    const std::string name = sss::eval::pairTypeName(static_cast<PairType>(t));
    if (pairs_by_type[t] > 0) {
      std::printf("  %-13s %3ld pairs: %ld matches, within 2 px %.3f, recall %.3f, EPE %.2f px (%.3f m)\n", name.c_str(),
                  pairs_by_type[t], e.matches, e.withinFraction(), e.recall(), e.meanErrorPx(), e.meanErrorM());
    }
    const bool seen = pairs_by_type[t] > 0;  // no pair of this type: null, not a misleading 0
    figures["within_2px_" + name] = seen ? nlohmann::ordered_json(e.withinFraction()) : nlohmann::ordered_json();
    figures["recall_" + name] = seen ? nlohmann::ordered_json(e.recall()) : nlohmann::ordered_json();
    figures["mean_error_px_" + name] = seen ? nlohmann::ordered_json(e.meanErrorPx()) : nlohmann::ordered_json();
  }
  figures["pattern"] = pattern;
  figures["dr_error_m"] = {dr_along_m, dr_lateral_m};
  std::printf("%s\n", figures.dump().c_str());
  return 0;
}
