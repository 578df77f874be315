// GeoTIFF products read back with GDAL: the UTM zone of the origin, a geotransform that puts known
// cells of the mission frame at their true UTM coordinates, nodata, overviews, the projected-grid
// case and the errors a user can meet.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>

#include "pipeline/core/geodesy.hpp"
#include "products/geotiff.hpp"
#include "products/mosaic_products.hpp"
#include "products/survey_rasters.hpp"
#include "tests/support/geotiff_read.hpp"
#include "tests/support/status_assertions.hpp"

namespace fs = std::filesystem;

namespace sss::products {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

class GeoTiffTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() / ("sss_geotiff_test_" + std::to_string(getpid()))).string();
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir_;
};

// A raster of no data with 3 x 3 blocks of distinct values centred on the given cells: nearest
// neighbour resampling into a grid rotated by the meridian convergence samples within 0.36 px of a
// block's centre, so the pixel at the block centre's true coordinates must hold its value.
struct Block {
  int row, col;
  float value;
};
FrameRaster blockRaster(RasterType type, int rows, int cols, double resolution_m, const std::vector<Block>& blocks) {
  FrameRaster raster;
  raster.rows = rows;
  raster.cols = cols;
  raster.resolution_m = resolution_m;
  raster.north_top_edge_m = 130.25;  // not on the resolution grid on purpose: the warp aligns the output
  raster.east_left_edge_m = -40.5;
  raster.type = type;
  raster.values.assign(static_cast<size_t>(rows) * cols, kNaN);
  for (const Block& b : blocks) {
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc) raster.values[static_cast<size_t>(b.row + dr) * cols + b.col + dc] = b.value;
  }
  return raster;
}

// The true UTM coordinates of a raster cell's centre in the mission frame at origin.
void cellUtm(const FrameRaster& raster, const sss::core::MissionOrigin& origin, int epsg, int row, int col,
             double& easting_m, double& northing_m) {
  const double north = raster.north_top_edge_m - (row + 0.5) * raster.resolution_m;
  const double east = raster.east_left_edge_m + (col + 0.5) * raster.resolution_m;
  const sss::core::LocalTangentPlane plane(origin.latitude_deg, origin.longitude_deg);
  const auto geo = plane.toGeodetic({north, east, 0.0});
  sss::test::utmOf(geo.latitude_deg, geo.longitude_deg, epsg, easting_m, northing_m);
}

TEST(UtmZone, FollowsTheOriginIncludingNorwayAndSvalbardAndThePoles) {
  EXPECT_EQ(utmEpsgCode(59.35, 18.07), 32634);   // Stockholm archipelago
  EXPECT_EQ(utmEpsgCode(-33.9, 151.2), 32756);   // Sydney
  EXPECT_EQ(utmEpsgCode(36.6, -121.9), 32610);   // Monterey Bay
  EXPECT_EQ(utmEpsgCode(60.4, 4.5), 32632);      // off Bergen: Norway's zone 32V, not 31
  EXPECT_EQ(utmEpsgCode(78.2, 10.0), 32633);     // Svalbard: 33X
  EXPECT_EQ(utmEpsgCode(86.0, 0.0), 32661);      // UPS north
  EXPECT_EQ(utmEpsgCode(-85.0, 0.0), 32761);     // UPS south
}

