// What sss-optimiser leaves in its products folder, from the engine after a synthetic lawnmower (3
// lines of 4 subframes, closures with seabed correspondences): every file sss-process writes that
// needs no sonar file, consistent with the engine, GeoTIFFs in the origin's UTM zone; without an
// origin, no file that needs one; across the antimeridian, GeoJSON cut there.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/optimiser/optimiser_engine.hpp"
#include "products/footprints.hpp"
#include "tools/fixtures/synthetic_subframes.hpp"
#include "products/live_products.hpp"
#include "tests/optimiser/pose_graph_test_helpers.hpp"
#include "tests/support/geotiff_read.hpp"

namespace fs = std::filesystem;

namespace sss::products {
namespace {

namespace synthetic = sss::optimiser::synthetic;

std::string readText(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// One engine for both tests: a full smoothing is seconds under the sanitizers.
class LiveProductsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    engine_ = new sss::optimiser::OptimiserEngine(sss::optimiser::OptimiserEngineOptions{});
    mosaics_ = new MosaicStore(sss::subframe::PictureOptions{}, std::numeric_limits<size_t>::max());
    const synthetic::Mission mission = synthetic::makeLawnmowerMission(sss::optimiser::test_helpers::missionOptions(3));
    synthetic::SubframeOptions options;
    options.correspondences_per_closure = 20;  // enough for seabed points
    options.pings_per_subframe = 50;  // 100 m subframes of 2 m pings: the mosaics are drawn in seconds under ASan
    options.ping_spacing_m = 2.0;
    std::vector<std::vector<sss::core::Pose>> truth;
    std::vector<sss::core::Subframe> subframes = synthetic::makeSubframes(mission, options, &truth);
    for (auto& s : subframes) {
      // The synthetic subframes carry no image: give each a plain 60 m swath at the mosaic's 0.5 m
      // (lines 100 m apart: a 20 m strip between two lines is seen twice).
      s.geometry.bins_per_side = 120;
      s.geometry.bin_size_m = 0.5;
      s.geometry.first_bin_range_m = 0.0;
      s.image.assign(static_cast<size_t>(s.rows()) * s.cols(), 1.0f);
      s.mask.assign(s.image.size(), sss::core::kMaskValid);
      ASSERT_TRUE(engine_->addSubframe(s).ok);
      mosaics_->add(s);
      footprints_.push_back(footprintOf(s));
    }
    for (size_t c = 0; c < mission.closures.size(); ++c) {
      ASSERT_TRUE(engine_->addLoopClosure(synthetic::makeMatcherClosure(mission, c, truth, options)).ok);
    }
    engine_->finish();
  }
  static void TearDownTestSuite() {
    delete engine_;
    delete mosaics_;
  }
  void SetUp() override {
    dir_ = (fs::temp_directory_path() / ("sss_live_products_test_" + std::to_string(getpid()))).string();
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string dir_;
  static sss::optimiser::OptimiserEngine* engine_;
  static MosaicStore* mosaics_;
  static std::vector<SubframeFootprint> footprints_;
};
sss::optimiser::OptimiserEngine* LiveProductsTest::engine_ = nullptr;
MosaicStore* LiveProductsTest::mosaics_ = nullptr;
std::vector<SubframeFootprint> LiveProductsTest::footprints_;

TEST_F(LiveProductsTest, EveryProductIsWrittenAndTheRastersLandInTheOriginsUtmZone) {
  std::vector<std::string> messages;
  ASSERT_TRUE(writeLiveProducts(*engine_, *mosaics_, footprints_, dir_, sss::core::MissionOrigin{59.35, 18.07}, messages))
      << (messages.empty() ? "" : messages.back());
  ASSERT_FALSE(messages.empty());
  EXPECT_NE(messages.back().find("products written to " + dir_), std::string::npos) << messages.back();
  for (const char* file :
       {"slam.tum", "navigation.csv", "navigation.nmea", "loop_closures.csv", "track.geojson", "subframes.geojson",
        "coverage.yaml", "coverage.png", "coverage.tif", "mosaic_dr.png", "mosaic_slam.png", "mosaic_slam.yaml",
        "mosaic_dr.tif", "mosaic_slam.tif", "bathymetry.ply", "heightmap.yaml", "heightmap.tif"}) {
    EXPECT_TRUE(fs::is_regular_file(dir_ + "/" + file)) << file;
  }
  // A navigation row per ping pose, the closures with their decisions, one footprint per subframe.
  const std::string navigation = readText(dir_ + "/navigation.csv");
  size_t rows = 0;
  for (size_t at = navigation.find("\n2"); at != std::string::npos; at = navigation.find("\n2", at + 1)) ++rows;
  EXPECT_EQ(rows, engine_->pingTrajectory(true).size());
  EXPECT_NE(readText(dir_ + "/loop_closures.csv").find(",accepted,"), std::string::npos);
  const std::string polygons = readText(dir_ + "/subframes.geojson");
  size_t features = 0;
  for (size_t at = polygons.find("\"Polygon\""); at != std::string::npos; at = polygons.find("\"Polygon\"", at + 1))
    ++features;
  EXPECT_EQ(features, footprints_.size());
  for (const char* raster : {"coverage.tif", "mosaic_slam.tif", "heightmap.tif"}) {
    const auto tif = sss::test::readGeoTiff(dir_ + "/" + raster);
    ASSERT_TRUE(tif.ok) << tif.error;
    EXPECT_EQ(tif.epsg, 32634) << raster;
  }
  // Three parallel lines: some cells are seen from two of them.
  const auto coverage = sss::test::readGeoTiff(dir_ + "/coverage.tif");
  EXPECT_GE(*std::max_element(coverage.values.begin(), coverage.values.end()), 2.0);
}

// A survey across 180 E (origin set so that the meridian runs through its middle): the tracks and the
// footprints it cuts are split there (RFC 7946 §3.1.9), every longitude in [-180, 180], no edge that
// jumps across the globe, footprint rings counterclockwise.
TEST_F(LiveProductsTest, GeoJsonAcrossTheAntimeridianIsCutThere) {
  const std::vector<sss::optimiser::StampedPose> slam = engine_->pingTrajectory(true);
  double east_min_m = 1e9, east_max_m = -1e9;
  for (const auto& p : slam) {
    east_min_m = std::min(east_min_m, p.T_world_body.translation.y());
    east_max_m = std::max(east_max_m, p.T_world_body.translation.y());
  }
  ASSERT_GT(east_max_m - east_min_m, 100.0);
  const double latitude_deg = -45.0;
  // Metres per degree of longitude on the WGS-84 ellipsoid at 45 S (prime vertical radius x cos lat).
  const double metres_per_deg = 78846.8;
  const sss::core::MissionOrigin origin{latitude_deg, 180.0 - 0.5 * (east_min_m + east_max_m) / metres_per_deg};
  fs::create_directories(dir_);
  ASSERT_TRUE(writeGeoJsonFiles(dir_, slam, engine_->pingTrajectory(false), footprints_, *engine_, origin).ok);

  // Every vertex wrapped; consecutive vertices of one piece never more than a degree apart.
  auto checkPiece = [](const nlohmann::json& piece) {
    for (size_t i = 0; i < piece.size(); ++i) {
      const double lon = piece[i][0].get<double>();
      EXPECT_GE(lon, -180.0);
      EXPECT_LE(lon, 180.0);
      if (i > 0) {
        EXPECT_LT(std::abs(lon - piece[i - 1][0].get<double>()), 1.0);
      }
    }
  };
  const nlohmann::json tracks = nlohmann::json::parse(readText(dir_ + "/track.geojson"));
  ASSERT_EQ(tracks["features"].size(), 2u);
  for (const auto& feature : tracks["features"]) {
    ASSERT_EQ(feature["geometry"]["type"], "MultiLineString") << feature["properties"]["name"];
    const auto& pieces = feature["geometry"]["coordinates"];
    ASSERT_GE(pieces.size(), 2u);
    for (size_t k = 0; k < pieces.size(); ++k) {
      checkPiece(pieces[k]);
      if (k == 0) continue;
      // A piece starts where the previous one ended, on the other side of the antimeridian.
      const auto& end = pieces[k - 1].back();
      const auto& start = pieces[k].front();
      EXPECT_DOUBLE_EQ(std::abs(end[0].get<double>()), 180.0);
      EXPECT_DOUBLE_EQ(start[0].get<double>(), -end[0].get<double>());
      EXPECT_DOUBLE_EQ(start[1].get<double>(), end[1].get<double>());
    }
  }
  const nlohmann::json polygons = nlohmann::json::parse(readText(dir_ + "/subframes.geojson"));
  ASSERT_EQ(polygons["features"].size(), footprints_.size());
  size_t cut = 0;
  for (const auto& feature : polygons["features"]) {
    const bool multi = feature["geometry"]["type"] == "MultiPolygon";
    cut += multi ? 1 : 0;
    const nlohmann::json parts = multi ? feature["geometry"]["coordinates"]
                                       : nlohmann::json::array({feature["geometry"]["coordinates"]});
    for (const auto& polygon : parts) {
      const auto& ring = polygon[0];
      checkPiece(ring);
      EXPECT_EQ(ring.front(), ring.back());
      double twice_area = 0.0;
      for (size_t i = 0; i + 1 < ring.size(); ++i)
        twice_area += ring[i][0].get<double>() * ring[i + 1][1].get<double>() -
                      ring[i + 1][0].get<double>() * ring[i][1].get<double>();
      EXPECT_GT(twice_area, 0.0) << "clockwise ring in subframe " << feature["properties"]["subframe_id"];
    }
  }
  EXPECT_GE(cut, 1u);
}

TEST_F(LiveProductsTest, WithoutAnOriginTheFilesThatNeedOneAreLeftOut) {
  std::vector<std::string> messages;
  ASSERT_TRUE(writeLiveProducts(*engine_, *mosaics_, footprints_, dir_, std::nullopt, messages));
  for (const char* file : {"slam.tum", "navigation.csv", "loop_closures.csv", "coverage.yaml", "mosaic_slam.png"}) {
    EXPECT_TRUE(fs::is_regular_file(dir_ + "/" + file)) << file;
  }
  for (const char* file : {"navigation.nmea", "track.geojson", "coverage.tif", "mosaic_slam.tif", "heightmap.tif"}) {
    EXPECT_FALSE(fs::exists(dir_ + "/" + file)) << file;
  }
}

}  // namespace
}  // namespace sss::products
