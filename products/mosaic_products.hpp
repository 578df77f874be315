// The side-scan mosaics as products: the subframes kept at mosaic resolution while a mission runs
// (bounded in memory), and mosaic_dr / mosaic_slam written as PNG + YAML geo-reference + GeoTIFF,
// the SLAM one geo-referenced with the optimiser's correction at every ping. Shared by sss-process
// and the live optimiser.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/optimiser/optimiser_engine.hpp"
#include "pipeline/subframe/pictures.hpp"
#include "products/geotiff.hpp"

namespace sss::products {

// Subframes decimated to the mosaic's resolution (see decimateForMosaic). At most max_bytes of
// images are kept: beyond, the oldest subframes go (counted), so a mission longer than the bound
// gets the mosaics of its newest part.
class MosaicStore {
 public:
  MosaicStore(sss::subframe::PictureOptions pictures, size_t max_bytes);
  void add(const sss::subframe::Subframe& subframe);
  const std::vector<sss::subframe::Subframe>& subframes() const { return subframes_; }
  size_t bytes() const { return bytes_; }
  uint64_t dropped() const { return dropped_; }

 private:
  sss::subframe::PictureOptions pictures_;
  size_t max_bytes_;
  size_t bytes_ = 0;
  uint64_t dropped_ = 0;
  std::vector<sss::subframe::Subframe> subframes_;  // oldest first
};

// Writes dir/mosaic_dr.{png,yaml} and dir/mosaic_slam.{png,yaml}, and their GeoTIFFs when frame
// is given; `tool` names the writer in the descriptions. The names of the GeoTIFFs written are
// appended to geotiffs (with the last one's info in geotiff_info).
sss::core::Status writeMosaicProducts(const std::string& dir, const std::vector<sss::subframe::Subframe>& subframes,
                                      const sss::optimiser::OptimiserEngine& engine,
                                      const sss::subframe::PictureOptions& pictures,
                                      const std::optional<sss::core::MissionOrigin>& origin,
                                      const std::optional<RasterFrame>& frame, const std::string& tool,
                                      std::vector<std::string>& geotiffs, GeoTiffInfo& geotiff_info);

}  // namespace sss::products
