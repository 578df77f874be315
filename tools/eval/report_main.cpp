// sss-report: one page per run (index.html + report.md + metrics.json + figures) saying whether
// SLAM made the navigation better than dead reckoning; see tools/eval/run_report.hpp.
#include "tools/eval/run_report.hpp"

#include <iostream>
#include <string>

namespace {

const char* kUsage =
    "usage: sss-report --mission MISSION_DIR --run RUN_DIR --out REPORT_DIR [--title TEXT]\n"
    "MISSION_DIR: the sss-sim --out folder (ground_truth.tum; seabed.yaml and mosaic.yaml when present).\n"
    "RUN_DIR: the sss-process output (slam.tum; dead_reckoning.tum, loop_closures.csv, heightmap.yaml,\n"
    "  heightmap_dr.yaml, mosaic_dr.yaml, mosaic_slam.yaml, summary.json when present).\n"
    "Writes REPORT_DIR/index.html, report.md, metrics.json and PNG figures; prints a short table.\n"
    "Missing optional inputs leave their section out with a note.\n"
    "Exit codes: 0 ok, 1 an output could not be written, 2 bad arguments or a missing/bad required input.\n";

}  // namespace

int main(int argc, char** argv) {
  sss::eval::RunReportRequest request;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      return 0;
    }
    if (arg.rfind("--", 0) != 0 || i + 1 >= argc) {
      std::cerr << "sss-report: unexpected argument '" << arg << "' (or a flag without its value)\n" << kUsage;
      return 2;
    }
    const std::string value = argv[++i];
    if (arg == "--mission") request.mission_dir = value;
    else if (arg == "--run") request.run_dir = value;
    else if (arg == "--out") request.out_dir = value;
    else if (arg == "--title") request.title = value;
    else {
      std::cerr << "sss-report: unknown flag " << arg << "\n" << kUsage;
      return 2;
    }
  }
  if (request.mission_dir.empty() || request.run_dir.empty() || request.out_dir.empty()) {
    std::cerr << "sss-report: --mission, --run and --out are required\n" << kUsage;
    return 2;
  }
  const sss::eval::RunReport report = sss::eval::writeRunReport(request);
  if (report.status != sss::eval::RunReportStatus::ok) {
    std::cerr << "sss-report: " << report.error << "\n";
    return report.status == sss::eval::RunReportStatus::bad_input ? 2 : 1;
  }
  std::cout << sss::eval::formatRunTable(report);
  for (const std::string& note : report.notes) std::cerr << "sss-report: note: " << note << "\n";
  return 0;
}
