// sss-bench-dense-matcher: dense matching speed and accuracy on simulated lawnmower subframe pairs
// (the matcher's acceptance size: 200 pings x 2x1300 bins), parallel and anti-parallel; last line is one JSON object.
#include <nlohmann/json.hpp>

#include <cmath>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "pipeline/transport/command_line.hpp"
#include "pipeline/matcher/dense_matcher.hpp"
#include "tools/fixtures/synthetic_pair.hpp"

namespace {

}  // namespace

int main(int argc, char** argv) {
  using namespace sss::matcher;
  int repeats = 2;
  double dr_error_m = 5.0;
  DenseMatcherOptions options;
  sss::cli::CommandLine command_line(
      "sss-bench-dense-matcher",
      "matches one parallel and one anti-parallel simulated pair per repeat with a DR error between the lines and "
      "prints timings, accuracy and a JSON summary");
  command_line.add_option("--repeats", repeats, "pairs of each direction")->check(sss::cli::positive())
      ->capture_default_str();
  command_line.add_option("--dr-error-m", dr_error_m, "DR error between the lines")->check(sss::cli::nonNegative())
      ->capture_default_str();
  command_line.add_option("--threads", options.threads, "matcher threads")->check(sss::cli::positive())
      ->capture_default_str();
  command_line.add_option("--stride", options.stride, "probe stride")->check(sss::cli::positive())->capture_default_str();
  command_line.add_option("--iterations", options.iterations, "PatchMatch iterations")->check(sss::cli::positive())
      ->capture_default_str();
  bool no_forward_backward = false;
  command_line.add_flag("--no-fb", no_forward_backward, "no forward-backward check");
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  if (no_forward_backward) options.forward_backward_check = false;
  const DenseMatcher matcher(options);

  synthetic::Seabed seabed;
  seabed.seed = 7;
  synthetic::SurveyLine line_a;  // 200 pings, 2 x 1300 bins of 0.13 m, 2 m/s at 4 Hz
  double seconds = 0.0, kd_tree = 0.0, initialisation = 0.0, patch_match = 0.0, consistency = 0.0;
  long matches = 0, within = 0, matchable = 0;
  int pairs = 0;
  for (int repeat = 0; repeat < repeats; ++repeat) {
    for (const auto direction : {synthetic::Direction::kParallel, synthetic::Direction::kAntiParallel}) {
      // Lines 150 m apart: about 55% overlap of the 338 m swath.
      const synthetic::SurveyLine line_b = synthetic::secondLine(line_a, direction, 150.0, 3.0 + repeat);
      synthetic::RenderOptions render_a, render_b;
      render_a.speckle_seed = 100 + repeat;
      render_b.speckle_seed = 200 + repeat;
      render_b.gain = 1.3;
      GeoImage a = synthetic::render(seabed, line_a, render_a);
      GeoImage b = synthetic::render(seabed, line_b, render_b);
      // DR error between the lines: dr_error_m at an angle mixing along- and across-track.
      synthetic::addDrError(a, {0.5, -0.3}, 0.001);
      synthetic::addDrError(b, {0.5 + dr_error_m * 0.6, -0.3 + dr_error_m * 0.8}, -0.004);
      MatchTimings t;
      const std::vector<Correspondence> result = matcher.match(a, b, &t);
      const synthetic::Evaluation e =
          synthetic::evaluate(result, line_a, a, line_b, b, options.stride, options.patch_size, 2.0);
      std::printf("%-13s total %.3f s (kd-tree %.3f, init %.3f, patchmatch %.3f, consistency %.3f) "
                  "overlap %ld, matches %ld, within 2 px %.3f, recall %.3f\n",
                  direction == synthetic::Direction::kParallel ? "parallel" : "anti-parallel", t.total_s, t.kd_tree_s,
                  t.initialisation_s, t.patch_match_s, t.consistency_s, t.overlapping_pixels, e.matches,
                  e.withinFraction(), e.recall());
      seconds += t.total_s;
      kd_tree += t.kd_tree_s;
      initialisation += t.initialisation_s;
      patch_match += t.patch_match_s;
      consistency += t.consistency_s;
      matches += e.matches;
      within += e.within_tolerance;
      matchable += e.matchable;
      ++pairs;
    }
  }
  const double n = pairs > 0 ? pairs : 1;
  // The machine-readable last line (nlohmann: a figure that is not finite is null, never an invalid nan).
  nlohmann::ordered_json figures;
  figures["seconds_per_pair"] = seconds / n;
  figures["within_2px"] = matches ? double(within) / matches : 0.0;
  figures["recall"] = matchable ? double(within) / matchable : 0.0;
  figures["pairs"] = pairs;
  figures["kd_tree_s"] = kd_tree / n;
  figures["initialisation_s"] = initialisation / n;
  figures["patch_match_s"] = patch_match / n;
  figures["consistency_s"] = consistency / n;
  figures["matches_per_pair"] = std::round(matches / n);
  figures["dr_error_m"] = dr_error_m;
  figures["threads"] = options.threads;
  figures["stride"] = options.stride;
  std::printf("%s\n", figures.dump().c_str());
  return 0;
}
