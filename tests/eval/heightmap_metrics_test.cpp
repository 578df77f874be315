// Heightmaps: MAE of an estimate with a known offset on another grid, NaN cells ignored, coverage,
// the writer/reader round trip and its file:line errors, and the error-map PNG.
#include "tools/eval/heightmap_metrics.hpp"
#include "tools/eval/run_report_internal.hpp"
#include "tests/support/status_assertions.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace sss::eval {
namespace {

namespace fs = std::filesystem;

// A tilted plane: bilinear resampling reproduces it exactly, so any error is the estimate's.
double planeDepthM(double north_m, double east_m) { return 40.0 + 0.02 * north_m - 0.01 * east_m; }

HeightmapRaster truthPlane() {
  HeightmapRaster truth;
  truth.rows = 201;
  truth.cols = 161;
  truth.resolution_m = 0.5;
  truth.north_min_m = -50.0;
  truth.east_min_m = -40.0;
  truth.depth_m.resize(static_cast<size_t>(truth.rows) * truth.cols);
  for (int r = 0; r < truth.rows; ++r) {
    for (int c = 0; c < truth.cols; ++c) truth.at(r, c) = static_cast<float>(planeDepthM(truth.northM(r), truth.eastM(c)));
  }
  return truth;
}

// 1.3 m cells from (-30.1, -20.3), offset +0.25 m, every 7th cell without data, and the top rows
// reaching past the truth's northern edge (50 m).
HeightmapRaster offsetEstimate(size_t& nan_cells, size_t& outside_cells) {
  HeightmapRaster estimate;
  estimate.rows = 70;
  estimate.cols = 40;
  estimate.resolution_m = 1.3;
  estimate.north_min_m = -30.1;
  estimate.east_min_m = -20.3;
  estimate.depth_m.resize(static_cast<size_t>(estimate.rows) * estimate.cols);
  nan_cells = outside_cells = 0;
  for (int r = 0; r < estimate.rows; ++r) {
    for (int c = 0; c < estimate.cols; ++c) {
      const size_t index = static_cast<size_t>(r) * estimate.cols + c;
      if (index % 7 == 3) {
        estimate.at(r, c) = std::numeric_limits<float>::quiet_NaN();
        ++nan_cells;
        continue;
      }
      estimate.at(r, c) = static_cast<float>(planeDepthM(estimate.northM(r), estimate.eastM(c)) + 0.25);
      if (estimate.northM(r) > 50.0) ++outside_cells;
    }
  }
  return estimate;
}

TEST(HeightmapCompare, MaeOfAKnownOffsetIsTheOffsetAndNanCellsAreIgnored) {
  const HeightmapRaster truth = truthPlane();
  size_t nan_cells = 0, outside_cells = 0;
  const HeightmapRaster estimate = offsetEstimate(nan_cells, outside_cells);
  ASSERT_GT(outside_cells, 0u);
  const HeightmapErrorResult result = compareHeightmaps(truth, estimate);
  ASSERT_TRUE(result.ok) << result.error;
  const size_t cells = 70 * 40;
  EXPECT_EQ(result.estimate_cells, cells);
  EXPECT_EQ(result.cells_with_data, cells - nan_cells);
  EXPECT_EQ(result.compared_cells, cells - nan_cells - outside_cells);
  EXPECT_DOUBLE_EQ(result.coverage_fraction, static_cast<double>(cells - nan_cells) / cells);
  EXPECT_NEAR(result.covered_area_m2, (cells - nan_cells) * 1.3 * 1.3, 1e-6);
  // float32 depths of ~40 m carry ~4e-6 m of rounding.
  EXPECT_NEAR(result.abs_error_m.mean, 0.25, 2e-5);
  EXPECT_NEAR(result.abs_error_m.rmse, 0.25, 2e-5);
  EXPECT_NEAR(result.abs_error_m.median, 0.25, 2e-5);
  EXPECT_NEAR(result.abs_error_m.max, 0.25, 2e-5);
  EXPECT_NEAR(result.mean_signed_error_m, 0.25, 2e-5);
  // Error map on the estimate's grid, NaN where nothing was compared.
  ASSERT_EQ(result.error_map.rows, estimate.rows);
  EXPECT_TRUE(std::isnan(result.error_map.at(0, 3)));
  EXPECT_NEAR(result.error_map.at(0, 0), 0.25, 2e-5);
  EXPECT_TRUE(std::isnan(result.error_map.at(estimate.rows - 1, 0)));  // north of the truth
}

TEST(HeightmapCompare, TruthHolesAreNotCompared) {
  HeightmapRaster truth = truthPlane();
  truth.at(100, 80) = std::numeric_limits<float>::quiet_NaN();  // (0, 0)
  const HeightmapRaster estimate = truthPlane();
  const HeightmapErrorResult result = compareHeightmaps(truth, estimate);
  ASSERT_TRUE(result.ok);
  // On the same grid every estimate cell centre is a truth cell centre: only the hole's own cell
  // is lost, not its bilinear neighbours (they weigh it 0).
  EXPECT_EQ(result.cells_with_data, result.estimate_cells);
  EXPECT_EQ(result.compared_cells, result.cells_with_data - 1);
  EXPECT_TRUE(std::isnan(result.error_map.at(100, 80)));
  EXPECT_NEAR(result.abs_error_m.max, 0.0, 1e-6);
}

TEST(HeightmapCompare, NoDataOrNoOverlapIsAnError) {
  const HeightmapRaster truth = truthPlane();
  HeightmapRaster empty = truth;
  std::fill(empty.depth_m.begin(), empty.depth_m.end(), std::numeric_limits<float>::quiet_NaN());
  EXPECT_FALSE(compareHeightmaps(truth, empty).ok);
  HeightmapRaster far = truth;
  far.north_min_m += 10000.0;
  const HeightmapErrorResult result = compareHeightmaps(truth, far);
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.error.find("origin"), std::string::npos);
  EXPECT_FALSE(compareHeightmaps(truth, HeightmapRaster()).ok);
}

