// sss-bench-optimiser-checkpoint: an H-hour lawnmower of subframes (200 ping poses each) and
// closures (with correspondences, each pair delivered in R association rounds) fed to the optimiser
// engine, one update and one checkpoint save per subframe, as sss-optimiser does. Prints, per hour,
// the checkpoint's size (rewritten file + journal) and save times, and what a full rewrite of
// everything would cost at that point; a JSON summary last.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/transport/command_line.hpp"
#include "pipeline/optimiser/optimiser_engine.hpp"
#include "tools/fixtures/synthetic_subframes.hpp"

namespace {

using namespace sss::optimiser;

double fileBytes(const std::string& path) {
  struct stat s {};
  return ::stat(path.c_str(), &s) == 0 ? static_cast<double>(s.st_size) : 0.0;
}

double seconds(const std::chrono::steady_clock::time_point& since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, static_cast<size_t>(std::ceil(p * values.size())) - 1)];
}

struct HourFigures {
  double hours = 0.0;
  double file_mb = 0.0, journal_mb = 0.0;
  double save_p50_ms = 0.0, save_max_ms = 0.0;  // saves during that hour
  double graph_text_ms = 0.0;                   // formatting the graph's text alone (no I/O)
  double full_rewrite_ms = 0.0;                 // everything written anew at the end of that hour
  double load_ms = 0.0;
};

}  // namespace

