// Each subframe's footprint on the seabed (its swath either side along a few of its pings): the
// survey's coverage and the GeoJSON layers for GIS, under the optimiser's corrected poses. Shared by
// sss-process and the live optimiser.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/mission_origin.hpp"
#include "pipeline/optimiser/optimiser_engine.hpp"
#include "pipeline/subframe/subframe_builder.hpp"
#include "products/coverage.hpp"

namespace sss::products {

// A subframe's id, line, canonical swath per side and a few DR pings along it (first, every 25th, last).
struct SubframeFootprint {
  int64_t id = 0;
  int line_id = 0;
  double half_width_m = 0.0;
  std::vector<sss::optimiser::StampedPose> pings;
};
SubframeFootprint footprintOf(const sss::subframe::Subframe& subframe);

// Every footprint's swath edges under the corrected poses (the engine's correction at each ping),
// on the level seabed plane through the vehicle, in the footprints' order.
std::vector<FootprintStrip> slamStrips(const std::vector<SubframeFootprint>& footprints,
                                       const sss::optimiser::OptimiserEngine& engine);

// For GIS (QGIS opens them as they are; RFC 7946, WGS 84 longitude/latitude): dir/track.geojson, the
// SLAM and DR tracks (a vertex every 4 poses), and dir/subframes.geojson, each footprint's polygon
// under the corrected poses with its id and line (rings counterclockwise). A track or footprint that
// crosses the antimeridian is cut there into a MultiLineString / MultiPolygon (RFC 7946 §3.1.9).
// Nothing without an origin (a projected frame).
sss::core::Status writeGeoJsonFiles(const std::string& dir, const std::vector<sss::optimiser::StampedPose>& slam,
                                    const std::vector<sss::optimiser::StampedPose>& dr,
                                    const std::vector<SubframeFootprint>& footprints,
                                    const sss::optimiser::OptimiserEngine& engine,
                                    const std::optional<sss::core::MissionOrigin>& origin);

}  // namespace sss::products
