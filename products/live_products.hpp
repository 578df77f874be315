// What sss-optimiser writes into its products folder at the end of a mission (SIGTERM) and on
// SIGUSR1, so that the files are ready when the vehicle is recovered: the same survey products as
// sss-process (slam.tum, navigation.csv/.nmea, loop_closures.csv, track/subframes GeoJSON, coverage,
// mosaics, bathymetry.ply, heightmap; the rasters also as GeoTIFF in the origin's UTM zone).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/mission_origin.hpp"
#include "pipeline/optimiser/optimiser_engine.hpp"
#include "products/footprints.hpp"
#include "products/mosaic_products.hpp"

namespace sss::products {

// Writes them into directory (created if missing) from the engine after full smoothing. messages
// gets one line saying what was written, or why not; false when a file could not be written.
// Without an origin (a projected frame) there is no GeoTIFF, GeoJSON nor NMEA.
bool writeLiveProducts(const sss::optimiser::OptimiserEngine& engine, const MosaicStore& mosaics,
                       const std::vector<SubframeFootprint>& footprints, const std::string& directory,
                       const std::optional<sss::core::MissionOrigin>& origin, std::vector<std::string>& messages);

}  // namespace sss::products
