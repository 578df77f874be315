// The survey products a hydrographer opens at once, end to end on a short simulated survey off
// Sydney (UTM zone 56 south) with three hand-placed targets: the GeoTIFFs read back with GDAL put
// each target at its true coordinates, the heightmap and coverage rasters hold the run's values,
// and the corrected copy of the JSF carries slam.tum in every ping with every other byte unchanged.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "drivers/edgetech/jsf_file_reader.hpp"
#include "drivers/edgetech/jsf_format.hpp"
#include "pipeline/core/geodesy.hpp"
#include "pipeline/core/pose.hpp"
#include "tests/support/geotiff_read.hpp"
#include "tools/eval/trajectory_io.hpp"
#include "tools/process/offline_runner.hpp"
#include "tests/support/status_assertions.hpp"

namespace fs = std::filesystem;

namespace {

struct Target {
  double north_m, east_m;
};
// Between the two lines (20 m from each), and beyond either line (22 m and 12 m out).
const std::vector<Target> kTargets = {{60.0, 20.0}, {115.0, 52.0}, {90.0, -22.0}};

std::vector<uint8_t> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

class SurveyProductsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = (fs::temp_directory_path() / ("sss_products_test_" + std::to_string(getpid()))).string();
    fs::create_directories(root_);
    // Bright flat discs (reflectivity 2, 1.5 m radius, 0.1 m high: a mat or a plate, not a boulder)
    // on a textured seabed without random boulders, so that the brightest return near each target
    // is the target. A tall target would not do: a mosaic lays its top over towards the sonar
    // (h_target x altitude / ground range: 0.7 m for 0.8 m at 18 m altitude and 20 m out) and shows
    // the face turned to the sonar, which is side-scan physics, not the geo-reference under test.
    std::ofstream config(root_ + "/targets.yaml");
    config << "sim:\n  seabed:\n    boulders_per_hectare: 0\n    objects:\n";
    for (const Target& t : kTargets) {
      config << "      - {north_m: " << t.north_m << ", east_m: " << t.east_m
             << ", radius_m: 1.5, height_m: 0.1, reflectivity: 2.0}\n";
    }
    config.close();
    const std::string command = std::string(SSS_SIM_PATH) + " --out " + root_ + "/mission --config " + root_ +
                                "/targets.yaml --lines 2 --line-length-m 150 --line-spacing-m 40 --seed 5" +
                                " --origin-latitude-deg -33.85 --origin-longitude-deg 151.28 > " + root_ +
                                "/sim.log 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << "sss-sim failed, see " << root_ << "/sim.log";
    sss::offline::OfflineRequest request;
    request.sonar_path = root_ + "/mission/sonar.jsf";
    request.ins_path = root_ + "/mission/ins.nmea";
    request.out_dir = root_ + "/run";
    request.corrected_dir = root_ + "/run/corrected";
    result_ = sss::offline::runOffline(request);
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }

  static std::string root_;
  static sss::offline::OfflineResult result_;
};
std::string SurveyProductsTest::root_;
sss::offline::OfflineResult SurveyProductsTest::result_;

