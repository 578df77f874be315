// sss-report: one page per run (index.html + report.md + metrics.json + figures) saying whether
// SLAM made the navigation better than dead reckoning; see tools/eval/run_report.hpp.
#include "pipeline/transport/command_line.hpp"
#include "tools/eval/run_report.hpp"

#include <iostream>
#include <string>

namespace {

const char* kExplanation =
    "MISSION_DIR: the sss-sim --out folder (ground_truth.tum; seabed.yaml and mosaic.yaml when present).\n"
    "RUN_DIR: the sss-process output (slam.tum; dead_reckoning.tum, loop_closures.csv, heightmap.yaml,\n"
    "  heightmap_dr.yaml, mosaic_dr.yaml, mosaic_slam.yaml, summary.json when present).\n"
    "Writes REPORT_DIR/index.html, report.md, metrics.json and PNG figures; prints a short table.\n"
    "Missing optional inputs leave their section out with a note.\n"
    "Exit codes: 0 ok, 1 an output could not be written, 2 bad arguments or a missing/bad required input.\n";

}  // namespace

int main(int argc, char** argv) {
  sss::eval::RunReportRequest request;
  sss::cli::CommandLine command_line("sss-report",
                                     "one page per run saying whether SLAM made the navigation better than dead reckoning",
                                     kExplanation);
  command_line.add_option("--mission", request.mission_dir, "the sss-sim --out folder")->required();
  command_line.add_option("--run", request.run_dir, "the sss-process --out folder")->required();
  command_line.add_option("--out", request.out_dir, "report folder")->required();
  command_line.add_option("--title", request.title, "page title");
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  const sss::eval::RunReport report = sss::eval::writeRunReport(request);
  if (report.status != sss::eval::RunReportStatus::ok) {
    std::cerr << "sss-report: " << report.error << "\n";
    return report.status == sss::eval::RunReportStatus::bad_input ? 2 : 1;
  }
  std::cout << sss::eval::formatRunTable(report);
  for (const std::string& note : report.notes) std::cerr << "sss-report: note: " << note << "\n";
  return 0;
}
