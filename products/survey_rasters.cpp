// Pipeline rasters as GeoTIFF rasters, see survey_rasters.hpp.
#include "products/survey_rasters.hpp"

#include <limits>

namespace sss::products {

FrameRaster heightmapRaster(const sss::optimiser::HeightmapGrid& grid, const std::string& description) {
  FrameRaster raster =
      rasterOverCentredGrid(grid.rows, grid.cols, grid.resolution_m, grid.north_min_m, grid.east_min_m);
  raster.type = RasterType::kFloat32;
  raster.nodata_value = -9999.0;
  raster.description = description;
  for (int row = 0; row < grid.rows; ++row) {
    for (int col = 0; col < grid.cols; ++col) {
      raster.values[northUpIndex(raster, row, col)] = grid.depth_m[static_cast<size_t>(row) * grid.cols + col];
    }
  }
  return raster;
}

FrameRaster mosaicRaster(const sss::subframe::MosaicRaster& mosaic, const std::string& description) {
  FrameRaster raster;
  raster.rows = mosaic.rows;
  raster.cols = mosaic.cols;
  raster.resolution_m = mosaic.resolution_m;
  raster.north_top_edge_m = mosaic.north_max_m;
  raster.east_left_edge_m = mosaic.east_min_m;
  raster.type = RasterType::kByte;
  raster.description = description;
  raster.values.resize(mosaic.gray.size());
  for (size_t i = 0; i < mosaic.gray.size(); ++i) {
    raster.values[i] = mosaic.gray[i] == 0 ? std::numeric_limits<float>::quiet_NaN() : mosaic.gray[i];
  }
  return raster;
}

}  // namespace sss::products