TEST_F(SurveyProductsTest, MosaicGeoTiffsPutEveryTargetAtItsTrueUtmCoordinatesWithinTwoPixels) {
  ASSERT_TRUE(result_.ok) << result_.error;
  EXPECT_EQ(result_.summary.geotiff_epsg, 32756);
  EXPECT_EQ(result_.summary.geotiff_crs, "WGS 84 / UTM zone 56S");
  const auto truth = sss::eval::readTum(root_ + "/mission/ground_truth.tum");
  ASSERT_TRUE(truth.ok && truth.origin) << truth.error;
  const sss::core::LocalTangentPlane sim_frame(truth.origin->latitude_deg, truth.origin->longitude_deg);

  for (const char* name : {"mosaic_slam.tif", "mosaic_dr.tif"}) {
    const auto tif = sss::test::readGeoTiff(root_ + "/run/" + name);
    ASSERT_TRUE(tif.ok) << tif.error;
    EXPECT_EQ(tif.epsg, 32756) << name;
    EXPECT_EQ(tif.data_type, "Byte");
    ASSERT_TRUE(tif.has_nodata);
    EXPECT_EQ(tif.nodata, 0.0);
    const double pixel_m = tif.transform[1];
    EXPECT_DOUBLE_EQ(pixel_m, 0.5);
    for (const Target& target : kTargets) {
      const auto geo = sss::core::LocalTangentPlane(sim_frame).toGeodetic({target.north_m, target.east_m, 0.0});
      double easting = 0.0, northing = 0.0;
      sss::test::utmOf(geo.latitude_deg, geo.longitude_deg, 32756, easting, northing);
      int row = 0, col = 0;
      ASSERT_TRUE(tif.pixelOf(easting, northing, row, col)) << name;
      // The target's return: the brightest pixels within 5 m of where it should be (the disc; the
      // rest of the window is sediment at most half as bright).
      const int window = static_cast<int>(5.0 / pixel_m);
      double brightest = 0.0;
      for (int r = std::max(0, row - window); r <= std::min(tif.rows - 1, row + window); ++r)
        for (int c = std::max(0, col - window); c <= std::min(tif.cols - 1, col + window); ++c)
          brightest = std::max(brightest, tif.at(r, c));
      double sum_x = 0.0, sum_y = 0.0;
      int count = 0;
      for (int r = std::max(0, row - window); r <= std::min(tif.rows - 1, row + window); ++r) {
        for (int c = std::max(0, col - window); c <= std::min(tif.cols - 1, col + window); ++c) {
          if (tif.at(r, c) < 0.7 * brightest) continue;
          sum_x += tif.centreX(c);
          sum_y += tif.centreY(r);
          ++count;
        }
      }
      ASSERT_GT(count, 0);
      const double off_m = std::hypot(sum_x / count - easting, sum_y / count - northing);
      std::printf("%s: target at N %.0f E %.0f found %.2f m (%.1f px) from its true position (%d px of >= 70 %% of %g)\n",
                  name, target.north_m, target.east_m, off_m, off_m / pixel_m, count, brightest);
      EXPECT_GE(brightest, 200.0) << "the target must stand out for this test to mean anything";
      EXPECT_LE(off_m, 2.0 * pixel_m) << name << ": target at N " << target.north_m << " E " << target.east_m;
    }
  }
}

TEST_F(SurveyProductsTest, HeightmapAndCoverageGeoTiffsHoldTheRunsValues) {
  ASSERT_TRUE(result_.ok) << result_.error;
  const auto depth = sss::test::readGeoTiff(root_ + "/run/heightmap.tif");
  ASSERT_TRUE(depth.ok) << depth.error;
  EXPECT_EQ(depth.epsg, 32756);
  EXPECT_EQ(depth.data_type, "Float32");
  EXPECT_EQ(depth.nodata, -9999.0);
  // Nearest-neighbour warping copies values: every depth in the GeoTIFF is one of the grid's, and
  // about as many cells hold one (the rotated grid gains or loses a few along its edges).
  std::vector<float> grid_depths;
  {
    std::ifstream in(root_ + "/run/heightmap_depth.f32", std::ios::binary);
    float value = 0.0f;
    while (in.read(reinterpret_cast<char*>(&value), sizeof value)) {
      if (std::isfinite(value)) grid_depths.push_back(value);
    }
  }
  ASSERT_GT(grid_depths.size(), 50u);
  const std::multiset<float> known(grid_depths.begin(), grid_depths.end());
  size_t valid = 0;
  for (double v : depth.values) {
    if (v == -9999.0) continue;
    ++valid;
    EXPECT_TRUE(known.count(static_cast<float>(v))) << v;
    EXPECT_GT(v, 30.0) << "depths are positive down (the simulated seabed lies ~60 m down)";
  }
  EXPECT_NEAR(static_cast<double>(valid), static_cast<double>(grid_depths.size()), 0.1 * grid_depths.size());

  const auto depth_dr = sss::test::readGeoTiff(root_ + "/run/heightmap_dr.tif");
  ASSERT_TRUE(depth_dr.ok) << depth_dr.error;
  EXPECT_EQ(depth_dr.epsg, 32756);
  EXPECT_EQ(depth_dr.nodata, -9999.0);

  const auto coverage = sss::test::readGeoTiff(root_ + "/run/coverage.tif");
  ASSERT_TRUE(coverage.ok) << coverage.error;
  EXPECT_EQ(coverage.epsg, 32756);
  double most = 0.0;
  for (double v : coverage.values) most = std::max(most, v);
  EXPECT_EQ(most, 2.0) << "two survey lines";
}

