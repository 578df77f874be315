// sss-report end to end: a short simulated mission and a run folder fabricated from it with known
// errors (SLAM 0.1 m north of the truth, heightmaps 0.05 m and 0.3 m too deep, 3 + 1 closures) ->
// exit code, files, metrics.json numbers, the verdict; missing required and optional inputs.
#include "pipeline/core/geodesy.hpp"
#include "tools/eval/frame_alignment.hpp"
#include "tools/eval/heightmap_metrics.hpp"
#include "tools/eval/run_report.hpp"
#include "tools/eval/trajectory_io.hpp"
#include "tools/sim/mission.hpp"
#include "tests/support/run_program.hpp"
#include "tests/support/status_assertions.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#ifndef SSS_REPORT_PATH
#error "SSS_REPORT_PATH must name the sss-report executable"
#endif

namespace sss::eval {
namespace {

namespace fs = std::filesystem;

using sss::testing::ProgramRun, sss::testing::slurp;

const std::vector<std::string> kFigures = {"trajectories.png",    "error_over_time.png",   "loop_closures.png",
                                           "mosaics_dr_slam.png", "heightmap_slam.png",    "heightmap_error_dr.png",
                                           "heightmap_error_slam.png"};

class RunReport : public ::testing::Test {
 protected:
  // One mission for every test: 2 lines of 120 m (both long enough to count as survey lines),
  // few samples; DR drift x10 so DR's error (metres) dwarfs the 0.1 m given to SLAM.
  static void SetUpTestSuite() {
    mission_dir_ = fs::temp_directory_path() / ("sss_run_report_mission_" + std::to_string(::getpid()));
    fs::remove_all(mission_dir_);
    sim::SimOptions options;
    options.seed = 4;
    options.trajectory.lines = 2;
    options.trajectory.line_length_m = 120.0;
    options.trajectory.line_spacing_m = 40.0;
    options.sonar.samples_per_side = 500;
    options.waterfall_bins_per_side = 250;
    options.seabed.resolution_m = 0.3;
    options.dead_reckoning.drift_scale = 10.0;
    sim::MissionReport report;
    ASSERT_OK(sim::writeMission(sim::Mission(options), mission_dir_.string(), report));
  }
  static void TearDownTestSuite() { fs::remove_all(mission_dir_); }

