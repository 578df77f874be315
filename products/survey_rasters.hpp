// The pipeline's rasters (heightmap grid, mosaic) as GeoTIFF rasters: the conversions only, so
// that sss-process and the live optimiser write the same files.
#pragma once

#include <string>

#include "pipeline/optimiser/bathymetry.hpp"
#include "pipeline/subframe/pictures.hpp"
#include "products/geotiff.hpp"

namespace sss::products {

// Depth (metres, positive down) as float32, no data -9999; the grid's cell centres stay where they are.
FrameRaster heightmapRaster(const sss::optimiser::HeightmapGrid& grid, const std::string& description);
// Mean normalised intensity as 8-bit (1..255), 0 = no data.
FrameRaster mosaicRaster(const sss::subframe::MosaicRaster& mosaic, const std::string& description);

}  // namespace sss::products