TEST_F(GeoTiffTest, DepthRasterLandsInTheOriginsUtmZoneWithKnownCellsAtTheirTrueCoordinates) {
  const sss::core::MissionOrigin origin{59.35, 18.07};  // 2.9 deg west of zone 34's meridian: 2.5 deg convergence
  const std::vector<Block> blocks = {{5, 5, 41.5f}, {60, 20, 52.25f}, {100, 150, 63.0f}, {20, 180, 70.75f}};
  FrameRaster raster = blockRaster(RasterType::kFloat32, 110, 190, 0.5, blocks);
  raster.description = "test depth";
  RasterFrame frame;
  frame.origin = origin;
  GeoTiffInfo info;
  const std::string path = dir_ + "/depth.tif";
  ASSERT_OK(writeGeoTiff(path, raster, frame, &info));
  EXPECT_EQ(info.epsg, 32634);
  EXPECT_EQ(info.crs_name, "WGS 84 / UTM zone 34N");
  EXPECT_EQ(info.overview_count, 0) << "small rasters need no overviews";

  const auto back = sss::test::readGeoTiff(path);
  ASSERT_TRUE(back.ok) << back.error;
  EXPECT_EQ(back.epsg, 32634);
  EXPECT_EQ(back.data_type, "Float32");
  ASSERT_TRUE(back.has_nodata);
  EXPECT_EQ(back.nodata, -9999.0);
  EXPECT_EQ(back.description, "test depth");
  // North up, the input's resolution, the grid aligned to whole multiples of it (-tap).
  EXPECT_DOUBLE_EQ(back.transform[1], 0.5);
  EXPECT_DOUBLE_EQ(back.transform[5], -0.5);
  EXPECT_EQ(back.transform[2], 0.0);
  EXPECT_EQ(back.transform[4], 0.0);
  EXPECT_NEAR(std::remainder(back.transform[0], 0.5), 0.0, 1e-6);
  EXPECT_NEAR(std::remainder(back.transform[3], 0.5), 0.0, 1e-6);
  // The rotated input needs a slightly larger output (2.5 deg: + ~8 px across 190).
  EXPECT_GE(back.cols, 190);
  EXPECT_LE(back.cols, 200 + 10);

  for (const Block& b : blocks) {
    double easting = 0.0, northing = 0.0;
    cellUtm(raster, origin, 32634, b.row, b.col, easting, northing);
    int row = 0, col = 0;
    ASSERT_TRUE(back.pixelOf(easting, northing, row, col)) << "block " << b.value;
    EXPECT_EQ(back.at(row, col), b.value) << "block at cell (" << b.row << ", " << b.col << ")";
    // The block's pixels (about 9 of them) are centred on its true position: a shift or a wrong
    // CRS moves the centroid by a pixel or more, nearest-neighbour resampling by under half of one.
    double sum_x = 0.0, sum_y = 0.0;
    int count = 0;
    for (int r = 0; r < back.rows; ++r) {
      for (int c = 0; c < back.cols; ++c) {
        if (back.at(r, c) != b.value) continue;
        sum_x += back.centreX(c);
        sum_y += back.centreY(r);
        ++count;
      }
    }
    ASSERT_GE(count, 6);
    EXPECT_NEAR(sum_x / count, easting, 0.5 * 0.5) << "block " << b.value;
    EXPECT_NEAR(sum_y / count, northing, 0.5 * 0.5) << "block " << b.value;
  }
  // A cell far from every block is no data.
  double easting = 0.0, northing = 0.0;
  cellUtm(raster, origin, 32634, 50, 100, easting, northing);
  int row = 0, col = 0;
  ASSERT_TRUE(back.pixelOf(easting, northing, row, col));
  EXPECT_EQ(back.at(row, col), -9999.0);
}

TEST_F(GeoTiffTest, SouthernHemisphereMosaicIsEightBitWithZeroAsNoData) {
  const sss::core::MissionOrigin origin{-33.85, 151.28};  // zone 56S
  const std::vector<Block> blocks = {{10, 10, 200.0f}, {30, 45, 17.0f}};
  RasterFrame frame;
  frame.origin = origin;
  const FrameRaster raster = blockRaster(RasterType::kByte, 50, 60, 0.25, blocks);
  const std::string path = dir_ + "/mosaic.tif";
  ASSERT_OK(writeGeoTiff(path, raster, frame));
  const auto back = sss::test::readGeoTiff(path);
  ASSERT_TRUE(back.ok) << back.error;
  EXPECT_EQ(back.epsg, 32756);
  EXPECT_EQ(back.data_type, "Byte");
  ASSERT_TRUE(back.has_nodata);
  EXPECT_EQ(back.nodata, 0.0);
  EXPECT_DOUBLE_EQ(back.transform[1], 0.25);
  for (const Block& b : blocks) {
    double easting = 0.0, northing = 0.0;
    cellUtm(raster, origin, 32756, b.row, b.col, easting, northing);
    int row = 0, col = 0;
    ASSERT_TRUE(back.pixelOf(easting, northing, row, col));
    EXPECT_EQ(back.at(row, col), b.value);
  }
}