TEST(HeightmapIo, WritesAndReadsTheSimulatorFormat) {
  const fs::path dir = fs::temp_directory_path() / "sss_eval_heightmap_io";
  fs::remove_all(dir);
  fs::create_directories(dir);
  size_t nan_cells = 0, outside_cells = 0;
  HeightmapRaster estimate = offsetEstimate(nan_cells, outside_cells);
  estimate.description = "test reconstruction\nsecond comment line";
  std::string error;
  ASSERT_OK(writeHeightmap((dir / "recon.yaml").string(), estimate));
  EXPECT_TRUE(fs::exists(dir / "recon_depth.f32"));
  EXPECT_EQ(fs::file_size(dir / "recon_depth.f32"), estimate.depth_m.size() * 4);
  ASSERT_OK(writeHeightmap((dir / "prefix").string(), estimate));
  EXPECT_TRUE(fs::exists(dir / "prefix.yaml"));
  EXPECT_TRUE(fs::exists(dir / "prefix_depth.f32"));

  HeightmapRaster read;
  ASSERT_OK(readHeightmap((dir / "recon.yaml").string(), read));
  EXPECT_EQ(read.rows, estimate.rows);
  EXPECT_EQ(read.cols, estimate.cols);
  EXPECT_DOUBLE_EQ(read.resolution_m, estimate.resolution_m);
  EXPECT_DOUBLE_EQ(read.north_min_m, estimate.north_min_m);
  EXPECT_DOUBLE_EQ(read.east_min_m, estimate.east_min_m);
  ASSERT_EQ(read.depth_m.size(), estimate.depth_m.size());
  for (size_t i = 0; i < read.depth_m.size(); ++i) {
    if (std::isnan(estimate.depth_m[i])) {
      EXPECT_TRUE(std::isnan(read.depth_m[i]));
    } else {
      EXPECT_EQ(read.depth_m[i], estimate.depth_m[i]);
    }
  }
  error = sss::testing::failureMessage(writeHeightmap("/nonexistent/dir/map", estimate));
  EXPECT_NE(error.find("/nonexistent/dir/map_depth.f32"), std::string::npos);
  HeightmapRaster bad = estimate;
  bad.depth_m.pop_back();
  error = sss::testing::failureMessage(writeHeightmap((dir / "bad").string(), bad));
  fs::remove_all(dir);
}

