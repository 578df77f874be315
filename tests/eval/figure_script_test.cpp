// The figures drawn by report_figures.py from the data figure_script writes: every kind of figure
// on small hand-made data (a straight truth and a shifted estimate, small rasters), that the
// picture follows the data, and the one-line problem when python, the script or a raster is missing.
#include "tools/eval/figure_script.hpp"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

namespace sss::eval {
namespace {

namespace fs = std::filesystem;

class FigureScript : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sss_figure_script_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  FigureBatch batch(const std::string& name) const { return {(dir_ / name).string(), Json::array(), ""}; }

  // Truth straight north for 200 m; the estimate the same line east_offset_m to the east.
  static void addTrajectoryMap(FigureBatch& figures, const std::string& file, double east_offset_m) {
    std::vector<Eigen::Vector2d> truth, estimate;
    for (int k = 0; k <= 200; ++k) {
      truth.emplace_back(k, 0.0);
      estimate.emplace_back(k, east_offset_m);
    }
    Json& map = addFigure(figures, "map", file, "straight line");
    map["lines"] = {mapLine("truth", truth, "black", 2.0, true, true), mapLine("estimate", estimate, paletteColour(1))};
  }

  // A depth-like raster: a slope with a hole of no data.
  static HeightmapRaster slope() {
    HeightmapRaster map;
    map.rows = 60;
    map.cols = 40;
    map.resolution_m = 0.5;
    map.north_min_m = -10.0;
    map.east_min_m = 5.0;
    for (int r = 0; r < map.rows; ++r) {
      for (int c = 0; c < map.cols; ++c) map.depth_m.push_back(20.0f + 0.1f * static_cast<float>(r));
    }
    for (int r = 20; r < 30; ++r) {
      for (int c = 10; c < 20; ++c) map.at(r, c) = std::numeric_limits<float>::quiet_NaN();
    }
    return map;
  }

