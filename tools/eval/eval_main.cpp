// sss-eval: trajectory (ATE raw / aligned / gauge-free, RPE, per survey line, LCE), loop-closure,
// heightmap and matching accuracy against the simulator's ground truth; prints a table, writes the
// JSON report (keys in report.hpp) and PNG figures.
#include "pipeline/transport/command_line.hpp"
#include "tools/eval/report.hpp"

#include <cmath>
#include <limits>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace {

const char* kExplanation =
    "TUM lines: 'sec.usec x y z qx qy qz qw' in local NED metres (as sss-sim writes them).\n"
    "--label names the estimates in order (default: file name); the first estimate is the baseline\n"
    "  of the 'vs first' column (horizontal ATE RMSE improvement, %).\n"
    "--plot OUT.png writes OUT.png (trajectories, north/east), OUT_error.png (error over time) and\n"
    "  OUT_heightmap_<label>.png per heightmap, drawn by report_figures.py (python3-matplotlib) from\n"
    "  OUT_figure_data/; without it the JSON is still written and the exit code is 1.\n"
    "--error-map PREFIX writes PREFIX_<label>.yaml + PREFIX_<label>_depth.f32 (estimate - true\n"
    "  depth, the seabed raster format).\n"
    "Truth is interpolated at estimate times (gaps up to --max-gap-s, default 1 s); otherwise the\n"
    "  nearest truth pose within --time-tolerance-s (default 0.02 s) is used.\n"
    "--closures: each loop closure's relative pose (sss-process loop_closures.csv: dx_m dy_m dz_m =\n"
    "  B's centre in A's body frame, dheading_rad) minus the truth's at the two centre times, as along\n"
    "  (x), lateral (y), depth (z) and heading errors; RMS and max per status (accepted, rejected, ...).\n"
    "  The same for DR's relative pose: --closures-dr DR.tum, by default the first --est.\n"
    "  --closure-table also lists every closure, with its own sigmas along and across and its horizontal\n"
    "  NEES when the file carries its covariance (cov_xx_m2, cov_xy_m2, cov_yy_m2).\n"
    "Horizontal ATE is given raw, SE(3)-aligned and gauge-free: after the best rotation and scale of the\n"
    "  estimate about its first position (a heading bias and a DVL scale factor, which no relative\n"
    "  measurement sees; no shift is removed), with the fitted rotation (deg, clockwise +) and scale.\n"
    "LCE (on whenever --gt and an --est are given; --no-lce turns it off, --lce also runs it without\n"
    "  --est and fails when the truth has no survey lines, where the default only skips it):\n"
    "  landmark consistency error of the truth (a self-check, ~0) and of every --est, on\n"
    "  correspondences made from the truth: seabed points every --lce-grid-m metres, each sighted when\n"
    "  a survey line's fan plane passes over it at a ground range within --lce-swath-m MIN,MAX; two\n"
    "  sightings from different lines make a pair (at most --lce-max-pairs, thinned evenly). Flat\n"
    "  seabed at --lce-seabed-depth-m, else the mean depth of --seabed, else the truth's median depth\n"
    "  + 18 m (the simulator's default altitude); without pitch the result does not depend on it.\n"
    "--matches: the dense matches of sss-process --write-matches against the truth of the sss-sim mission\n"
    "  in --mission (rebuilt from its mission.yaml): end-point error of each match in pixels of the\n"
    "  matching image (rows = pings, columns = decimation bins) and in metres, the fraction within 2 px and\n"
    "  recall at 2 px (matches within 2 px over the matchable probe pixels, scaled to the matching grid),\n"
    "  per pair type by centre-heading difference (parallel <= 30 deg, anti-parallel >= 150 deg, else\n"
    "  crossing) and overall; bias along and bias outward: the mean signed error along B's track and\n"
    "  in ground range (positive outward: the match nearer B's track than the truth), a systematic\n"
    "  offset as against scatter; --match-table also lists every pair and round.\n"
    "Exit codes: 0 ok, 1 an output could not be written, 2 bad arguments or input files.\n";