TEST_F(SurveyProductsTest, CorrectedJsfCarriesSlamInEveryPingAndIsOtherwiseTheInput) {
  ASSERT_TRUE(result_.ok) << result_.error;
  const auto& s = result_.summary;
  const std::string copy = root_ + "/run/corrected/sonar.jsf";
  EXPECT_EQ(s.corrected_copy, copy);
  EXPECT_EQ(s.corrected_records, 2 * s.pings) << "port and starboard of every ping";
  EXPECT_EQ(s.corrected_records_without_pose, 0u);

  const auto slam = sss::eval::readTum(root_ + "/run/slam.tum");
  ASSERT_TRUE(slam.ok && slam.origin) << slam.error;
  const sss::core::LocalTangentPlane frame(slam.origin->latitude_deg, slam.origin->longitude_deg);
  std::map<int64_t, sss::core::Pose> slam_at;
  for (const auto& p : slam.poses) slam_at[p.utime_us] = p.T_world_body;

  sss::edgetech::JsfFileReader reader(copy);
  ASSERT_TRUE(reader.isOpen()) << reader.error();
  sss::edgetech::JsfMessage message;
  std::set<size_t> allowed;
  double worst_horizontal_m = 0.0, worst_heading_deg = 0.0, worst_depth_m = 0.0;
  size_t compared = 0;
  while (reader.next(message)) {
    if (message.header.message_type != sss::edgetech::kJsfSonarData) continue;
    for (size_t field : {30, 31}) allowed.insert(message.stream_offset + 16 + field);
    for (size_t k = 80; k < 90; ++k) allowed.insert(message.stream_offset + 16 + k);
    for (size_t k = 136; k < 140; ++k) allowed.insert(message.stream_offset + 16 + k);
    for (size_t k = 172; k < 178; ++k) allowed.insert(message.stream_offset + 16 + k);
    const auto decoded = sss::edgetech::decodeSonarData(message.header, message.body.data(), message.body.size());
    ASSERT_OK(decoded);
    const auto found = slam_at.find(decoded->ping_time_us);
    ASSERT_NE(found, slam_at.end()) << "a ping time slam.tum does not have";
    const auto& r = *decoded;
    const Eigen::Vector3d read_back = frame.toNed({r.latitude_deg, r.longitude_deg, r.depth_m});
    worst_horizontal_m = std::max(worst_horizontal_m, (read_back - found->second.translation).head<2>().norm());
    worst_depth_m = std::max(worst_depth_m, std::abs(read_back.z() - found->second.translation.z()));
    const double heading_rad = sss::core::eulerFromQuaternion(found->second.rotation).heading_rad;
    worst_heading_deg =
        std::max(worst_heading_deg, std::abs(std::remainder(r.heading_rad - heading_rad, 2 * M_PI)) * 180.0 / M_PI);
    ++compared;
  }
  EXPECT_EQ(compared, 2 * s.pings);
  // JSF stores 1e-4 minute of arc (0.19 m of latitude, 0.15 m of longitude here at 33.85 S) and
  // millimetres: half a quantum of each, plus slam.tum's own rounding.
  std::printf("corrected JSF against slam.tum: horizontal %.3f m, depth %.4f m, heading %.4f deg (worst)\n",
              worst_horizontal_m, worst_depth_m, worst_heading_deg);
  EXPECT_LT(worst_horizontal_m, 0.13);
  EXPECT_LT(worst_depth_m, 0.002);
  EXPECT_LT(worst_heading_deg, 0.006);

  // The SLAM navigation differs from what was recorded, and only the navigation bytes changed.
  const std::vector<uint8_t> before = readBytes(root_ + "/mission/sonar.jsf"), after = readBytes(copy);
  ASSERT_EQ(before.size(), after.size());
  size_t changed = 0, outside = 0;
  for (size_t i = 0; i < before.size(); ++i) {
    if (before[i] == after[i]) continue;
    ++changed;
    outside += allowed.count(i) ? 0 : 1;
  }
  EXPECT_EQ(outside, 0u) << "bytes outside the pings' navigation fields changed";
  EXPECT_GT(changed, s.pings) << "the corrected navigation differs from the recorded one";
}

}  // namespace