  fs::path dir_;
};

cv::Mat readPng(const fs::path& path) { return cv::imread(path.string(), cv::IMREAD_COLOR); }

// Pixels that are not (near) white: what was drawn.
int inkedPixels(const cv::Mat& image) {
  cv::Mat channels[3];
  cv::split(image, channels);
  cv::Mat dark = (channels[0] < 200) | (channels[1] < 200) | (channels[2] < 200);
  return cv::countNonZero(dark);
}

// Pixels near tab10 orange ("C1", RGB 255 127 14): the estimate's line and its legend entry.
int orangePixels(const cv::Mat& image) {
  cv::Mat mask;
  cv::inRange(image, cv::Scalar(0, 97, 215), cv::Scalar(54, 157, 255), mask);  // BGR, +-40 or so
  return cv::countNonZero(mask);
}

TEST_F(FigureScript, TrajectoryMapIsDrawnAndFollowsTheEstimate) {
  FigureBatch figures = batch("data");
  addTrajectoryMap(figures, "near.png", 2.0);
  addTrajectoryMap(figures, "far.png", 40.0);
  const FigureRun run = drawFigures(figures, dir_.string());
  ASSERT_TRUE(run.problem.empty()) << run.problem;
  ASSERT_EQ(run.written.size(), 2u);
  EXPECT_EQ(run.written[0], (dir_ / "near.png").string());
  EXPECT_TRUE(fs::exists(dir_ / "data" / "figures.json"));

  const cv::Mat near = readPng(dir_ / "near.png"), far = readPng(dir_ / "far.png");
  ASSERT_FALSE(near.empty());
  ASSERT_FALSE(far.empty());
  // 11 in at 100 dpi wide; the height follows the map's aspect within 4..14 in.
  EXPECT_EQ(near.cols, 1100);
  EXPECT_GE(near.rows, 400);
  EXPECT_LE(near.rows, 1400);
  // Axes, ticks, two lines and the legend: far more than a blank page's few stray pixels.
  EXPECT_GT(inkedPixels(near), 5000);
  // The estimate itself: a 200 m line at about 5 px per metre is ~1000 px long.
  EXPECT_GT(orangePixels(near), 500);
  EXPECT_GT(orangePixels(far), 500);
  // A different estimate draws a different picture (a 40 m offset widens the map's extent).
  EXPECT_TRUE(near.size() != far.size() || cv::norm(near, far, cv::NORM_L1) > 0.0);
}

TEST_F(FigureScript, DrawsCurvesMosaicsDepthAndErrorMaps) {
  FigureBatch figures = batch("data");
  std::vector<ErrorSample> series;
  for (int k = 0; k < 100; ++k) {
    ErrorSample s;
    s.utime_us = 1'000'000'000LL + k * 1'000'000LL;
    s.horizontal_m = 0.01 * k;
    s.aligned_horizontal_m = k == 50 ? std::numeric_limits<double>::quiet_NaN() : 0.005 * k;  // a gap
    series.push_back(s);
  }
  Json& curves = addFigure(figures, "curves", "error.png", "error over time");
  curves["curves"] = Json::array();
  for (Json& curve : horizontalErrorCurves("DR", series, paletteColour(1), series.front().utime_us)) {
    curves["curves"].push_back(std::move(curve));
  }
  SurveyLine line;
  line.index = 0;
  line.start_utime_us = series[10].utime_us;
  line.end_utime_us = series[60].utime_us;
  curves["bands"] = surveyLineBands({line}, series.front().utime_us);
  ASSERT_EQ(curves["bands"].size(), 1u);
  EXPECT_NEAR(curves["bands"][0]["x_max"].get<double>(), 1.0, 1e-9);  // 60 s = 1 min

  GreyMosaic mosaic;
  mosaic.rows = 80;
  mosaic.cols = 50;
  mosaic.resolution_m = 0.5;
  mosaic.north_max_m = 30.0;
  mosaic.east_min_m = -10.0;
  for (int k = 0; k < mosaic.rows * mosaic.cols; ++k) mosaic.pixels.push_back(static_cast<uint8_t>(k % 251));
  Json& mosaics = addFigure(figures, "mosaics", "mosaics.png", "two mosaics");
  mosaics["panels"] = Json::array();
  for (const char* name : {"dr", "slam"}) {
    Json panel = mosaicRaster(figures, mosaic, name);
    panel["label"] = name;
    mosaics["panels"].push_back(std::move(panel));
  }
  addFigure(figures, "depth", "depth.png", "depth")["raster"] = heightmapRaster(figures, slope(), "depth");
  Json& error_map = addFigure(figures, "error_map", "error_map.png", "error map");
  error_map["raster"] = heightmapRaster(figures, slope(), "error");
  error_map["limit_m"] = 0.0;  // the script picks the p99

  const FigureRun run = drawFigures(figures, dir_.string());
  ASSERT_TRUE(run.problem.empty()) << run.problem;
  EXPECT_TRUE(run.missing.empty());
  const cv::Mat error_png = readPng(dir_ / "error.png");
  EXPECT_EQ(error_png.cols, 1200);
  EXPECT_EQ(error_png.rows, 550);
  EXPECT_EQ(readPng(dir_ / "mosaics.png").cols, 1560);
  for (const char* name : {"depth.png", "error_map.png"}) {
    const cv::Mat image = readPng(dir_ / name);
    EXPECT_EQ(image.cols, 900) << name;
    EXPECT_GT(inkedPixels(image), 20000) << name;  // the raster itself, not only the axes
  }
}

TEST_F(FigureScript, WithoutPythonSaysSoOnceAndNamesSetupDeps) {
  FigureBatch figures = batch("data");
  addTrajectoryMap(figures, "a.png", 1.0);
  addTrajectoryMap(figures, "b.png", 2.0);
  FigureScriptOptions options;
  options.python = (dir_ / "no-python3").string();
  const FigureRun run = drawFigures(figures, dir_.string(), options);
  EXPECT_TRUE(run.written.empty());
  EXPECT_EQ(run.missing, (std::vector<std::string>{"a.png", "b.png"}));
  EXPECT_NE(run.problem.find(options.python + " not found"), std::string::npos) << run.problem;
  EXPECT_NE(run.problem.find("tools/setup-deps.sh"), std::string::npos) << run.problem;
  EXPECT_EQ(run.problem.find('\n'), std::string::npos) << run.problem;  // one line
  EXPECT_FALSE(fs::exists(dir_ / "a.png"));
}

// The real interpreter without its site packages (-S): numpy and matplotlib cannot be imported.
TEST_F(FigureScript, WithoutMatplotlibSaysToInstallIt) {
  FigureBatch figures = batch("data");
  addTrajectoryMap(figures, "a.png", 1.0);
  FigureScriptOptions options;
  options.python = (dir_ / "python3-without-packages").string();
  {
    std::ofstream wrapper(options.python);
    wrapper << "#!/bin/sh\nexec /usr/bin/python3 -S \"$@\"\n";
  }
  fs::permissions(options.python, fs::perms::owner_all);
  const FigureRun run = drawFigures(figures, dir_.string(), options);
  EXPECT_EQ(run.missing.size(), 1u);
  EXPECT_NE(run.problem.find("matplotlib is not installed"), std::string::npos) << run.problem;
  EXPECT_NE(run.problem.find("tools/setup-deps.sh"), std::string::npos) << run.problem;
}

TEST_F(FigureScript, MissingScriptIsNamed) {
  FigureBatch figures = batch("data");
  addTrajectoryMap(figures, "a.png", 1.0);
  FigureScriptOptions options;
  options.script = (dir_ / "gone.py").string();
  const FigureRun run = drawFigures(figures, dir_.string(), options);
  EXPECT_EQ(run.missing.size(), 1u);
  EXPECT_NE(run.problem.find(options.script + " is missing"), std::string::npos) << run.problem;
}

TEST_F(FigureScript, OneBadFigureCostsOnlyItself) {
  FigureBatch figures = batch("data");
  addTrajectoryMap(figures, "good.png", 1.0);
  addFigure(figures, "depth", "bad.png", "raster that is not there")["raster"] =
      Json{{"npy", "absent.npy"}, {"resolution_m", 1.0}, {"north_min_m", 0.0}, {"east_min_m", 0.0}};
  const FigureRun run = drawFigures(figures, dir_.string());
  EXPECT_EQ(run.written, (std::vector<std::string>{(dir_ / "good.png").string()}));
  EXPECT_EQ(run.missing, (std::vector<std::string>{"bad.png"}));
  EXPECT_NE(run.problem.find("bad.png"), std::string::npos) << run.problem;
  EXPECT_NE(run.problem.find("absent.npy"), std::string::npos) << run.problem;  // the script's own message
  EXPECT_EQ(run.problem.find('\n'), std::string::npos) << run.problem;
}

TEST_F(FigureScript, StalePngsOfTheSameNameAreNotTakenForNewOnes) {
  FigureBatch figures = batch("data");
  addTrajectoryMap(figures, "a.png", 1.0);
  { std::ofstream(dir_ / "a.png") << "old"; }
  FigureScriptOptions options;
  options.python = (dir_ / "no-python3").string();
  const FigureRun run = drawFigures(figures, dir_.string(), options);
  EXPECT_EQ(run.missing.size(), 1u);
  EXPECT_FALSE(fs::exists(dir_ / "a.png"));
}

}  // namespace
}  // namespace sss::eval
