// Pictures of canonical subframes: a waterfall PNG per survey line and a geo-referenced mosaic
// PNG of a whole mission (OpenCV), for eyes and reports, not for the matcher.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/status.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/subframe/subframe_builder.hpp"

namespace sss::subframe {

struct PictureOptions {
  double display_max_intensity = 3.0;  // normalised intensity shown white
  double mosaic_resolution_m = 0.5;
  int waterfall_max_width_px = 1250;   // columns averaged down to at most this width
};

// Writes <dir>/waterfall_line_<id>.png for every line (subframes stacked in time order, oldest row
// at the top; masked pixels dark blue, subframe boundaries as a red tick at the left edge).
// Returns the files written, or why one could not be written.
sss::core::Result<std::vector<std::string>> writeWaterfalls(const std::vector<Subframe>& subframes,
                                                            const std::string& dir, const PictureOptions& options);

// A north-up mosaic raster: row 0 is the northernmost; cell (row, col) covers north
// north_max_m - (row + 1) * resolution_m .. north_max_m - row * resolution_m and east
// east_min_m + col * resolution_m .. + resolution_m (mission frame, metres).
struct MosaicRaster {
  int rows = 0;
  int cols = 0;
  double resolution_m = 0.5;
  double north_max_m = 0.0;  // top edge of row 0
  double east_min_m = 0.0;   // left edge of column 0
  std::vector<uint8_t> gray;  // mean normalised intensity 1..255; 0 = no data
};

// The mosaic's mean normalised intensity per cell of every valid pixel geo-referenced with the
// given poses per subframe id (DR when a subframe has none there); an error when nothing can be
// placed.
sss::core::Result<MosaicRaster> renderMosaic(const std::vector<Subframe>& subframes,
                                             const std::map<int64_t, std::vector<sss::core::Pose>>& poses_by_subframe,
                                             const PictureOptions& options);

// Writes a rendered mosaic as an 8-bit grey PNG (black = no data) with its geo-reference beside it
// (same name, .yaml; keys as below).
sss::core::Status writeMosaic(const MosaicRaster& mosaic, const std::string& path,
                              const std::optional<sss::core::MissionOrigin>& origin = std::nullopt);

// Renders and writes a north-up mosaic: mean normalised intensity per cell of every valid pixel geo-referenced
// with the given poses per subframe id (DR when a subframe has none there); black = no data. Its geo-reference goes
// beside it as the same name with .yaml (keys resolution_m, north_max_m, east_min_m, rows, cols,
// and origin_latitude_deg / origin_longitude_deg when the frame's origin is given).
sss::core::Status writeMosaic(const std::vector<Subframe>& subframes,
                              const std::map<int64_t, std::vector<sss::core::Pose>>& poses_by_subframe,
                              const std::string& path, const PictureOptions& options,
                              const std::optional<sss::core::MissionOrigin>& origin = std::nullopt);

// A copy of a subframe with `factor` bins averaged into one (masked if any is masked): mosaics
// are drawn at ~0.5 m, so a long mission's mosaics need not keep full-resolution images. A subframe
// without a consistent image gives one with no columns.
Subframe decimateForMosaic(const Subframe& subframe, int factor);
// The factor for a mosaic resolution: the renderer takes every other column, so factor x 2 bins
// per cell at most.
inline int mosaicDecimationFactor(const PictureOptions& options, double bin_size_m) {
  return std::max(1, static_cast<int>(std::floor(options.mosaic_resolution_m / (2.0 * bin_size_m))));
}

}  // namespace sss::subframe
