// sss-bench-optimiser: an 8-hour lawnmower mission fed to the sliding-window pose graph node by
// node; prints window update times (p50/p95/max) and RSS over time, and a JSON summary last.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/transport/command_line.hpp"
#include "pipeline/optimiser/pose_graph.hpp"
#include "tools/fixtures/synthetic_mission.hpp"

namespace {

using namespace sss::optimiser;

double rssMiB() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;  // kB
  }
  return -1.0;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t index = std::min(values.size() - 1, static_cast<size_t>(std::ceil(p * values.size())) - 1);
  return values[index];
}

std::vector<sss::core::Pose> estimates(const SlidingWindowPoseGraph& graph) {
  std::vector<sss::core::Pose> out;
  for (const NodeState& n : graph.nodes()) out.push_back(n.T_world_body);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  double hours = 8.0;
  bool full_smoothing = true;
  synthetic::MissionOptions mission_options;
  mission_options.line_length_m = 2000.0;
  mission_options.false_fraction = 0.03;
  // Over hours a steaming error of 0.2 deg would drift hundreds of metres; an INS with DVL aiding
  // keeps about 0.1 % of distance travelled.
  mission_options.heading_bias_rad = 0.0005;
  mission_options.velocity_scale_error = 0.001;
  PoseGraphOptions options;
  options.window_size = 45;  // two 2 km lines of 20 subframes: adjacent-line closures stay inside
  sss::cli::CommandLine command_line(
      "sss-bench-optimiser",
      "simulates an H-hour lawnmower with 100 m subframes and closures between neighbouring lines (a fraction "
      "false), feeds it node by node to the window, prints update times and RSS, then a JSON summary");
  command_line.add_option("--hours", hours, "mission length")->check(sss::cli::positive())->capture_default_str();
  command_line.add_option("--line-length-m", mission_options.line_length_m, "line length")
      ->check(sss::cli::positive())
      ->capture_default_str();
  command_line.add_option("--window", options.window_size, "window size (nodes)")->capture_default_str();
  command_line.add_option("--false-fraction", mission_options.false_fraction, "fraction of false closures")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  command_line.add_option("--seed", mission_options.seed, "seed")->capture_default_str();
  bool no_full_smoothing = false;
  command_line.add_flag("--no-full-smoothing", no_full_smoothing, "no end-of-mission smoothing");
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  full_smoothing = !no_full_smoothing;
  if (const std::vector<std::string> problems = validatePoseGraphOptions(options); !problems.empty()) {
    std::fprintf(stderr, "sss-bench-optimiser: %s\n", problems.front().c_str());
    return 2;
  }
  const double line_time_s =
      (mission_options.line_length_m + M_PI * 0.5 * mission_options.line_spacing_m) / mission_options.speed_m_s;
  mission_options.num_lines = std::max(2, static_cast<int>(std::ceil(hours * 3600.0 / line_time_s)));
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(mission_options);
  int num_false = 0;
  for (const auto& c : mission.closures) num_false += c.is_false ? 1 : 0;
  std::printf("mission: %.1f h, %d lines of %.0f m, %zu nodes, %zu closures (%d false), window %d\n", hours,
              mission_options.num_lines, mission_options.line_length_m, mission.nodes.size(), mission.closures.size(),
              num_false, options.window_size);

  SlidingWindowPoseGraph graph(options);
  std::vector<double> update_s, solve_s;
  const double rss_start_mib = rssMiB();
  std::printf("update = decisions + Ceres solve + marginalisation + covariance; solve = Ceres alone\n");
  std::printf("%8s %8s %10s %10s %10s %10s %9s %7s %9s\n", "updates", "nodes", "upd_p50_s", "upd_p95_s", "upd_max_s",
              "solve_p95_s", "rss_mib", "window", "prior_dim");
  size_t next_closure = 0;
  const size_t report_every = std::max<size_t>(1, mission.nodes.size() / 8);
  for (size_t i = 0; i < mission.nodes.size(); ++i) {
    const synthetic::Node& n = mission.nodes[i];
    if (const Status added = graph.addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m); !added.ok) {
      std::fprintf(stderr, "%s\n", added.message.c_str());
      return 1;
    }
    while (next_closure < mission.closures.size() && mission.closures[next_closure].newer_node == static_cast<int>(i)) {
      const Status added = graph.addLoopClosure(mission.closures[next_closure++].closure);
      if (!added.ok) {
        std::fprintf(stderr, "%s\n", added.message.c_str());
        return 1;
      }
    }
    const UpdateReport report = graph.optimize();
    update_s.push_back(report.update_s);
    solve_s.push_back(report.solve_s);
    if ((i + 1) % report_every == 0 || i + 1 == mission.nodes.size()) {
      // Statistics of the updates since the previous line: flat columns mean bounded cost.
      const size_t count = std::min(update_s.size(), report_every);
      const std::vector<double> recent(update_s.end() - count, update_s.end());
      const std::vector<double> recent_solve(solve_s.end() - count, solve_s.end());
      std::printf("%8zu %8zu %10.4f %10.4f %10.4f %10.4f %9.1f %7d %9d\n", update_s.size(), graph.numNodes(),
                  percentile(recent, 0.5), percentile(recent, 0.95), percentile(recent, 1.0),
                  percentile(recent_solve, 0.95), rssMiB(), graph.windowStats().active_nodes,
                  graph.windowStats().prior_rows);
    }
  }
  const double rss_end_mib = rssMiB();
  const double ate_dr = synthetic::translationRmse(synthetic::drPoses(mission), mission.nodes);
  const double ate_window = synthetic::translationRmse(estimates(graph), mission.nodes);
  const PoseGraphCounters& k = graph.counters();
  int false_accepted = 0, true_rejected = 0;
  const std::vector<ClosureRecord> records = graph.closures();
  for (size_t c = 0; c < records.size() && c < mission.closures.size(); ++c) {
    const bool accepted = records[c].status == ClosureStatus::kAccepted;
    false_accepted += mission.closures[c].is_false && accepted ? 1 : 0;
    true_rejected += !mission.closures[c].is_false && !accepted ? 1 : 0;
  }
  std::printf("closures: %llu accepted, %llu gate, %llu inconsistent, %llu no support; %d false accepted, %d true "
              "not accepted\n",
              static_cast<unsigned long long>(k.closures_accepted), static_cast<unsigned long long>(k.closures_rejected_gate),
              static_cast<unsigned long long>(k.closures_rejected_inconsistent),
              static_cast<unsigned long long>(k.closures_rejected_no_support), false_accepted, true_rejected);
  double full_s = 0.0, ate_full = ate_window;
  if (full_smoothing) {
    const UpdateReport report = graph.fullSmoothing();
    full_s = report.update_s;
    ate_full = synthetic::translationRmse(estimates(graph), mission.nodes);
    std::printf("full smoothing: %.3f s, %d iterations\n", full_s, report.iterations);
  }
  if (full_smoothing)
    std::printf("ATE: DR %.2f m, window %.2f m, full smoothing %.2f m\n", ate_dr, ate_window, ate_full);
  else
    std::printf("ATE: DR %.2f m, window %.2f m (full smoothing skipped)\n", ate_dr, ate_window);
  // Non-finite figures (full smoothing skipped) are null, so that the line stays valid JSON.
  auto number = [](double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); };
  nlohmann::ordered_json figures;
  figures["updates"] = update_s.size();
  figures["nodes"] = graph.numNodes();
  figures["closures"] = mission.closures.size();
  figures["false_closures"] = num_false;
  figures["false_accepted"] = false_accepted;
  figures["window"] = options.window_size;
  figures["update_p50_s"] = number(percentile(update_s, 0.5));
  figures["update_p95_s"] = number(percentile(update_s, 0.95));
  figures["update_max_s"] = number(percentile(update_s, 1.0));
  figures["solve_p50_s"] = number(percentile(solve_s, 0.5));
  figures["solve_p95_s"] = number(percentile(solve_s, 0.95));
  figures["solve_max_s"] = number(percentile(solve_s, 1.0));
  figures["rss_start_mib"] = number(rss_start_mib);
  figures["rss_end_mib"] = number(rss_end_mib);
  figures["ate_dr_m"] = number(ate_dr);
  figures["ate_opt_m"] = number(ate_window);
  figures["ate_full_m"] = number(ate_full);
  figures["full_smoothing_s"] = number(full_s);
  std::printf("%s\n", figures.dump().c_str());
  return 0;
}