bool endsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  sss::eval::EvalRequest request;
  sss::eval::EvalOptions options;
  std::vector<std::string> labels, heightmap_labels, estimates, heightmaps;
  sss::cli::CommandLine command_line(
      "sss-eval",
      "trajectory, loop-closure, heightmap and matching accuracy against the simulator's ground truth",
      kExplanation);
  command_line.add_option("--gt", request.truth_path, "ground truth (TUM)");
  command_line.add_option("--est", estimates, "an estimate (TUM); repeatable, the first is the baseline");
  command_line.add_option("--label", labels, "names of the estimates, in order");
  command_line.add_option("--seabed", request.seabed_path, "the true seabed (seabed.yaml)");
  command_line.add_option("--heightmap", heightmaps, "a heightmap to evaluate (YAML); repeatable");
  command_line.add_option("--heightmap-label", heightmap_labels, "names of the heightmaps, in order");
  command_line.add_option("--json", request.json_path, "write the report as JSON");
  command_line.add_option("--plot", request.plot_path, "write the figures (a name ending in .png)");
  command_line.add_option("--error-map", request.error_map_prefix, "write heightmap error maps with this prefix");
  command_line.add_option("--closures", request.closures_path, "loop_closures.csv of sss-process");
  command_line.add_option("--closures-dr", request.closures_dr_path, "DR (TUM) for the closures' DR comparison");
  command_line.add_flag("--closure-table", options.closure_table, "also list every closure");
  command_line.add_option("--matches", request.matches_path, "matches.csv of sss-process --write-matches");
  command_line.add_option("--mission", request.mission_dir, "the sss-sim mission of --matches");
  command_line.add_flag("--match-table", options.match_table, "also list every pair and round");
  bool lce = false;
  const CLI::Option* lce_flag = command_line.add_flag("--lce,!--no-lce", lce, "run LCE (--no-lce: do not)")
                                    ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);  // the last one wins
  bool interpolate = true;
  command_line.add_flag("!--no-interpolation", interpolate, "nearest truth pose instead of interpolation");
  command_line.add_option("--time-tolerance-s", options.trajectory.association.max_time_difference_s,
                          "nearest-pose tolerance")
      ->check(sss::cli::nonNegative())
      ->capture_default_str();
  command_line.add_option("--max-gap-s", options.trajectory.association.max_interpolation_gap_s,
                          "largest truth gap interpolated over")
      ->check(sss::cli::nonNegative())
      ->capture_default_str();
  command_line.add_option("--rpe-windows-m", options.trajectory.rpe.windows_m, "RPE windows, e.g. 10,50,100")
      ->delimiter(',')
      ->check(sss::cli::positive());
  sss::cli::addIncreasingPair(command_line, "--lce-swath-m", options.lce.min_ground_range_m,
                              options.lce.max_ground_range_m, "MIN,MAX ground ranges of LCE sightings, e.g. 10,70",
                              sss::cli::nonNegative());
  command_line.add_option("--lce-grid-m", options.lce.grid_m, "LCE seabed point spacing")
      ->check(CLI::Range(0.1, 1e6))
      ->capture_default_str();
  command_line.add_option("--lce-max-pairs", options.lce.max_correspondences, "LCE pairs at most")
      ->check(CLI::Range(size_t{1}, std::numeric_limits<size_t>::max()))
      ->capture_default_str();
  command_line.add_option("--lce-seabed-depth-m", options.lce_seabed_depth_m, "flat seabed depth for LCE")
      ->check(sss::cli::nonNegative());
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  options.trajectory.association.interpolate_truth = interpolate;
  const bool lce_given = lce_flag->count() > 0;
  // LCE by default with a truth and an estimate: it is the metric of what side-scan can see.
  request.lce = (lce_given && lce) || (!lce_given && !request.truth_path.empty() && !estimates.empty());
  request.lce_optional = !lce_given;
  if (estimates.empty() && heightmaps.empty() && request.closures_path.empty() && !request.lce &&
      request.matches_path.empty()) {
    std::cerr << "sss-eval: nothing to evaluate: give --gt TRUTH.tum with --est EST.tum, --closures C.csv or --lce,\n"
                 "  and/or --seabed S.yaml --heightmap H.yaml, and/or --matches M.csv --mission DIR\n"
              << command_line.help();
    return 2;
  }
  if (request.matches_path.empty() != request.mission_dir.empty()) {
    std::cerr << "sss-eval: --matches matches.csv and --mission MISSION_DIR go together (the truth comes from the mission)\n";
    return 2;
  }
  if ((!estimates.empty() || !request.closures_path.empty() || request.lce) && request.truth_path.empty()) {
    std::cerr << "sss-eval: --est, --closures and --lce need --gt TRUTH.tum\n";
    return 2;
  }
  if (!request.closures_dr_path.empty() && request.closures_path.empty()) {
    std::cerr << "sss-eval: --closures-dr needs --closures loop_closures.csv\n";
    return 2;
  }
  if (!heightmaps.empty() && request.seabed_path.empty()) {
    std::cerr << "sss-eval: --heightmap needs --seabed seabed.yaml (the true seabed)\n";
    return 2;
  }
  if (labels.size() > estimates.size() || heightmap_labels.size() > heightmaps.size()) {
    std::cerr << "sss-eval: more --label (" << labels.size() << ") or --heightmap-label (" << heightmap_labels.size()
              << ") than --est (" << estimates.size() << ") or --heightmap (" << heightmaps.size() << ")\n";
    return 2;
  }
  if (!request.plot_path.empty() && !endsWith(request.plot_path, ".png")) {
    std::cerr << "sss-eval: --plot expects a file name ending in .png, got '" << request.plot_path << "'\n";
    return 2;
  }
  for (size_t k = 0; k < estimates.size(); ++k) request.estimates.push_back({k < labels.size() ? labels[k] : "", estimates[k]});
  for (size_t k = 0; k < heightmaps.size(); ++k) {
    request.heightmaps.push_back({k < heightmap_labels.size() ? heightmap_labels[k] : "", heightmaps[k]});
  }

  // Output folders are created as needed (like sss-sim --out).
  for (const std::string& output : {request.json_path, request.plot_path, request.error_map_prefix}) {
    const std::filesystem::path parent = std::filesystem::path(output).parent_path();
    std::error_code ec;
    if (!output.empty() && !parent.empty()) std::filesystem::create_directories(parent, ec);
    if (ec) {
      std::cerr << "sss-eval: cannot create " << parent.string() << ": " << ec.message() << "\n";
      return 1;
    }
  }

  try {
    sss::eval::EvalReport report;
    if (const sss::core::Status evaluated = sss::eval::runEvaluation(request, options, report); !evaluated) {
      std::cerr << "sss-eval: " << evaluated.message << "\n";
      return 2;
    }
    if (!request.matches_path.empty()) {
      // Apart from runEvaluation: it needs the simulator to rebuild the truth.
      if (const sss::core::Status evaluated =
              sss::eval::evaluateMatchFile(request.matches_path, request.mission_dir, report.matches);
          !evaluated) {
        std::cerr << "sss-eval: " << evaluated.message << "\n";
        return 2;
      }
      report.has_matches = true;
    }
    std::cout << sss::eval::formatTable(report);
    // Without figures (e.g. no python3-matplotlib) the JSON is still written; the exit code says 1.
    std::string figures_error;
    if (const sss::core::Status drawn = sss::eval::writeFigures(request, report); !drawn) figures_error = drawn.message;
    if (!request.json_path.empty()) {
      report.json_path = request.json_path;
      std::ofstream out(request.json_path, std::ios::binary);
      out << sss::eval::reportJson(report);
      out.close();
      if (!out) {
        std::cerr << "sss-eval: cannot write " << request.json_path << "; check the directory exists and is writable\n";
        return 1;
      }
    }
    for (const std::string& plot : report.plots) std::cout << "wrote " << plot << "\n";
    if (!request.json_path.empty()) std::cout << "wrote " << request.json_path << "\n";
    if (!figures_error.empty()) {
      std::cerr << "sss-eval: " << figures_error << "\n";
      return 1;
    }
  } catch (const std::bad_alloc&) {
    std::cerr << "sss-eval: out of memory; are the inputs the right files?\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "sss-eval: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
