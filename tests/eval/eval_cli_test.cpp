// sss-eval end to end on files written by the test: exit codes, the table, the JSON report's keys
// and values, the figures, and clear errors (exit 2) for bad input.
#include "tools/eval/heightmap_metrics.hpp"
#include "tools/eval/trajectory_io.hpp"

#include "tests/eval/eval_test_paths.hpp"
#include "tests/support/run_program.hpp"
#include "tests/support/status_assertions.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#ifndef SSS_EVAL_PATH
#error "SSS_EVAL_PATH must name the sss-eval executable"
#endif

namespace sss::eval {
namespace {

namespace fs = std::filesystem;

using sss::testing::ProgramRun, sss::testing::slurp;

class EvalCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("sss_eval_cli_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    truth_ = test::lawnmower(3, 200.0, 60.0);
    std::string error;
    ASSERT_OK(writeTum(path("truth.tum"), truth_));
    ASSERT_OK(writeTum(path("dr.tum"), shifted(2.0)));
    ASSERT_OK(writeTum(path("slam.tum"), shifted(0.5)));
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  Trajectory shifted(double east_m) const {
    Trajectory poses = truth_;
    for (StampedPose& p : poses) p.T_world_body.translation.y() += east_m;
    return poses;
  }

  ProgramRun run(const std::string& arguments) const {
    return sss::testing::runProgram(std::string(SSS_EVAL_PATH) + " " + arguments, dir_);
  }

  fs::path dir_;
  Trajectory truth_;
};

TEST_F(EvalCli, EvaluatesTwoEstimatesIntoTableJsonAndFigures) {
  const ProgramRun result = run("--gt " + path("truth.tum") + " --est " + path("dr.tum") + " --label DR --est " +
                         path("slam.tum") + " --label SLAM --json " + path("out/report.json") + " --plot " +
                         path("out/fig.png"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("DR "), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("SLAM "), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("3 survey lines"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("75.0"), std::string::npos) << result.out;  // SLAM: 0.5 m vs 2 m
  for (const char* figure : {"out/fig.png", "out/fig_error.png"}) EXPECT_GT(fs::file_size(dir_ / figure), 1000u);

  const YAML::Node json = YAML::LoadFile(path("out/report.json"));  // JSON is YAML
  EXPECT_EQ(json["schema"].as<std::string>(), "sss-eval/1");
  EXPECT_EQ(json["truth"]["poses"].as<size_t>(), truth_.size());
  EXPECT_EQ(json["truth"]["lines"].size(), 3u);
  for (const char* key : {"index", "start_utime_us", "end_utime_us", "length_m", "heading_deg"}) {
    EXPECT_TRUE(json["truth"]["lines"][0][key]) << key;
  }
  for (const char* key : {"interpolate_truth", "max_interpolation_gap_s", "max_time_difference_s", "rpe_windows_m"}) {
    EXPECT_TRUE(json["options"][key]) << key;
  }
  ASSERT_EQ(json["estimates"].size(), 2u);
  const YAML::Node dr = json["estimates"][0];
  const YAML::Node slam = json["estimates"][1];
  EXPECT_EQ(dr["label"].as<std::string>(), "DR");
  EXPECT_EQ(dr["matched"].as<size_t>(), truth_.size());
  for (const char* key : {"label", "path", "poses", "matched", "exact", "interpolated", "nearest", "unmatched", "ate",
                          "rpe", "lines", "improvement_vs_first_percent", "series"}) {
    EXPECT_TRUE(dr[key]) << key;
  }
  for (const char* key : {"position_m", "horizontal_m", "vertical_m", "rotation_deg", "aligned_position_m",
                          "aligned_horizontal_m", "alignment", "gauge_free_horizontal_m", "gauge_horizontal_m",
                          "gauge_free_scale", "gauge_free_rotation_deg"}) {
    EXPECT_TRUE(dr["ate"][key]) << key;
  }
  for (const char* key : {"count", "rmse", "mean", "median", "max"}) {
    EXPECT_TRUE(dr["ate"]["gauge_free_horizontal_m"][key]) << key;
  }
  // A 2 m shift is not a rotation or scale: the start keeps all of it, and no fit beats raw.
  EXPECT_NEAR(dr["series"]["gauge_free_horizontal_m"][0].as<double>(), 2.0, 1e-5);
  EXPECT_LE(dr["ate"]["gauge_free_horizontal_m"]["rmse"].as<double>(), 2.0 + 1e-5);
  EXPECT_NE(result.out.find("horiz g-free"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("gauge-free horizontal ATE"), std::string::npos) << result.out;
  // LCE runs by default with --gt and --est, without --lce.
  ASSERT_TRUE(json["lce"].IsMap());
  EXPECT_EQ(json["lce"]["estimates"].size(), 2u);
  EXPECT_GT(json["lce"]["correspondences"].as<size_t>(), 500u);
  EXPECT_TRUE(json["lce_skipped"].IsNull());
  EXPECT_NE(result.out.find("truth (self-check)"), std::string::npos) << result.out;
  for (const char* key : {"count", "rmse", "mean", "median", "max"}) EXPECT_TRUE(dr["ate"]["horizontal_m"][key]) << key;
  EXPECT_NEAR(dr["ate"]["horizontal_m"]["rmse"].as<double>(), 2.0, 1e-5);
  EXPECT_NEAR(dr["ate"]["aligned_horizontal_m"]["rmse"].as<double>(), 0.0, 1e-5);
  EXPECT_NEAR(dr["ate"]["alignment"]["translation_m"][1].as<double>(), -2.0, 1e-5);
  EXPECT_EQ(dr["ate"]["alignment"]["quaternion_xyzw"].size(), 4u);
  EXPECT_TRUE(dr["improvement_vs_first_percent"].IsNull());
  EXPECT_NEAR(slam["improvement_vs_first_percent"].as<double>(), 75.0, 1e-3);
  ASSERT_EQ(dr["rpe"].size(), 3u);
  EXPECT_DOUBLE_EQ(dr["rpe"][1]["window_m"].as<double>(), 50.0);
  for (const char* key : {"translation_percent", "translation_m", "rotation_deg"}) EXPECT_TRUE(dr["rpe"][1][key]) << key;
  EXPECT_EQ(dr["lines"].size(), 3u);
  for (const char* key : {"time_s", "distance_m", "position_m", "horizontal_m", "aligned_horizontal_m",
                          "gauge_free_horizontal_m", "along_track_m", "across_track_m", "line"}) {
    EXPECT_EQ(dr["series"][key].size(), truth_.size()) << key;
  }
  EXPECT_EQ(json["heightmaps"].size(), 0u);
  EXPECT_EQ(json["outputs"]["plots"].size(), 2u);
}

TEST_F(EvalCli, NoLceTurnsTheDefaultLceOffAndATruthWithoutLinesSkipsIt) {
  ASSERT_EQ(run("--gt " + path("truth.tum") + " --est " + path("dr.tum") + " --no-lce --json " + path("off.json")).exit_code,
            0);
  const YAML::Node off = YAML::LoadFile(path("off.json"));
  EXPECT_TRUE(off["lce"].IsNull());
  EXPECT_TRUE(off["lce_skipped"].IsNull());
  // --lce after --no-lce: the last one wins.
  ASSERT_EQ(run("--gt " + path("truth.tum") + " --est " + path("dr.tum") + " --no-lce --lce --json " + path("on.json"))
                .exit_code,
            0);
  EXPECT_TRUE(YAML::LoadFile(path("on.json"))["lce"].IsMap());

  // A 40 m straight line has no survey line: the default LCE is skipped with a reason, --lce fails.
  std::string error;
  ASSERT_OK(writeTum(path("short.tum"), test::straightLine(40.0)));
  ProgramRun result = run("--gt " + path("short.tum") + " --est " + path("short.tum") + " --json " + path("short.json"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("LCE) skipped"), std::string::npos) << result.out;
  const YAML::Node skipped = YAML::LoadFile(path("short.json"));
  EXPECT_TRUE(skipped["lce"].IsNull());
  EXPECT_NE(skipped["lce_skipped"].as<std::string>().find("no survey lines"), std::string::npos);
  result = run("--gt " + path("short.tum") + " --est " + path("short.tum") + " --lce");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("no survey lines"), std::string::npos) << result.err;
}

TEST_F(EvalCli, ComparesHeightmapsAndWritesErrorMaps) {
  HeightmapRaster seabed;
  seabed.rows = 80;
  seabed.cols = 60;
  seabed.resolution_m = 1.0;
  seabed.north_min_m = -10.0;
  seabed.east_min_m = -10.0;
  seabed.depth_m.assign(80 * 60, 50.0f);
  HeightmapRaster estimate = seabed;
  for (size_t i = 0; i < estimate.depth_m.size(); ++i) estimate.depth_m[i] = i % 4 == 0 ? NAN : 50.3f;
  std::string error;
  ASSERT_OK(writeHeightmap(path("seabed"), seabed));
  ASSERT_OK(writeHeightmap(path("recon.yaml"), estimate));
  const ProgramRun result = run("--seabed " + path("seabed.yaml") + " --heightmap " + path("recon.yaml") + " --json " +
                         path("hm.json") + " --plot " + path("hm.png") + " --error-map " + path("err"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const YAML::Node json = YAML::LoadFile(path("hm.json"));
  ASSERT_EQ(json["heightmaps"].size(), 1u);
  const YAML::Node h = json["heightmaps"][0];
  EXPECT_EQ(h["label"].as<std::string>(), "recon");
  EXPECT_NEAR(h["abs_error_m"]["mean"].as<double>(), 0.3, 1e-5);
  EXPECT_NEAR(h["coverage_fraction"].as<double>(), 0.75, 1e-12);
  EXPECT_EQ(h["compared_cells"].as<size_t>(), 3600u);
  EXPECT_EQ(h["error_map_yaml"].as<std::string>(), path("err_recon.yaml"));
  EXPECT_EQ(h["error_map_png"].as<std::string>(), path("hm_heightmap_recon.png"));
  EXPECT_TRUE(fs::exists(path("err_recon_depth.f32")));
  EXPECT_GT(fs::file_size(path("hm_heightmap_recon.png")), 1000u);
  EXPECT_EQ(json["estimates"].size(), 0u);
}

TEST_F(EvalCli, ScoresLoopClosuresAndLandmarkConsistency) {
  // Two closures between lines 0 and 1 (poses 200 and 800, 0.5 m apart on the path); the accepted
  // one 0.3 m too far along track, the rejected one 4 m; both with sigmas of 0.3 m along and 0.2 m
  // across, so NEES 1 and 178.
  std::ofstream csv(path("loop_closures.csv"));
  csv << "# loop closures\nsubframe_id_a,subframe_id_b,utime_a_us,utime_b_us,round,status,rejection,dx_m,dy_m,dz_m,"
         "droll_rad,dpitch_rad,dheading_rad,num_inliers,mean_zncc,north_a_m,east_a_m,north_b_m,east_b_m,cov_xx_m2,"
         "cov_xy_m2,cov_yy_m2\n";
  const sss::core::Pose T_a_b = truth_[200].T_world_body.inverse() * truth_[800].T_world_body;
  const double heading_rad = sss::core::eulerFromQuaternion(T_a_b.rotation).heading_rad;
  for (const auto& [status, along_error_m] : {std::pair<const char*, double>{"accepted", 0.3}, {"rejected", 4.0}}) {
    csv << "3,7," << truth_[200].utime_us << "," << truth_[800].utime_us << ",0," << status << ",none,"
        << std::setprecision(12) << T_a_b.translation.x() + along_error_m << "," << T_a_b.translation.y() << ","
        << T_a_b.translation.z() << ",0,0," << heading_rad << ",50,0.6,0,0,0,0,0.09,0,0.04\n";
  }
  csv.close();
  const ProgramRun result = run("--gt " + path("truth.tum") + " --est " + path("dr.tum") + " --label DR --est " +
                                path("slam.tum") + " --closures " + path("loop_closures.csv") +
                                " --closure-table --lce --lce-seabed-depth-m 50 --json " + path("c.json"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("truth (self-check)"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("3-7"), std::string::npos) << result.out;  // the per-closure table
  EXPECT_NE(result.out.find("accepted"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("NEES"), std::string::npos) << result.out;  // the closure's own sigmas and NEES

  const YAML::Node json = YAML::LoadFile(path("c.json"));
  const YAML::Node closures = json["closures"];
  EXPECT_EQ(closures["count"].as<size_t>(), 2u);
  EXPECT_EQ(closures["dr"]["label"].as<std::string>(), "DR");
  ASSERT_EQ(closures["groups"].size(), 2u);
  EXPECT_EQ(closures["groups"][0]["status"].as<std::string>(), "accepted");
  // TUM files hold 6 decimals: the truth read back is within 1 um.
  EXPECT_NEAR(closures["groups"][0]["closure"]["along_m"]["rmse"].as<double>(), 0.3, 1e-5);
  EXPECT_NEAR(closures["groups"][0]["closure"]["along_m"]["bias"].as<double>(), 0.3, 1e-5);
  EXPECT_NEAR(closures["groups"][1]["closure"]["along_m"]["max"].as<double>(), 4.0, 1e-5);
  EXPECT_NEAR(closures["groups"][0]["closure"]["lateral_m"]["max"].as<double>(), 0.0, 1e-5);
  // DR is the truth shifted 2 m east everywhere: its relative poses are the truth's.
  EXPECT_NEAR(closures["groups"][0]["dr"]["horizontal_m"]["max"].as<double>(), 0.0, 1e-5);
  for (const char* key : {"subframe_id_a", "subframe_id_b", "round", "status", "rejection", "utime_a_us", "utime_b_us",
                          "truth", "error", "dr_error", "sigma_along_m", "sigma_lateral_m", "horizontal_nees"}) {
    EXPECT_TRUE(closures["closures"][0][key]) << key;
  }
  EXPECT_NEAR(closures["closures"][0]["sigma_along_m"].as<double>(), 0.3, 1e-9);
  EXPECT_NEAR(closures["closures"][0]["sigma_lateral_m"].as<double>(), 0.2, 1e-9);
  EXPECT_NEAR(closures["closures"][0]["horizontal_nees"].as<double>(), 1.0, 1e-3);
  EXPECT_NEAR(closures["closures"][1]["horizontal_nees"].as<double>(), 16.0 / 0.09, 1e-2);

  const YAML::Node lce = json["lce"];
  EXPECT_DOUBLE_EQ(lce["seabed_depth_m"].as<double>(), 50.0);
  EXPECT_GT(lce["correspondences"].as<size_t>(), 500u);  // ~39 rows x (9 + 9 + 5) columns
  EXPECT_LT(lce["truth"]["horizontal_m"]["max"].as<double>(), 1e-3);
  ASSERT_EQ(lce["estimates"].size(), 2u);
  EXPECT_EQ(lce["estimates"][0]["label"].as<std::string>(), "DR");
  EXPECT_LT(lce["estimates"][0]["horizontal_m"]["max"].as<double>(), 1e-3);  // a constant shift is consistent
  for (const char* key : {"seabed_depth_source", "grid_m", "min_ground_range_m", "max_ground_range_m",
                          "max_correspondences", "sightings", "seabed_points", "candidate_pairs"}) {
    EXPECT_TRUE(lce[key]) << key;
  }

  // Closures and LCE alone (no --est): no DR, the truth's LCE only.
  ASSERT_EQ(run("--gt " + path("truth.tum") + " --closures " + path("loop_closures.csv") + " --lce --json " +
                path("d.json")).exit_code, 0);
  const YAML::Node alone = YAML::LoadFile(path("d.json"));
  EXPECT_TRUE(alone["closures"]["dr"].IsNull());
  EXPECT_EQ(alone["lce"]["estimates"].size(), 0u);
}

TEST_F(EvalCli, BadInputsExitWithCodeTwoAndAClearMessage) {
  {
    std::ofstream bad(path("bad.tum"));
    bad << "# estimate\n1780300800.0 0 0 30 0 0 0 1\n1780300800.25 0 0 30 0 0 1\n";
  }
  ProgramRun result = run("--gt " + path("truth.tum") + " --est " + path("bad.tum"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find(path("bad.tum") + ":3:"), std::string::npos) << result.err;

  result = run("--gt " + path("missing.tum") + " --est " + path("dr.tum"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("missing.tum: cannot open"), std::string::npos) << result.err;

  Trajectory later = truth_;
  for (StampedPose& p : later) p.utime_us += 86400LL * 1000000;
  std::string error;
  ASSERT_OK(writeTum(path("later.tum"), later));
  result = run("--gt " + path("truth.tum") + " --est " + path("later.tum"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("same clock"), std::string::npos) << result.err;

  EXPECT_EQ(run("").exit_code, 2);
  EXPECT_EQ(run("--est " + path("dr.tum")).exit_code, 2);                              // no --gt
  EXPECT_EQ(run("--gt " + path("truth.tum") + " --est").exit_code, 2);                 // flag without value
  EXPECT_EQ(run("--gt " + path("truth.tum") + " --bogus x").exit_code, 2);
  EXPECT_EQ(run("--gt " + path("truth.tum") + " --est " + path("dr.tum") + " --rpe-windows-m 10,x").exit_code, 2);
  EXPECT_EQ(run("--gt " + path("truth.tum") + " --est " + path("dr.tum") + " --rpe-windows-m 0").exit_code, 2);
  EXPECT_EQ(run("--gt " + path("truth.tum") + " --est " + path("dr.tum") + " --label a --label b").exit_code, 2);
  EXPECT_EQ(run("--gt " + path("truth.tum") + " --est " + path("dr.tum") + " --plot x.jpg").exit_code, 2);
  EXPECT_EQ(run("--heightmap " + path("x.yaml")).exit_code, 2);  // no --seabed
  result = run("--seabed " + path("truth.tum") + " --heightmap " + path("truth.tum"));  // not YAML maps
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("truth.tum"), std::string::npos) << result.err;
  EXPECT_EQ(run("--gt " + path("truth.tum") + " --est " + path("dr.tum") + " --closures-dr " + path("dr.tum")).exit_code, 2);
  EXPECT_EQ(run("--gt " + path("truth.tum") + " --lce --lce-swath-m 70,10").exit_code, 2);
  EXPECT_EQ(run("--gt " + path("truth.tum") + " --lce --lce-grid-m 0").exit_code, 2);
  EXPECT_EQ(run("--closures " + path("truth.tum")).exit_code, 2);  // no --gt
  result = run("--gt " + path("truth.tum") + " --closures " + path("truth.tum"));  // not a closure file
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("the header has no column"), std::string::npos) << result.err;
  EXPECT_EQ(run("--matches " + path("truth.tum")).exit_code, 2);  // no --mission
  result = run("--matches " + path("truth.tum") + " --mission " + dir_.string());  // not a matches file
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find(path("truth.tum") + ":1:"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("'kind'"), std::string::npos) << result.err;
  EXPECT_EQ(run("--help").exit_code, 0);
}

}  // namespace
}  // namespace sss::eval