TEST_F(GeoTiffTest, ProjectedGridKeepsTheFilesCoordinatesAndTheNamedCrs) {
  const std::vector<Block> blocks = {{4, 4, 33.0f}};
  const FrameRaster raster = blockRaster(RasterType::kFloat32, 20, 30, 1.0, blocks);
  RasterFrame frame;
  frame.projected = true;
  frame.grid_easting_offset_m = 652000.0;
  frame.grid_northing_offset_m = 6580000.0;
  frame.projected_crs = "EPSG:32633";
  GeoTiffInfo info;
  ASSERT_OK(writeGeoTiff(dir_ + "/grid.tif", raster, frame, &info));
  EXPECT_EQ(info.crs_name, "WGS 84 / UTM zone 33N");
  EXPECT_EQ(info.epsg, 32633);
  auto back = sss::test::readGeoTiff(dir_ + "/grid.tif");
  ASSERT_TRUE(back.ok) << back.error;
  EXPECT_EQ(back.epsg, 32633);
  EXPECT_EQ(back.rows, 20);
  EXPECT_EQ(back.cols, 30);
  // No resampling: the frame's edges plus the grid offsets, exactly.
  EXPECT_DOUBLE_EQ(back.transform[0], 652000.0 - 40.5);
  EXPECT_DOUBLE_EQ(back.transform[3], 6580000.0 + 130.25);
  EXPECT_EQ(back.at(4, 4), 33.0);
  EXPECT_EQ(back.at(0, 29), -9999.0);

  // Without a CRS the grid's coordinates are still there, and the file has no CRS (not a guess).
  frame.projected_crs.clear();
  ASSERT_OK(writeGeoTiff(dir_ + "/grid_no_crs.tif", raster, frame, &info));
  EXPECT_EQ(info.crs_name, "");
  EXPECT_EQ(info.epsg, 0);
  back = sss::test::readGeoTiff(dir_ + "/grid_no_crs.tif");
  ASSERT_TRUE(back.ok) << back.error;
  EXPECT_EQ(back.wkt, "");
  EXPECT_DOUBLE_EQ(back.transform[0], 652000.0 - 40.5);
}

TEST_F(GeoTiffTest, LargeRastersGetOverviews) {
  FrameRaster raster = blockRaster(RasterType::kByte, 1500, 1200, 0.5, {{700, 600, 128.0f}});
  for (size_t i = 0; i < raster.values.size(); i += 3) raster.values[i] = 90.0f;
  RasterFrame frame;
  frame.origin = sss::core::MissionOrigin{59.35, 18.07};
  GeoTiffInfo info;
  ASSERT_OK(writeGeoTiff(dir_ + "/large.tif", raster, frame, &info));
  EXPECT_EQ(info.overview_count, 2) << "1500+ px: 2x and 4x (the next, 8x, would be under 256 px)";
  EXPECT_EQ(sss::test::readGeoTiff(dir_ + "/large.tif").overviews, 2);
}

TEST_F(GeoTiffTest, ProblemsAreNamedNotCrashes) {
  const FrameRaster raster = blockRaster(RasterType::kFloat32, 10, 10, 1.0, {{5, 5, 1.0f}});
  RasterFrame nowhere;
  {
    const sss::core::Status status = writeGeoTiff(dir_ + "/a.tif", raster, nowhere);
    EXPECT_FALSE(status.ok);
    EXPECT_NE(status.message.find("no origin on Earth"), std::string::npos) << status.message;
  }

  EXPECT_OK(isKnownCrs("EPSG:32633"));
  EXPECT_OK(isKnownCrs("+proj=utm +zone=33 +datum=WGS84"));
  {
    const sss::core::Status status = isKnownCrs("EPSG:not-a-code");
    EXPECT_FALSE(status.ok);
    EXPECT_NE(status.message.find("use e.g. EPSG:32633"), std::string::npos) << status.message;
  }

  RasterFrame bad_crs;
  bad_crs.projected = true;
  bad_crs.projected_crs = "EPSG:not-a-code";
  {
    const sss::core::Status status = writeGeoTiff(dir_ + "/b.tif", raster, bad_crs);
    EXPECT_FALSE(status.ok);
    EXPECT_NE(status.message.find("products.projected_crs 'EPSG:not-a-code'"), std::string::npos) << status.message;
  }

  RasterFrame frame;
  frame.origin = sss::core::MissionOrigin{59.35, 18.07};
  {
    const sss::core::Status status = writeGeoTiff(dir_ + "/no/such/folder/c.tif", raster, frame);
    EXPECT_FALSE(status.ok);
    EXPECT_NE(status.message.find("c.tif"), std::string::npos) << status.message;
  }

  FrameRaster inconsistent = raster;
  inconsistent.values.pop_back();
  {
    const sss::core::Status status = writeGeoTiff(dir_ + "/d.tif", inconsistent, frame);
    EXPECT_FALSE(status.ok);
    EXPECT_NE(status.message.find("inconsistent raster"), std::string::npos) << status.message;
  }
}