int main(int argc, char** argv) {
  double hours = 3.0;
  int rounds = 2;
  std::string dir = "/tmp";
  synthetic::SubframeOptions subframe_options;
  subframe_options.correspondences_per_closure = 3000;
  sss::cli::CommandLine command_line(
      "sss-bench-optimiser-checkpoint",
      "an H-hour lawnmower of 2 km lines, 100 m subframes of 200 pings, closures between neighbouring lines with N "
      "correspondences, each pair sent in R association rounds; times and sizes of the optimiser's checkpoints");
  command_line.add_option("--hours", hours, "mission length")->check(sss::cli::positive())->capture_default_str();
  command_line.add_option("--correspondences", subframe_options.correspondences_per_closure,
                          "correspondences per closure (the bathymetry's max_points_per_closure)")
      ->check(sss::cli::nonNegative())
      ->capture_default_str();
  command_line.add_option("--rounds", rounds, "association rounds per pair")->check(sss::cli::positive())
      ->capture_default_str();
  command_line.add_option("--dir", dir, "checkpoint folder")->capture_default_str();
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;

  synthetic::MissionOptions mission_options;
  mission_options.line_length_m = 2000.0;
  mission_options.heading_bias_rad = 0.0005;
  mission_options.velocity_scale_error = 0.001;
  const double line_time_s =
      (mission_options.line_length_m + M_PI * 0.5 * mission_options.line_spacing_m) / mission_options.speed_m_s;
  mission_options.num_lines = std::max(2, static_cast<int>(std::ceil(hours * 3600.0 / line_time_s)));
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(mission_options);
  std::vector<std::vector<sss::core::Pose>> truth;
  const std::vector<sss::core::Subframe> subframes = synthetic::makeSubframes(mission, subframe_options, &truth);

  OptimiserEngineOptions options;
  options.graph.window_size = 45;  // as sss-bench-optimiser: two 2 km lines
  OptimiserEngine engine(options);
  const std::string path = dir + "/sss-bench-checkpoint-" + std::to_string(::getpid()) + ".checkpoint";
  const std::string full_path = path + ".full";
  std::printf("mission: %.1f h, %d lines, %zu subframes, %zu closures x %d rounds, %d correspondences each\n", hours,
              mission_options.num_lines, subframes.size(), mission.closures.size(), rounds,
              subframe_options.correspondences_per_closure);
  std::printf("%6s %9s %11s %12s %12s %14s %16s %9s\n", "hours", "file_MB", "journal_MB", "save_p50_ms",
              "save_max_ms", "graph_text_ms", "full_rewrite_ms", "load_ms");

  std::vector<HourFigures> figures;
  std::vector<double> save_ms;  // this hour's
  std::vector<double> all_save_ms;
  int next_hour = 1;
  const int64_t start_utime_us = mission.nodes.front().utime_us;
  // Round r of a closure arrives r subframes after round 0 (re-association with newer poses).
  std::vector<std::vector<std::pair<size_t, int>>> arrivals(subframes.size() + rounds);
  for (size_t c = 0; c < mission.closures.size(); ++c)
    for (int r = 0; r < rounds; ++r) arrivals[mission.closures[c].newer_node + r].push_back({c, r});
  for (size_t i = 0; i < subframes.size(); ++i) {
    if (const Status added = engine.addSubframe(subframes[i]); !added.ok) {
      std::fprintf(stderr, "%s\n", added.message.c_str());
      return 1;
    }
    // A later round of a pair whose first is marginalised is refused, as live: not an error.
    for (const auto& [c, r] : arrivals[i])
      static_cast<void>(engine.addLoopClosure(synthetic::makeMatcherClosure(mission, c, truth, subframe_options, r)));
    engine.update();
    const auto t0 = std::chrono::steady_clock::now();
    const Status saved = engine.saveCheckpoint(path);
    save_ms.push_back(1e3 * seconds(t0));
    all_save_ms.push_back(save_ms.back());
    if (!saved.ok) {
      std::fprintf(stderr, "%s\n", saved.message.c_str());
      return 1;
    }
    const double mission_h = 1e-6 * static_cast<double>(subframes[i].pings.back().utime_us - start_utime_us) / 3600.0;
    if (mission_h < next_hour && i + 1 < subframes.size()) continue;
    HourFigures f;
    f.hours = mission_h;
    f.file_mb = fileBytes(path) / 1e6;
    f.journal_mb = fileBytes(path + ".journal") / 1e6;
    f.save_p50_ms = percentile(save_ms, 0.5);
    f.save_max_ms = percentile(save_ms, 1.0);
    const auto t3 = std::chrono::steady_clock::now();
    const size_t graph_bytes = engine.graph().checkpointText().size();
    f.graph_text_ms = 1e3 * seconds(t3);
    (void)graph_bytes;
    OptimiserEngine copy = engine;  // a save to another path writes everything anew
    const auto t1 = std::chrono::steady_clock::now();
    if (const Status rewritten = copy.saveCheckpoint(full_path); !rewritten.ok) {
      std::fprintf(stderr, "%s\n", rewritten.message.c_str());
      return 1;
    }
    f.full_rewrite_ms = 1e3 * seconds(t1);
    OptimiserEngine loaded(options);
    const auto t2 = std::chrono::steady_clock::now();
    const Status load = loaded.loadCheckpoint(path);
    f.load_ms = 1e3 * seconds(t2);
    if (!load.ok) std::fprintf(stderr, "%s\n", load.message.c_str());
    std::printf("%6.2f %9.2f %11.2f %12.2f %12.2f %14.2f %16.1f %9.1f\n", f.hours, f.file_mb, f.journal_mb,
                f.save_p50_ms, f.save_max_ms, f.graph_text_ms, f.full_rewrite_ms, f.load_ms);
    figures.push_back(f);
    save_ms.clear();
    ++next_hour;
  }
  for (const std::string& p : {path, path + ".journal", full_path, full_path + ".journal"}) std::remove(p.c_str());

  // Non-finite figures (no save measured) are null, so that the line stays valid JSON.
  auto number = [](double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); };
  nlohmann::ordered_json summary;
  summary["saves"] = all_save_ms.size();
  summary["save_p50_ms"] = number(percentile(all_save_ms, 0.5));
  summary["save_p95_ms"] = number(percentile(all_save_ms, 0.95));
  summary["save_max_ms"] = number(percentile(all_save_ms, 1.0));
  summary["hours"] = nlohmann::ordered_json::array();
  for (const HourFigures& f : figures) {
    nlohmann::ordered_json hour;
    hour["h"] = number(f.hours);
    hour["file_mb"] = number(f.file_mb);
    hour["journal_mb"] = number(f.journal_mb);
    hour["save_p50_ms"] = number(f.save_p50_ms);
    hour["save_max_ms"] = number(f.save_max_ms);
    hour["graph_text_ms"] = number(f.graph_text_ms);
    hour["full_rewrite_ms"] = number(f.full_rewrite_ms);
    hour["load_ms"] = number(f.load_ms);
    summary["hours"].push_back(hour);
  }
  std::printf("%s\n", summary.dump().c_str());
  return 0;
}
