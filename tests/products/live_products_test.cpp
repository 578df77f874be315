// What sss-optimiser leaves in its products folder, from the engine after a synthetic lawnmower (3
// lines of 4 subframes, closures with seabed correspondences): every file sss-process writes that
// needs no sonar file, consistent with the engine, GeoTIFFs in the origin's UTM zone; without an
// origin, no file that needs one.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "pipeline/optimiser/optimiser_engine.hpp"
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
