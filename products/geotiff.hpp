// GeoTIFF survey products (GDAL): a north-up raster in the mission frame written in a CRS that GIS
// software places on the map: the UTM zone of the mission origin (WGS 84), or the file's own grid.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/status.hpp"

namespace sss::products {

// Where the mission frame lies on Earth.
// - Geographic: the local NED tangent plane at a WGS-84 origin (every INS and most sonar files).
//   The raster is warped (nearest neighbour; the transform approximated within 0.01 pixel) into
//   the origin's UTM zone.
// - Projected: the input gave positions in projected metres (XTF NavUnits 0); frame (north, east)
//   plus the offsets is the file's grid. XTF does not name that grid's CRS, so the user does
//   (`products.projected_crs`, any string GDAL takes: "EPSG:32633"); without one the GeoTIFF has
//   the grid's coordinates and no CRS.
struct RasterFrame {
  std::optional<sss::core::MissionOrigin> origin;
  bool projected = false;
  double grid_northing_offset_m = 0.0;
  double grid_easting_offset_m = 0.0;
  std::string projected_crs;
};

enum class RasterType {
  kByte,     // 1..255, 0 = no data (mosaics, counts)
  kFloat32,  // nodata_value = no data (depths)
};

// A north-up raster in the mission frame: row 0 is the northernmost, column 0 the westernmost.
struct FrameRaster {
  int rows = 0;
  int cols = 0;
  double resolution_m = 1.0;
  double north_top_edge_m = 0.0;  // north of row 0's top edge
  double east_left_edge_m = 0.0;  // east of column 0's left edge
  RasterType type = RasterType::kFloat32;
  std::vector<float> values;  // rows x cols, row-major; NaN = no data
  double nodata_value = -9999.0;  // how no data is written (kByte: always 0)
  bool categorical = false;       // overviews by nearest neighbour (counts), else by average
  std::string description;        // TIFFTAG_IMAGEDESCRIPTION
};

// The raster over a grid whose rows grow northwards with cell centres at north_min_m + row *
// resolution_m, east_min_m + col * resolution_m (the layout of the heightmap and coverage grids):
// its edges set, every value no data. Grid cell (row, col) goes to values[northUpIndex(...)].
FrameRaster rasterOverCentredGrid(int rows, int cols, double resolution_m, double north_min_m, double east_min_m);
inline size_t northUpIndex(const FrameRaster& raster, int grid_row, int col) {
  return static_cast<size_t>(raster.rows - 1 - grid_row) * static_cast<size_t>(raster.cols) + static_cast<size_t>(col);
}

// What was written, for logs and tests.
struct GeoTiffInfo {
  std::string crs_name;  // "WGS 84 / UTM zone 34N", the user's CRS, or "" (none)
  int epsg = 0;          // 0 when the CRS has no EPSG code or there is none
  int rows = 0, cols = 0;
  int overview_count = 0;
};

// The EPSG code of the WGS 84 UTM zone that holds (latitude, longitude): 326zz north, 327zz south
// (Norway's and Svalbard's zone exceptions included).
int utmEpsgCode(double latitude_deg, double longitude_deg);

// Succeeds when GDAL knows the CRS text (what products.projected_crs takes: "EPSG:32633", a WKT, a
// PROJ string); fails with the reason otherwise, so that a configuration is refused before a run.
sss::core::Status isKnownCrs(const std::string& crs);

// Rasters larger than this in either dimension get internal overviews (2x, 4x, ... down to ~256 px).
constexpr int kOverviewMinSizePx = 1024;

// Writes path as a tiled, DEFLATE-compressed GeoTIFF. Fails with a message naming the cause (no
// frame, GDAL's error) when it cannot.
sss::core::Status writeGeoTiff(const std::string& path, const FrameRaster& raster, const RasterFrame& frame,
                               GeoTiffInfo* info = nullptr);

}  // namespace sss::products