TEST(SurveyRasters, HeightmapCellCentresAndMosaicEdgesBecomeTheRightGeotransform) {
  sss::optimiser::HeightmapGrid grid;
  grid.rows = 3;
  grid.cols = 4;
  grid.resolution_m = 2.0;
  grid.north_min_m = -10.0;  // centre of row 0 (the southernmost)
  grid.east_min_m = 6.0;
  grid.depth_m = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, kNaN};
  const FrameRaster depth = heightmapRaster(grid, "d");
  EXPECT_DOUBLE_EQ(depth.north_top_edge_m, -10.0 + 2 * 2.0 + 1.0);
  EXPECT_DOUBLE_EQ(depth.east_left_edge_m, 5.0);
  EXPECT_EQ(depth.values[0], 9.0f) << "row 0 of the raster is the grid's northernmost row";
  EXPECT_EQ(depth.values[8], 1.0f);
  EXPECT_TRUE(std::isnan(depth.values[3]));

  sss::subframe::MosaicRaster mosaic;
  mosaic.rows = 1;
  mosaic.cols = 3;
  mosaic.resolution_m = 0.5;
  mosaic.north_max_m = 12.0;
  mosaic.east_min_m = -3.0;
  mosaic.gray = {0, 1, 255};
  const FrameRaster image = mosaicRaster(mosaic, "m");
  EXPECT_EQ(image.type, RasterType::kByte);
  EXPECT_DOUBLE_EQ(image.north_top_edge_m, 12.0);
  EXPECT_DOUBLE_EQ(image.east_left_edge_m, -3.0);
  EXPECT_TRUE(std::isnan(image.values[0]));
  EXPECT_EQ(image.values[2], 255.0f);
}

// The store behind the mosaics keeps subframes at mosaic resolution and, past its bound, only the
// newest (the vehicle's memory is bounded; the mosaics then show the newest part of the mission).
TEST(MosaicStore, DecimatesToTheMosaicResolutionAndKeepsTheNewestWithinItsBound) {
  sss::core::Subframe subframe;
  subframe.geometry.bins_per_side = 1000;
  subframe.geometry.bin_size_m = 0.05;  // 50 m per side
  subframe.pings.resize(200);
  subframe.image.assign(static_cast<size_t>(200) * 2000, 1.0f);
  subframe.mask.assign(subframe.image.size(), sss::core::kMaskValid);
  sss::subframe::PictureOptions pictures;  // 0.5 m: every other column of 0.25 m bins, 5 bins each
  MosaicStore unbounded(pictures, std::numeric_limits<size_t>::max());
  unbounded.add(subframe);
  ASSERT_EQ(unbounded.subframes().size(), 1u);
  EXPECT_EQ(unbounded.subframes().front().geometry.bins_per_side, 200);
  EXPECT_DOUBLE_EQ(unbounded.subframes().front().geometry.bin_size_m, 0.25);
  const size_t one = unbounded.bytes();
  EXPECT_EQ(one, 200u * 400u * 5u + 200u * sizeof(sss::core::SubframePing)) << "float + mask: a fifth of the 1.6 MB image";

  MosaicStore bounded(pictures, 3 * one + one / 2);
  for (int64_t id = 0; id < 10; ++id) {
    subframe.id = id;
    bounded.add(subframe);
  }
  ASSERT_EQ(bounded.subframes().size(), 3u);
  EXPECT_EQ(bounded.dropped(), 7u);
  EXPECT_EQ(bounded.subframes().front().id, 7) << "the newest are kept";
  EXPECT_LE(bounded.bytes(), 3 * one + one / 2);

  // A subframe without its image (or with a wrong-sized one) has nothing to draw and is not kept.
  sss::core::Subframe no_image = subframe;
  no_image.image.clear();
  unbounded.add(no_image);
  no_image.image.assign(100, 1.0f);
  unbounded.add(no_image);
  EXPECT_EQ(unbounded.subframes().size(), 1u);
}

}  // namespace
}  // namespace sss::products
