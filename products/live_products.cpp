// The products sss-optimiser writes at the end of a mission, see live_products.hpp.
#include "products/live_products.hpp"

#include <filesystem>

#include "pipeline/optimiser/bathymetry.hpp"
#include "products/coverage.hpp"
#include "products/geotiff.hpp"
#include "products/navigation_products.hpp"
#include "products/survey_rasters.hpp"

namespace fs = std::filesystem;

namespace sss::products {

bool writeLiveProducts(const sss::optimiser::OptimiserEngine& engine, const MosaicStore& mosaics,
                       const std::vector<SubframeFootprint>& footprints, const std::string& directory,
                       const std::optional<sss::core::MissionOrigin>& origin, std::vector<std::string>& messages) {
  std::error_code ec;
  fs::create_directories(directory, ec);
  const auto trajectory = engine.pingTrajectory(true);
  if (const sss::core::Status written =
          sss::optimiser::writeTum(directory + "/slam.tum", trajectory,
                                   "sss-optimiser: optimised pose of every ping of the subframes", origin);
      !written) {
    messages.push_back(written.message);
    return false;
  }
  const auto points = engine.seabedPoints(false);
  const sss::optimiser::HeightmapGrid heightmap = sss::optimiser::gridSeabedPoints(points, engine.options().bathymetry);
  sss::core::Status written = sss::optimiser::writeSeabedPly(directory + "/bathymetry.ply", points, origin);
  if (written && !points.empty()) {
    written = sss::optimiser::writeHeightmapFiles(directory + "/heightmap.yaml", heightmap,
                                                  "sss-optimiser: seabed re-triangulated with the optimised poses",
                                                  origin);
  }
  // The survey products sss-process writes: the corrected navigation, the tie report, the mosaics
  // (DR and SLAM) and the heightmap, with GeoTIFFs in the origin's UTM zone.
  if (written) written = writeNavigationFiles(directory, trajectory, engine, origin, {});
  if (written) written = writeTieReportCsv(directory + "/loop_closures.csv", engine);
  std::optional<RasterFrame> frame;
  if (origin) frame = RasterFrame{origin, false, 0.0, 0.0, ""};
  std::vector<std::string> geotiffs;
  GeoTiffInfo info;
  if (written) {
    written = writeMosaicProducts(directory, mosaics.subframes(), engine, sss::subframe::PictureOptions{}, origin,
                                  frame, "sss-optimiser", geotiffs, info);
  }
  if (written && mosaics.dropped() > 0) {
    messages.push_back("products: the mosaics show the newest " + std::to_string(mosaics.subframes().size()) +
                       " subframes; " + std::to_string(mosaics.dropped()) +
                       " older ones went to stay within products_mosaic_max_mib");
  }
  // Tracks and subframe footprints for GIS, and how many lines saw each 5 m cell.
  if (written) {
    written = writeGeoJsonFiles(directory, trajectory, engine.pingTrajectory(false), footprints, engine, origin);
  }
  if (written && !footprints.empty()) {
    const CoverageGrid coverage = computeCoverage(slamStrips(footprints, engine), 5.0);
    written = writeCoverageFiles(directory + "/coverage.yaml", coverage, origin);
    if (written && frame) written = writeGeoTiff(directory + "/coverage.tif", coverageRaster(coverage), *frame);
  }
  if (written && !points.empty() && frame) {
    written = writeGeoTiff(
        directory + "/heightmap.tif",
        heightmapRaster(heightmap, "sss-optimiser: seabed re-triangulated with the optimised poses (depth m, down)"),
        *frame);
  }
  messages.push_back(written ? "products written to " + directory + ": " + std::to_string(trajectory.size()) +
                                   " poses, " + std::to_string(points.size()) + " seabed points"
                             : "products: " + written.message);
  return written.ok;
}

}  // namespace sss::products