  void SetUp() override {
    ASSERT_TRUE(fs::exists(mission_dir_ / "ground_truth.tum"));
    dir_ = fs::temp_directory_path() / ("sss_run_report_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(run_dir());
    fabricateRun(0.1);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path run_dir() const { return dir_ / "run"; }
  fs::path out_dir() const { return dir_ / "report"; }

  // The run folder sss-process would write, with known errors.
  void fabricateRun(double slam_north_offset_m) {
    std::string error;
    fs::copy_file(mission_dir_ / "dead_reckoning.tum", run_dir() / "dead_reckoning.tum", fs::copy_options::overwrite_existing);
    const TumReadResult truth = readTum((mission_dir_ / "ground_truth.tum").string());
    ASSERT_TRUE(truth.ok) << truth.error;
    Trajectory slam = truth.poses;
    for (StampedPose& p : slam) p.T_world_body.translation.x() += slam_north_offset_m;
    ASSERT_OK(writeTum((run_dir() / "slam.tum").string(), slam));

    // Heightmaps on every other seabed cell (cell centres coincide, so bilinear sampling is exact).
    HeightmapRaster seabed;
    ASSERT_OK(readHeightmap((mission_dir_ / "seabed.yaml").string(), seabed));
    HeightmapRaster coarse;
    coarse.rows = seabed.rows / 2;
    coarse.cols = seabed.cols / 2;
    coarse.resolution_m = 2.0 * seabed.resolution_m;
    coarse.north_min_m = seabed.north_min_m;
    coarse.east_min_m = seabed.east_min_m;
    for (int r = 0; r < coarse.rows; ++r) {
      for (int c = 0; c < coarse.cols; ++c) coarse.depth_m.push_back(seabed.at(2 * r, 2 * c));
    }
    for (const auto& [name, offset_m] : {std::pair{"heightmap", 0.05f}, std::pair{"heightmap_dr", 0.3f}}) {
      HeightmapRaster estimate = coarse;
      for (float& depth : estimate.depth_m) depth += offset_m;
      ASSERT_OK(writeHeightmap((run_dir() / name).string(), estimate));
    }
    for (const char* name : {"mosaic_dr", "mosaic_slam"}) {
      fs::copy_file(mission_dir_ / "mosaic.png", run_dir() / (std::string(name) + ".png"), fs::copy_options::overwrite_existing);
      fs::copy_file(mission_dir_ / "mosaic.yaml", run_dir() / (std::string(name) + ".yaml"), fs::copy_options::overwrite_existing);
    }

    // Closures between subframe centres on the two lines (line 0 at east 0, line 1 at east 40).
    std::ofstream csv(run_dir() / "loop_closures.csv");
    csv << "# fabricated by run_report_test\n"
           "subframe_id_a,subframe_id_b,utime_a_us,utime_b_us,round,status,rejection,dx_m,dy_m,dz_m,droll_rad,"
           "dpitch_rad,dheading_rad,num_inliers,mean_zncc,north_a_m,east_a_m,north_b_m,east_b_m\n"
           "0,3,1780300800000000,1780300900000000,0,accepted,none,0.1,0,0,0,0,0,900,0.6,25,0,95,40\n"
           "1,2,1780300850000000,1780300870000000,0,accepted,none,0.1,0,0,0,0,0,800,0.6,75,0,45,40\n"
           "1,3,1780300850000000,1780300900000000,1,accepted,none,0.1,0,0,0,0,0,700,0.6,75,0,95,40\n"
           "0,2,1780300800000000,1780300870000000,0,rejected,chi_square_gate,3,0,0,0,0,0,90,0.3,25,0,45,40\n";
    csv.close();
    std::ofstream summary(run_dir() / "summary.json");
    summary << "{\"pings\": " << truth.poses.size()
            << ", \"subframes\": 4, \"pairs_attempted\": 6, \"closures_accepted\": 3, \"closures_rejected\": 1,\n"
               " \"wall_s\": 12.5, \"mission_s\": 150.0, \"real_time_factor\": 12.0, \"peak_rss_mib\": 321.5}\n";
  }

  ProgramRun run(const std::string& arguments) const {
    return sss::testing::runProgram(std::string(SSS_REPORT_PATH) + " " + arguments, dir_);
  }
  ProgramRun report() const {
    return run("--mission " + mission_dir_.string() + " --run " + run_dir().string() + " --out " + out_dir().string());
  }

  static fs::path mission_dir_;
  fs::path dir_;
};

fs::path RunReport::mission_dir_;

TEST_F(RunReport, WritesEveryFigureAndMetricsMatchTheKnownErrors) {
  const ProgramRun result = report();
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("SLAM reduced the horizontal position error RMSE"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find((out_dir() / "index.html").string()), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("3 closures accepted, 1 rejected"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("real-time factor"), std::string::npos) << result.out;

  const YAML::Node json = YAML::LoadFile((out_dir() / "metrics.json").string());  // JSON is YAML
  EXPECT_EQ(json["schema"].as<std::string>(), "sss-report/1");
  EXPECT_EQ(json["notes"].size(), 0u) << json["notes"];

  // Every listed file exists; the PNGs decode and have a readable size.
  std::set<std::string> listed;
  for (const YAML::Node& file : json["files"]) {
    const fs::path path = file.as<std::string>();
    listed.insert(path.filename().string());
    ASSERT_TRUE(fs::exists(path)) << path;
    if (path.extension() != ".png") continue;
    const cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(image.empty()) << path;
    EXPECT_GE(image.cols, 600) << path;
    EXPECT_LE(image.cols, 1600) << path;
    EXPECT_GE(image.rows, 300) << path;
    EXPECT_LE(image.rows, 1600) << path;
  }
  for (const char* name : {"index.html", "report.md", "metrics.json"}) EXPECT_TRUE(listed.count(name)) << name;
  const std::string html = slurp(out_dir() / "index.html");
  const std::string markdown = slurp(out_dir() / "report.md");
  for (const std::string& figure : kFigures) {
    EXPECT_TRUE(listed.count(figure)) << figure;
    EXPECT_NE(html.find("<img src=\"" + figure + "\""), std::string::npos) << figure;
    EXPECT_NE(markdown.find("](" + figure + ")"), std::string::npos) << figure;
  }
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("http"), std::string::npos);  // no network

  // SLAM is the truth shifted 0.1 m north: raw error 0.1 m everywhere, none after alignment.
  const YAML::Node trajectory = json["trajectory"];
  EXPECT_NEAR(trajectory["slam"]["ate_horizontal_m"]["rmse"].as<double>(), 0.1, 0.01);
  EXPECT_NEAR(trajectory["slam"]["ate_horizontal_m"]["max"].as<double>(), 0.1, 0.01);
  EXPECT_NEAR(trajectory["slam"]["ate_aligned_horizontal_m"]["rmse"].as<double>(), 0.0, 0.01);
  // Gauge-free keeps a shift (only rotation and scale about the start are fitted): 0.1 m at the start.
  EXPECT_GT(trajectory["slam"]["ate_gauge_free_horizontal_m"]["max"].as<double>(), 0.09);
  EXPECT_LE(trajectory["slam"]["ate_gauge_free_horizontal_m"]["rmse"].as<double>(),
            trajectory["slam"]["ate_horizontal_m"]["rmse"].as<double>() + 1e-9);
  for (const char* key : {"gauge_free_scale", "gauge_free_rotation_deg"}) EXPECT_TRUE(trajectory["dr"][key]) << key;
  EXPECT_TRUE(trajectory["ate_gauge_free_horizontal_rmse_improvement_percent"]);
  EXPECT_NE(result.out.find("gauge-free"), std::string::npos) << result.out;
  EXPECT_NE(html.find("ATE horizontal RMSE, gauge-free"), std::string::npos);
  const double dr_rmse = trajectory["dr"]["ate_horizontal_m"]["rmse"].as<double>();
  EXPECT_GT(dr_rmse, 0.3);  // 10x the default drift over ~300 m
  EXPECT_NEAR(trajectory["ate_horizontal_rmse_improvement_percent"].as<double>(),
              100.0 * (dr_rmse - trajectory["slam"]["ate_horizontal_m"]["rmse"].as<double>()) / dr_rmse, 1e-6);
  EXPECT_EQ(trajectory["lines"].size(), 2u);
  EXPECT_EQ(trajectory["slam"]["lines"].size(), 2u);
  EXPECT_DOUBLE_EQ(trajectory["rpe_window_m"].as<double>(), 100.0);
  EXPECT_EQ(trajectory["slam"]["matched"].as<size_t>(), trajectory["truth_poses"].as<size_t>());

  // Heightmaps: constant offsets, compared at cell centres of the seabed (float rounding only).
  const YAML::Node heightmap = json["heightmap"];
  EXPECT_NEAR(heightmap["slam"]["mae_m"].as<double>(), 0.05, 1e-4);
  EXPECT_NEAR(heightmap["dr"]["mae_m"].as<double>(), 0.3, 1e-4);
  EXPECT_NEAR(heightmap["slam"]["bias_m"].as<double>(), 0.05, 1e-4);
  EXPECT_NEAR(heightmap["mae_improvement_percent"].as<double>(), 100.0 * (0.3 - 0.05) / 0.3, 0.05);

  const YAML::Node closures = json["closures"];
  EXPECT_EQ(closures["accepted"].as<int>(), 3);
  EXPECT_EQ(closures["rejected"].as<int>(), 1);
  EXPECT_EQ(closures["total"].as<int>(), 4);
  EXPECT_EQ(closures["rejection_reasons"]["chi_square_gate"].as<int>(), 1);
  // The fabricated closures claim B 0.1 m ahead of A: every one is off by the true relative pose.
  EXPECT_EQ(json["closure_errors"]["accepted"].as<int>(), 3);
  EXPECT_GT(json["closure_errors"]["closure"]["horizontal_m"]["rmse"].as<double>(), 10.0);
  for (const char* key : {"along_m", "lateral_m", "depth_m", "heading_deg", "horizontal_m"}) {
    EXPECT_TRUE(json["closure_errors"]["dr"][key]) << key;
  }
  // LCE: the truth is its own self-check; SLAM (the truth shifted as a whole) is consistent too.
  EXPECT_GT(json["lce"]["correspondences"].as<int>(), 100);
  EXPECT_LT(json["lce"]["truth_max_m"].as<double>(), 1e-3);
  EXPECT_LT(json["lce"]["slam"]["max"].as<double>(), 1e-3);
  EXPECT_GT(json["lce"]["dr"]["mean"].as<double>(), json["lce"]["slam"]["mean"].as<double>());
  EXPECT_NE(json["lce"]["seabed_depth_source"].as<std::string>().find("seabed"), std::string::npos);
  EXPECT_DOUBLE_EQ(json["run"]["real_time_factor"].as<double>(), 12.0);
  EXPECT_DOUBLE_EQ(json["run"]["peak_rss_mib"].as<double>(), 321.5);

  EXPECT_EQ(json["outcome"].as<std::string>(), "better");
  const std::string verdict = json["verdict"].as<std::string>();
  EXPECT_EQ(verdict.rfind("SLAM reduced the horizontal position error RMSE from ", 0), 0u) << verdict;
  EXPECT_NE(verdict.find("3 closures accepted, 1 rejected"), std::string::npos) << verdict;
  EXPECT_NE(verdict.find("heightmap error (MAE) fell from 0.300 m to 0.050 m"), std::string::npos) << verdict;
  EXPECT_NE(html.find(verdict.substr(0, 40)), std::string::npos);
}

// The tie report and the survey products from sss-process's newer columns and summary blocks.
TEST_F(RunReport, ShowsTheTieReportCoverageFixesAndCalibration) {
  {
    std::ofstream csv(run_dir() / "loop_closures.csv");
    csv << "subframe_id_a,subframe_id_b,status,rejection,north_a_m,east_a_m,north_b_m,east_b_m,before_along_m,"
           "before_across_m,before_depth_m,before_heading_rad,after_along_m,after_across_m,after_depth_m,"
           "after_heading_rad\n"
           "0,3,accepted,none,25,0,95,40,0.40,-0.85,0.02,0.0035,0.05,-0.10,0.01,0.0002\n"
           "1,2,accepted,none,75,0,45,40,0.10,2.25,0.00,0.0010,0.30,1.40,0.00,0.0001\n"
           "0,2,rejected,chi_square_gate,25,0,45,40,6.00,1.00,0.00,0.0500,5.50,1.20,0.00,0.0400\n";
    std::ofstream summary(run_dir() / "summary.json");
    summary << "{\"pings\": 100, \"subframes\": 4, \"pairs_attempted\": 6, \"closures_accepted\": 2,"
               " \"closures_rejected\": 1, \"wall_s\": 1, \"mission_s\": 10, \"real_time_factor\": 10,"
               " \"peak_rss_mib\": 100,\n"
               " \"coverage\": {\"covered_m2\": 27125, \"seen_twice_m2\": 16150, \"fraction_seen_twice\": 0.5954},\n"
               " \"fixes\": {\"fed\": 12, \"accepted\": 11, \"rejected_gate\": 1, \"rms_residual_m\": 0.84},\n"
               " \"calibration\": {\"estimated\": true, \"dvl_scale\": 0.0021, \"dvl_scale_sigma\": 0.0004,"
               " \"heading_bias_rad\": 0.0052, \"heading_bias_sigma_rad\": 0.0009},\n"
               " \"geotiff\": {\"crs\": \"WGS 84 / UTM zone 34N\", \"epsg\": 32634,"
               " \"files\": [\"mosaic_slam.tif\", \"heightmap.tif\"]}}\n";
  }
  fs::copy_file(mission_dir_ / "mosaic.png", run_dir() / "coverage.png", fs::copy_options::overwrite_existing);
  const ProgramRun result = report();
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::string html = slurp(out_dir() / "index.html");
  const std::string markdown = slurp(out_dir() / "report.md");
  EXPECT_NE(html.find("Tie report"), std::string::npos);
  // Largest offset before the solve first: 0-2 (6.08 m), then 1-2 (2.25 m), then 0-3.
  const size_t first = html.find(">0-2<"), second = html.find(">1-2<"), third = html.find(">0-3<");
  ASSERT_NE(first, std::string::npos) << html;
  EXPECT_LT(first, second);
  EXPECT_LT(second, third);
  EXPECT_NE(html.find("rejected (chi_square_gate)"), std::string::npos);
  EXPECT_NE(html.find("<td>-0.85</td>"), std::string::npos) << "before across of 0-3";
  EXPECT_NE(html.find("<td>0.20</td>"), std::string::npos) << "before heading of 0-3 in degrees (0.0035 rad)";
  EXPECT_NE(html.find("<td class=\"bad\">1.40</td>"), std::string::npos)
      << "an accepted closure the solution leaves 1.4 m off stands out";
  EXPECT_NE(markdown.find("Tie report"), std::string::npos);
  // The products section: coverage, the GeoTIFFs' CRS, the fixes and the calibration with sigmas.
  EXPECT_NE(html.find("59.5 % of it seen from two lines"), std::string::npos) << html;
  EXPECT_NE(html.find("2.71 ha"), std::string::npos);
  EXPECT_NE(html.find("WGS 84 / UTM zone 34N"), std::string::npos);
  EXPECT_NE(html.find("<img src=\"coverage.png\""), std::string::npos);
  EXPECT_TRUE(fs::exists(out_dir() / "coverage.png"));
  EXPECT_NE(html.find("11 / 12"), std::string::npos);
  EXPECT_NE(html.find("<td>0.210</td><td>0.040</td>"), std::string::npos) << "DVL scale error in % with its sigma";
  EXPECT_NE(html.find("<td>0.298</td><td>0.052</td>"), std::string::npos) << "heading bias in deg with its sigma";
}

TEST_F(RunReport, MissingSlamTrajectoryExitsTwoNamingTheFile) {
  fs::remove(run_dir() / "slam.tum");
  ProgramRun result = report();
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find((run_dir() / "slam.tum").string() + ": missing"), std::string::npos) << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;  // one line
  EXPECT_FALSE(fs::exists(out_dir() / "index.html"));

  result = run("--mission " + (dir_ / "nowhere").string() + " --run " + run_dir().string() + " --out " +
               out_dir().string());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("nowhere"), std::string::npos) << result.err;
  EXPECT_EQ(run("--mission " + mission_dir_.string() + " --out " + out_dir().string()).exit_code, 2);  // no --run
  EXPECT_EQ(run("--help").exit_code, 0);
}

TEST_F(RunReport, MissingOptionalInputsLeaveTheirSectionsOutWithNotes) {
  for (const char* name : {"heightmap.yaml", "heightmap_dr.yaml", "summary.json", "mosaic_slam.yaml"}) {
    fs::remove(run_dir() / name);
  }
  {
    std::ofstream bad(run_dir() / "loop_closures.csv", std::ios::app);
    bad << "4,5,1,2,0,maybe,none,0,0,0,0,0,0,1,0.1,0,0,1,1\n";  // line 7: unknown status
  }
  const ProgramRun result = report();
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.err.find("note:"), std::string::npos) << result.err;
  const YAML::Node json = YAML::LoadFile((out_dir() / "metrics.json").string());
  EXPECT_TRUE(json["heightmap"].IsNull());
  EXPECT_TRUE(json["closures"].IsNull());
  EXPECT_TRUE(json["run"].IsNull());
  std::string notes;
  for (const YAML::Node& note : json["notes"]) notes += note.as<std::string>() + "\n";
  EXPECT_NE(notes.find("no SLAM heightmap"), std::string::npos) << notes;
  EXPECT_NE(notes.find("no DR heightmap"), std::string::npos) << notes;
  EXPECT_NE(notes.find("summary.json"), std::string::npos) << notes;
  EXPECT_NE(notes.find("mosaic_slam.yaml"), std::string::npos) << notes;
  EXPECT_NE(notes.find((run_dir() / "loop_closures.csv").string() + ":7: status 'maybe'"), std::string::npos) << notes;
  const std::string html = slurp(out_dir() / "index.html");
  EXPECT_NE(html.find("no SLAM heightmap"), std::string::npos);
  EXPECT_NE(html.find("trajectories.png"), std::string::npos);
  EXPECT_NE(html.find("error_over_time.png"), std::string::npos);
  for (const char* absent : {"loop_closures.png", "mosaics_dr_slam.png", "heightmap_slam.png", "heightmap_error_dr.png"}) {
    EXPECT_EQ(html.find(absent), std::string::npos) << absent;
    EXPECT_FALSE(fs::exists(out_dir() / absent)) << absent;
  }
  EXPECT_EQ(json["outcome"].as<std::string>(), "better");
}

// No /usr/bin/python3: the report without its figures and without index.html (both drawn by
// Python), report.md with every table, one note naming the cause and tools/setup-deps.sh, status ok
// (sss-report exits 0, as for any missing figure).
TEST_F(RunReport, WithoutPythonTheReportIsWrittenWithoutFiguresAndOneNote) {
  RunReportRequest request;
  request.mission_dir = mission_dir_.string();
  request.run_dir = run_dir().string();
  request.out_dir = out_dir().string();
  request.figures.python = (dir_ / "no-python3").string();
  const sss::eval::RunReport report = writeRunReport(request);
  ASSERT_EQ(report.status, RunReportStatus::ok) << report.error;
  ASSERT_EQ(report.notes.size(), 1u);
  EXPECT_NE(report.notes[0].find(request.figures.python + " not found"), std::string::npos) << report.notes[0];
  EXPECT_NE(report.notes[0].find("tools/setup-deps.sh"), std::string::npos) << report.notes[0];
  // The page is drawn by Python too: report.md is the report, with the notes and every table.
  EXPECT_FALSE(fs::exists(out_dir() / "index.html"));
  EXPECT_EQ(report.index_html, (out_dir() / "report.md").string());
  const std::string markdown = slurp(out_dir() / "report.md");
  EXPECT_NE(markdown.find("tools/setup-deps.sh"), std::string::npos);  // the notes
  EXPECT_NE(markdown.find("ATE horizontal RMSE"), std::string::npos);  // the tables are all there
  for (const std::string& figure : kFigures) {
    EXPECT_EQ(markdown.find("](" + figure + ")"), std::string::npos) << figure;
    EXPECT_FALSE(fs::exists(out_dir() / figure)) << figure;
  }
  EXPECT_TRUE(fs::exists(out_dir() / "metrics.json"));
}

// The page script missing (a broken install): the figures are drawn, report.md is the report and
// one note says where the script was looked for.
TEST_F(RunReport, WithoutThePageScriptTheFiguresAreDrawnAndReportMdIsTheReport) {
  RunReportRequest request;
  request.mission_dir = mission_dir_.string();
  request.run_dir = run_dir().string();
  request.out_dir = out_dir().string();
  request.figures.page_script = (dir_ / "no-report_page.py").string();
  const sss::eval::RunReport report = writeRunReport(request);
  ASSERT_EQ(report.status, RunReportStatus::ok) << report.error;
  ASSERT_EQ(report.notes.size(), 1u);
  EXPECT_EQ(report.notes[0].rfind("index.html not written: the page script " + request.figures.page_script, 0), 0u)
      << report.notes[0];
  EXPECT_FALSE(fs::exists(out_dir() / "index.html"));
  EXPECT_EQ(report.index_html, (out_dir() / "report.md").string());
  const std::string markdown = slurp(out_dir() / "report.md");
  EXPECT_NE(markdown.find("index.html not written: the page script"), std::string::npos);  // the note
  for (const std::string& figure : kFigures) {
    EXPECT_TRUE(fs::exists(out_dir() / figure)) << figure;
    EXPECT_NE(markdown.find("](" + figure + ")"), std::string::npos) << figure;
  }
}

TEST_F(RunReport, SaysPlainlyWhenSlamIsWorseThanDeadReckoning) {
  fabricateRun(20.0);  // far beyond the DR drift
  const ProgramRun result = report();
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const YAML::Node json = YAML::LoadFile((out_dir() / "metrics.json").string());
  EXPECT_EQ(json["outcome"].as<std::string>(), "worse");
  const std::string verdict = json["verdict"].as<std::string>();
  EXPECT_EQ(verdict.rfind("SLAM is worse than dead reckoning", 0), 0u) << verdict;
  EXPECT_LT(json["trajectory"]["ate_horizontal_rmse_improvement_percent"].as<double>(), 0.0);
  EXPECT_NE(slurp(out_dir() / "index.html").find("class=\"verdict worse\""), std::string::npos);
}

// A run processed with its own origin (sss-process takes its first fix): loop_closures.csv is in
// the run's frame, the figures in the truth's; the closure centres must land where they were.
TEST_F(RunReport, ClosureCentresOfARunWithItsOwnOriginAreMovedIntoTheTruthsFrame) {
  const TumReadResult truth = readTum((mission_dir_ / "ground_truth.tum").string());
  ASSERT_TRUE(truth.ok) << truth.error;
  ASSERT_TRUE(truth.origin.has_value());
  // The run's origin 100 m north and 30 m east of the truth's.
  const sss::core::LocalTangentPlane truth_plane(truth.origin->latitude_deg, truth.origin->longitude_deg);
  const sss::core::GeodeticPosition moved = truth_plane.toGeodetic(Eigen::Vector3d(100.0, 30.0, 0.0));
  const sss::core::MissionOrigin run_origin{moved.latitude_deg, moved.longitude_deg};
  Trajectory slam = truth.poses;
  reexpressTrajectory(slam, *truth.origin, run_origin);
  ASSERT_OK(writeTum((run_dir() / "slam.tum").string(), slam, "", run_origin));
  // Closure 0-3 from (25, 0) to (95, 40) in the truth's frame, written in the run's (-75, -30) ...
  const Eigen::Vector3d a = reexpressPosition({25.0, 0.0, 0.0}, *truth.origin, run_origin);
  const Eigen::Vector3d b = reexpressPosition({95.0, 40.0, 0.0}, *truth.origin, run_origin);
  ASSERT_NEAR(a.x(), -75.0, 0.1);
  {
    std::ofstream csv(run_dir() / "loop_closures.csv");
    csv.precision(12);
    csv << "subframe_id_a,subframe_id_b,status,rejection,north_a_m,east_a_m,north_b_m,east_b_m\n"
        << "0,3,accepted,none," << a.x() << "," << a.y() << "," << b.x() << "," << b.y() << "\n";
  }
  RunReportRequest request;
  request.mission_dir = mission_dir_.string();
  request.run_dir = run_dir().string();
  request.out_dir = out_dir().string();
  request.figures.python = (dir_ / "no-python3").string();  // the numbers only
  const sss::eval::RunReport report = writeRunReport(request);
  ASSERT_EQ(report.status, RunReportStatus::ok) << report.error;
  ASSERT_EQ(report.closures.size(), 1u);
  // ... and back to 1 cm (the transform is exact through WGS-84; the CSV keeps 12 digits).
  EXPECT_NEAR(report.closures[0].centre_a_north_east_m.x(), 25.0, 0.01);
  EXPECT_NEAR(report.closures[0].centre_a_north_east_m.y(), 0.0, 0.01);
  EXPECT_NEAR(report.closures[0].centre_b_north_east_m.x(), 95.0, 0.01);
  EXPECT_NEAR(report.closures[0].centre_b_north_east_m.y(), 40.0, 0.01);
}

}  // namespace
}  // namespace sss::eval
