// Mosaic products, see mosaic_products.hpp.
#include "products/mosaic_products.hpp"

#include <map>

#include "products/survey_rasters.hpp"

namespace sss::products {

using sss::core::Status;

MosaicStore::MosaicStore(sss::subframe::PictureOptions pictures, size_t max_bytes)
    : pictures_(pictures), max_bytes_(max_bytes) {}

namespace {
size_t imageBytes(const sss::subframe::Subframe& s) {
  return s.image.size() * sizeof(float) + s.mask.size() + s.pings.size() * sizeof(sss::subframe::SubframePing);
}
}  // namespace

void MosaicStore::add(const sss::subframe::Subframe& subframe) {
  const int factor = sss::subframe::mosaicDecimationFactor(pictures_, subframe.geometry.bin_size_m);
  sss::subframe::Subframe reduced = sss::subframe::decimateForMosaic(subframe, factor);
  if (reduced.cols() <= 0 || reduced.rows() < 2) return;  // no image to draw
  subframes_.push_back(std::move(reduced));
  bytes_ += imageBytes(subframes_.back());
  // Past the bound, drop the oldest (moves of a few hundred subframes at most, once per subframe).
  size_t drop = 0;
  while (bytes_ > max_bytes_ && drop + 1 < subframes_.size()) {
    bytes_ -= imageBytes(subframes_[drop]);
    ++drop;
  }
  subframes_.erase(subframes_.begin(), subframes_.begin() + static_cast<std::ptrdiff_t>(drop));
  dropped_ += drop;
}

Status writeMosaicProducts(const std::string& dir, const std::vector<sss::subframe::Subframe>& subframes,
                           const sss::optimiser::OptimiserEngine& engine, const sss::subframe::PictureOptions& pictures,
                           const std::optional<sss::core::MissionOrigin>& origin,
                           const std::optional<RasterFrame>& frame, const std::string& tool,
                           std::vector<std::string>& geotiffs, GeoTiffInfo& geotiff_info) {
  if (subframes.empty()) return Status::success();
  // The SLAM pose of every ping: the optimiser's correction at its time applied to its DR pose.
  std::map<int64_t, std::vector<sss::core::Pose>> slam_poses;
  for (const auto& s : subframes) {
    std::vector<sss::core::Pose>& poses = slam_poses[s.id];
    for (const auto& ping : s.pings) {
      poses.push_back(engine.correctionAt(ping.utime_us).T_corrected_dr * ping.T_world_body);
    }
  }
  const std::map<int64_t, std::vector<sss::core::Pose>> dr_poses;  // none: each subframe's own DR poses
  const struct {
    const std::map<int64_t, std::vector<sss::core::Pose>>& poses;
    const char* name;
    const char* description;
  } mosaics[] = {{dr_poses, "mosaic_dr", "side-scan mosaic geo-referenced with dead reckoning"},
                 {slam_poses, "mosaic_slam", "side-scan mosaic geo-referenced with the SLAM poses"}};
  for (const auto& mosaic : mosaics) {
    const std::string png = dir + "/" + mosaic.name + ".png";
    const auto raster = sss::subframe::renderMosaic(subframes, mosaic.poses, pictures);
    if (!raster) {
      return Status::error(raster.message() + " " + png);
    }
    if (const Status written = sss::subframe::writeMosaic(*raster, png, origin); !written) return written;
    if (!frame) continue;
    const std::string tif = std::string(mosaic.name) + ".tif";
    const Status written =
        writeGeoTiff(dir + "/" + tif, mosaicRaster(*raster, tool + ": " + mosaic.description), *frame, &geotiff_info);
    if (!written) return written;
    geotiffs.push_back(tif);
  }
  return Status::success();
}

}  // namespace sss::products
