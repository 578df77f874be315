// Loop-closure accuracy: closures made from the truth with known perturbations come back as those
// errors (along, lateral, depth, heading, wrapped near +-pi), per status; DR's relative pose error
// shows a step in DR; the reader names file and line for a bad file.
#include "tools/eval/closure_metrics.hpp"

#include "tests/eval/eval_test_paths.hpp"
#include "tests/support/status_assertions.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace sss::eval {
namespace {

namespace fs = std::filesystem;

// The header sss-process writes (tools/process/offline_runner.cpp writeClosuresCsv).
const char* kHeader =
    "# loop closures from the matcher and the optimiser's decision; T_a_b maps B's centre body frame into A's;\n"
    "# north/east: the two subframe centres under the final SLAM estimate (local NED, m)\n"
    "subframe_id_a,subframe_id_b,utime_a_us,utime_b_us,round,status,rejection,dx_m,dy_m,dz_m,droll_rad,"
    "dpitch_rad,dheading_rad,num_inliers,mean_zncc,north_a_m,east_a_m,north_b_m,east_b_m\n";

struct Perturbation {
  size_t a = 0, b = 0;  // truth pose indices of the two centres
  const char* status = "accepted";
  RelativePoseError error;  // added to the true relative pose
};

// A row as sss-process writes it, with the true relative pose + the perturbation (more decimals, so
// the numbers come back exactly).
std::string closureRow(const Trajectory& truth, const Perturbation& p, int64_t utime_a_us, int64_t utime_b_us) {
  const sss::core::Pose T_a_b = truth[p.a].T_world_body.inverse() * truth[p.b].T_world_body;
  const double heading_rad = sss::core::wrapAngle(sss::core::eulerFromQuaternion(T_a_b.rotation).heading_rad +
                                                  p.error.heading_rad);
  char row[512];
  std::snprintf(row, sizeof row, "%zu,%zu,%lld,%lld,1,%s,%s,%.9f,%.9f,%.9f,0,0,%.9f,100,0.5,0,0,0,0\n", p.a, p.b,
                static_cast<long long>(utime_a_us), static_cast<long long>(utime_b_us), p.status,
                std::string(p.status) == "rejected" ? "chi_square_gate" : "none",
                T_a_b.translation.x() + p.error.along_m, T_a_b.translation.y() + p.error.lateral_m,
                T_a_b.translation.z() + p.error.depth_m, heading_rad);
  return row;
}

class ClosureMetrics : public ::testing::Test {
 protected:
  void SetUp() override {
    truth_ = test::lawnmower(3, 200.0, 60.0);  // 0.5 m per pose; lines: 0..400, 588..988, 1177..1577
    // One file per process: ctest -j runs this fixture's tests side by side.
    path_ = (fs::temp_directory_path() / ("sss_closure_metrics_test_" + std::to_string(::getpid()) + ".csv")).string();
  }
  void TearDown() override { fs::remove(path_); }

  void write(const std::string& text) const {
    std::ofstream out(path_);
    out << text;
  }