TEST(HeightmapIo, ReportsBadFilesWithFileAndLine) {
  const fs::path dir = fs::temp_directory_path() / "sss_eval_heightmap_bad";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  {
    std::ofstream raw(dir / "d.f32", std::ios::binary);
    const float values[6] = {1, 2, 3, 4, 5, 6};
    raw.write(reinterpret_cast<const char*>(values), sizeof values);
  }
  HeightmapRaster raster;
  std::string error;
  const std::string header = "rows: 2\ncols: 3\nresolution_m: 1\nnorth_min_m: 0\neast_min_m: 0\n";
  ASSERT_OK(readHeightmap(write("ok.yaml", header + "depth_file: d.f32\n"), raster));
  EXPECT_EQ(raster.at(1, 2), 6.0f);

  error = sss::testing::failureMessage(
      readHeightmap(write("type.yaml", "rows: 2\ncols: three\nresolution_m: 1\nnorth_min_m: 0\neast_min_m: 0\n"
                                       "depth_file: d.f32\n"), raster));
  EXPECT_NE(error.find("type.yaml:2: cols: 'three' is not an integer"), std::string::npos) << error;

  error = sss::testing::failureMessage(readHeightmap(write("missing.yaml", "rows: 2\ncols: 3\n"), raster));
  EXPECT_NE(error.find("missing key 'resolution_m'"), std::string::npos) << error;

  error = sss::testing::failureMessage(
      readHeightmap(write("size.yaml", "rows: 3\ncols: 3\nresolution_m: 1\nnorth_min_m: 0\neast_min_m: 0\n"
                                       "depth_file: d.f32\n"), raster));
  EXPECT_NE(error.find("24 bytes, but rows x cols x 4 = 36"), std::string::npos) << error;

  error = sss::testing::failureMessage(readHeightmap(write("nofile.yaml", header + "depth_file: none.f32\n"), raster));
  EXPECT_NE(error.find("nofile.yaml:6: depth_file"), std::string::npos) << error;

  error = sss::testing::failureMessage(readHeightmap(write("syntax.yaml", "rows: 2\ncols: [3\n"), raster));
  EXPECT_NE(error.find("syntax.yaml:"), std::string::npos) << error;

  error = sss::testing::failureMessage(
      readHeightmap(write("res.yaml", "rows: 2\ncols: 3\nresolution_m: -1\nnorth_min_m: 0\neast_min_m: 0\n"
                                      "depth_file: d.f32\n"), raster));
  EXPECT_NE(error.find("res.yaml:3: resolution_m"), std::string::npos) << error;

  error = sss::testing::failureMessage(
      readHeightmap(write("huge.yaml", "rows: 2000000000\ncols: 2000000000\nresolution_m: 1\n"
                                       "north_min_m: 0\neast_min_m: 0\ndepth_file: d.f32\n"), raster));
  EXPECT_NE(error.find("huge.yaml:1:"), std::string::npos) << error;

  error = sss::testing::failureMessage(readHeightmap((dir / "absent.yaml").string(), raster));
  EXPECT_NE(error.find("absent.yaml: cannot open"), std::string::npos) << error;
  fs::remove_all(dir);
}

TEST(ReportScale, NiceCeilRoundsUpToOneTwoFive) {
  using report_internal::niceCeil;
  EXPECT_DOUBLE_EQ(niceCeil(0.25), 0.5);
  EXPECT_DOUBLE_EQ(niceCeil(0.2), 0.2);
  EXPECT_DOUBLE_EQ(niceCeil(3.0), 5.0);
  EXPECT_DOUBLE_EQ(niceCeil(7.0), 10.0);
  EXPECT_DOUBLE_EQ(niceCeil(0.0), 1.0);
}

}  // namespace
}  // namespace sss::eval