  Trajectory truth_;
  std::string path_;
  // Accepted: line 0 -> line 1 (B heads south: true heading ~pi, the error must wrap), line 1 ->
  // line 2; rejected: line 0 -> line 1, 5 m off.
  const std::vector<Perturbation> perturbations_ = {
      {200, 800, "accepted", {0.3, -0.2, 0.1, 0.01}},
      {900, 1400, "accepted", {-0.3, 0.2, -0.1, -0.01}},
      {100, 850, "rejected", {5.0, 0.0, 0.0, 0.1}},
  };
};

TEST_F(ClosureMetrics, KnownPerturbationsComeBackPerStatus) {
  std::string text = kHeader;
  for (const Perturbation& p : perturbations_) text += closureRow(truth_, p, truth_[p.a].utime_us, truth_[p.b].utime_us);
  // A closure whose centre lies before the truth: listed, but without an error.
  text += closureRow(truth_, perturbations_[0], truth_.front().utime_us - 10000000, truth_[800].utime_us);
  write(text);
  std::vector<ClosureRecord> closures;
  std::string error;
  ASSERT_OK(readClosureCsv(path_, closures));
  ASSERT_EQ(closures.size(), 4u);
  EXPECT_EQ(closures[2].status, "rejected");
  EXPECT_EQ(closures[2].rejection, "chi_square_gate");
  EXPECT_EQ(closures[0].round, 1);
  EXPECT_EQ(closures[0].line, 4);

  // DR: the truth with a 2 m step to the east from pose 700 on (between the turn and line 1's
  // centres): closures spanning the step see it in A's frame, the others see nothing.
  Trajectory dr = truth_;
  for (size_t i = 700; i < dr.size(); ++i) dr[i].T_world_body.translation.y() += 2.0;

  const ClosureEvaluation ev = evaluateClosures(closures, truth_, &dr, 1.0);
  ASSERT_EQ(ev.closures.size(), 4u);
  EXPECT_EQ(ev.without_truth, 1u);
  EXPECT_EQ(ev.without_dr, 0u);
  EXPECT_FALSE(ev.closures[3].has_truth);
  for (size_t k = 0; k < perturbations_.size(); ++k) {
    const ClosureError& e = ev.closures[k];
    ASSERT_TRUE(e.has_truth);
    EXPECT_NEAR(e.closure_error.along_m, perturbations_[k].error.along_m, 1e-8);
    EXPECT_NEAR(e.closure_error.lateral_m, perturbations_[k].error.lateral_m, 1e-8);
    EXPECT_NEAR(e.closure_error.depth_m, perturbations_[k].error.depth_m, 1e-8);
    EXPECT_NEAR(e.closure_error.heading_rad, perturbations_[k].error.heading_rad, 1e-8);
  }
  // Closure 0: A northbound at north 100 m; B on the southbound line 60 m east, at north 30 pi m
  // (400 m of path minus 200 m of line 0 and a 30 m-radius semicircle, back from north 200 m).
  EXPECT_NEAR(ev.closures[0].truth.translation_m.x(), 30.0 * M_PI - 100.0, 1e-9);
  EXPECT_NEAR(ev.closures[0].truth.translation_m.y(), 60.0, 1e-9);
  EXPECT_NEAR(std::abs(ev.closures[0].truth.heading_rad), M_PI, 1e-9);
  // DR: A northbound before the step, B after: +2 m lateral (starboard = east); closure 1 is
  // entirely after the step.
  EXPECT_NEAR(ev.closures[0].dr_error.lateral_m, 2.0, 1e-9);
  EXPECT_NEAR(ev.closures[0].dr_error.along_m, 0.0, 1e-9);
  EXPECT_NEAR(ev.closures[1].dr_error.lateral_m, 0.0, 1e-9);
  EXPECT_NEAR(ev.closures[2].dr_error.lateral_m, 2.0, 1e-9);
  EXPECT_NEAR(ev.closures[2].dr_error.heading_rad, 0.0, 1e-9);

  ASSERT_EQ(ev.groups.size(), 2u);
  const ClosureGroup& accepted = ev.groups[0];
  EXPECT_EQ(accepted.status, "accepted");
  EXPECT_EQ(accepted.count, 2u);  // the one outside the truth is not counted
  EXPECT_NEAR(accepted.closure.along_m.abs.rmse, 0.3, 1e-8);
  EXPECT_NEAR(accepted.closure.along_m.abs.max, 0.3, 1e-8);
  EXPECT_NEAR(accepted.closure.along_m.bias, 0.0, 1e-8);
  EXPECT_NEAR(accepted.closure.lateral_m.abs.rmse, 0.2, 1e-8);
  EXPECT_NEAR(accepted.closure.depth_m.abs.max, 0.1, 1e-8);
  EXPECT_NEAR(accepted.closure.heading_deg.abs.rmse, 0.01 * 180.0 / M_PI, 1e-6);
  EXPECT_NEAR(accepted.closure.horizontal_m.rmse, std::hypot(0.3, 0.2), 1e-8);
  EXPECT_NEAR(accepted.dr.lateral_m.abs.rmse, std::sqrt(2.0), 1e-8);  // errors 2 and 0
  EXPECT_NEAR(accepted.dr.lateral_m.abs.max, 2.0, 1e-8);
  EXPECT_NEAR(accepted.dr.lateral_m.bias, 1.0, 1e-8);
  const ClosureGroup& rejected = ev.groups[1];
  EXPECT_EQ(rejected.status, "rejected");
  EXPECT_EQ(rejected.count, 1u);
  EXPECT_NEAR(rejected.closure.along_m.abs.rmse, 5.0, 1e-8);
  EXPECT_NEAR(rejected.closure.heading_deg.bias, 0.1 * 180.0 / M_PI, 1e-6);
  EXPECT_NEAR(rejected.dr.lateral_m.abs.max, 2.0, 1e-8);

  // Without DR: no DR errors, empty DR statistics.
  const ClosureEvaluation no_dr = evaluateClosures(closures, truth_, nullptr, 1.0);
  EXPECT_FALSE(no_dr.closures[0].has_dr);
  EXPECT_EQ(no_dr.groups[0].dr.horizontal_m.count, 0u);
  EXPECT_EQ(no_dr.without_dr, 0u);
}

TEST_F(ClosureMetrics, CentreTimesBetweenTruthSamplesAreInterpolated) {
  // A straight northbound line at 2 m/s: B 20.25 s after A is 40.5 m ahead, whatever the samples.
  const Trajectory line = test::straightLine(200.0);
  std::ostringstream text;
  text << kHeader << "1,2," << line[10].utime_us + 125000 << "," << line[91].utime_us + 125000
       << ",0,accepted,none,40.5,0,0,0,0,0,10,0.5,0,0,0,0\n";
  write(text.str());
  std::vector<ClosureRecord> closures;
  std::string error;
  ASSERT_OK(readClosureCsv(path_, closures));
  const ClosureEvaluation ev = evaluateClosures(closures, line, nullptr, 1.0);
  ASSERT_TRUE(ev.closures[0].has_truth);
  EXPECT_NEAR(ev.closures[0].truth.translation_m.x(), 40.5, 1e-9);
  EXPECT_NEAR(ev.closures[0].closure_error.along_m, 0.0, 1e-9);
}

TEST_F(ClosureMetrics, ReaderNamesFileAndLineOfAProblem) {
  std::vector<ClosureRecord> closures;
  std::string error;
  write("subframe_id_a,subframe_id_b,utime_a_us,utime_b_us,status,dx_m,dy_m,dz_m\n");
  error = sss::testing::failureMessage(readClosureCsv(path_, closures));
  EXPECT_NE(error.find(path_ + ":1: the header has no column 'dheading_rad'"), std::string::npos) << error;

  write(std::string(kHeader) + "1,2,100,200,0,accepted,none,x,0,0,0,0,0,10,0.5,0,0,0,0\n");
  error = sss::testing::failureMessage(readClosureCsv(path_, closures));
  EXPECT_NE(error.find(path_ + ":4: dx_m 'x'"), std::string::npos) << error;

  write(std::string(kHeader) + "1,2,100,200,0,accepted\n");
  error = sss::testing::failureMessage(readClosureCsv(path_, closures));
  EXPECT_NE(error.find(":4: 6 fields"), std::string::npos) << error;

  error = sss::testing::failureMessage(readClosureCsv(path_ + ".missing", closures));
  EXPECT_NE(error.find("cannot open"), std::string::npos) << error;

  // Only the needed columns, no status: one "unknown" group.
  write("subframe_id_a,subframe_id_b,utime_a_us,utime_b_us,dx_m,dy_m,dz_m,dheading_rad\n1,2,100,200,1,2,3,0.1\n");
  ASSERT_OK(readClosureCsv(path_, closures));
  ASSERT_EQ(closures.size(), 1u);
  EXPECT_EQ(closures[0].status, "unknown");
  EXPECT_EQ(closures[0].round, -1);
  EXPECT_DOUBLE_EQ(closures[0].translation_m.z(), 3.0);
}

TEST_F(ClosureMetrics, HorizontalNeesUsesTheClosuresOwnCovariance) {
  // The columns sss-process writes after east_b_m; closure 0 (error along 0.3, lateral -0.2) with
  // sigmas 0.3 and 0.1 m and no correlation: NEES = 1 + 4 = 5; closure 1 (-0.3, 0.2) with a
  // correlated covariance [[0.09, 0.02], [0.02, 0.04]]: e^T C^-1 e = 2.3529...; a closure without
  // a usable covariance (zero) has none.
  std::string text = kHeader;
  text.insert(text.rfind("east_b_m") + 8, ",cov_xx_m2,cov_xy_m2,cov_yy_m2,sigma_heading_rad");
  const char* covariances[] = {",0.09,0,0.01,0.001\n", ",0.09,0.02,0.04,0.001\n", ",0,0,0,0\n"};
  for (size_t k = 0; k < perturbations_.size(); ++k) {
    std::string row = closureRow(truth_, perturbations_[k], truth_[perturbations_[k].a].utime_us,
                                 truth_[perturbations_[k].b].utime_us);
    row.pop_back();  // the newline
    text += row + covariances[k];
  }
  write(text);
  std::vector<ClosureRecord> closures;
  std::string error;
  ASSERT_OK(readClosureCsv(path_, closures));
  ASSERT_EQ(closures.size(), 3u);
  EXPECT_TRUE(closures[0].has_covariance);
  EXPECT_DOUBLE_EQ(closures[1].horizontal_covariance_m2(0, 1), 0.02);
  const ClosureEvaluation ev = evaluateClosures(closures, truth_, nullptr, 1.0);
  EXPECT_NEAR(ev.closures[0].horizontal_nees, 5.0, 1e-6);
  const Eigen::Vector2d e(-0.3, 0.2);
  Eigen::Matrix2d c;
  c << 0.09, 0.02, 0.02, 0.04;
  EXPECT_NEAR(ev.closures[1].horizontal_nees, e.dot(c.inverse() * e), 1e-6);
  EXPECT_TRUE(std::isnan(ev.closures[2].horizontal_nees));
  ASSERT_EQ(ev.groups.size(), 2u);
  EXPECT_EQ(ev.groups[0].nees_count, 2u);
  EXPECT_NEAR(ev.groups[0].mean_horizontal_nees, 0.5 * (5.0 + e.dot(c.inverse() * e)), 1e-6);
  EXPECT_EQ(ev.groups[1].nees_count, 0u);
  EXPECT_TRUE(std::isnan(ev.groups[1].mean_horizontal_nees));

  // A covariance column that is not a number: refused with the line.
  write(text.substr(0, text.rfind(",0,0,0,0")) + ",x,0,0,0\n");
  error = sss::testing::failureMessage(readClosureCsv(path_, closures));
  EXPECT_NE(error.find("cov_xx_m2"), std::string::npos) << error;
}

}  // namespace
}  // namespace sss::eval
