// Subframe footprints as products, see footprints.hpp.
#include "products/footprints.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>

#include "pipeline/core/geodesy.hpp"
#include "pipeline/core/time.hpp"
#include "products/geojson_geometry.hpp"

namespace sss::products {

using sss::core::Status;

SubframeFootprint footprintOf(const sss::subframe::Subframe& s) {
  SubframeFootprint f{s.id, s.line_id, s.geometry.bins_per_side * s.geometry.bin_size_m + s.geometry.first_bin_range_m,
                      {}};
  for (size_t i = 0; i < s.pings.size(); ++i)
    if (i % 25 == 0 || i + 1 == s.pings.size()) f.pings.push_back({s.pings[i].utime_us, s.pings[i].T_world_body});
  return f;
}

std::vector<FootprintStrip> slamStrips(const std::vector<SubframeFootprint>& footprints,
                                     const sss::optimiser::OptimiserEngine& engine) {
  std::vector<FootprintStrip> strips;
  for (const SubframeFootprint& f : footprints) {
    FootprintStrip strip;
    strip.line_id = f.line_id;
    for (const auto& ping : f.pings) {
      const sss::core::Pose pose = engine.correctionAt(ping.utime_us).T_corrected_dr * ping.T_world_body;
      // The swath edges on the level seabed plane through the vehicle, across its heading.
      const double heading = sss::core::eulerFromQuaternion(pose.rotation).heading_rad;
      const Eigen::Vector2d across(-std::sin(heading), std::cos(heading));  // starboard, north/east
      strip.port_ne_m.push_back(pose.translation.head<2>() - f.half_width_m * across);
      strip.starboard_ne_m.push_back(pose.translation.head<2>() + f.half_width_m * across);
    }
    strips.push_back(std::move(strip));
  }
  return strips;
}

namespace {

// 1e-8 deg (~1 mm) is all a GIS needs and keeps the files small.
nlohmann::json coordinatesOf(const std::vector<LonLat>& vertices) {
  nlohmann::json coordinates = nlohmann::json::array();
  for (const LonLat& p : vertices)
    coordinates.push_back({std::round(p.lon_deg * 1e8) / 1e8, std::round(p.lat_deg * 1e8) / 1e8});
  return coordinates;
}

// One piece a LineString, pieces either side of the antimeridian a MultiLineString.
nlohmann::json lineGeometry(const std::vector<std::vector<LonLat>>& pieces) {
  if (pieces.size() == 1) return {{"type", "LineString"}, {"coordinates", coordinatesOf(pieces.front())}};
  nlohmann::json parts = nlohmann::json::array();
  for (const auto& piece : pieces) parts.push_back(coordinatesOf(piece));
  return {{"type", "MultiLineString"}, {"coordinates", parts}};
}

// One ring a Polygon, rings either side of the antimeridian a MultiPolygon (of polygons without holes).
nlohmann::json polygonGeometry(const std::vector<std::vector<LonLat>>& rings) {
  if (rings.size() == 1) return {{"type", "Polygon"}, {"coordinates", nlohmann::json::array({coordinatesOf(rings.front())})}};
  nlohmann::json polygons = nlohmann::json::array();
  for (const auto& ring : rings) polygons.push_back(nlohmann::json::array({coordinatesOf(ring)}));
  return {{"type", "MultiPolygon"}, {"coordinates", polygons}};
}

}  // namespace

Status writeGeoJsonFiles(const std::string& dir, const std::vector<sss::optimiser::StampedPose>& slam,
                         const std::vector<sss::optimiser::StampedPose>& dr,
                         const std::vector<SubframeFootprint>& footprints, const sss::optimiser::OptimiserEngine& engine,
                         const std::optional<sss::core::MissionOrigin>& origin) {
  if (!origin) return Status::success();
  const sss::core::LocalTangentPlane plane(origin->latitude_deg, origin->longitude_deg);
  // Longitudes continuous through the antimeridian (taken near the origin's), cut by the geometry.
  auto lonLat = [&](const Eigen::Vector3d& ned) {
    const sss::core::GeodeticPosition g = plane.toGeodetic(ned);
    return LonLat{unwrapLongitudeNear(g.longitude_deg, origin->longitude_deg), g.latitude_deg};
  };
  auto write = [&](const std::string& path, const nlohmann::json& json) {
    std::ofstream out(path);
    out << json.dump() << "\n";
    return out ? Status::success() : Status::error("cannot write " + path);
  };
  nlohmann::json tracks = {{"type", "FeatureCollection"}, {"features", nlohmann::json::array()}};
  for (const auto& [name, poses] : {std::pair<const char*, const std::vector<sss::optimiser::StampedPose>*>{"SLAM", &slam},
                                    {"DR", &dr}}) {
    std::vector<LonLat> line;
    for (size_t i = 0; i < poses->size(); ++i)
      if (i % 4 == 0 || i + 1 == poses->size()) line.push_back(lonLat((*poses)[i].T_world_body.translation));
    const std::vector<std::vector<LonLat>> pieces = cutLineAtAntimeridian(line);
    if (pieces.empty()) continue;
    tracks["features"].push_back({{"type", "Feature"},
                                  {"properties", {{"name", name},
                                                  {"start_utc", sss::core::formatUtimeIso8601(poses->front().utime_us)},
                                                  {"end_utc", sss::core::formatUtimeIso8601(poses->back().utime_us)}}},
                                  {"geometry", lineGeometry(pieces)}});
  }
  if (const Status written = write(dir + "/track.geojson", tracks); !written) return written;

  nlohmann::json polygons = {{"type", "FeatureCollection"}, {"features", nlohmann::json::array()}};
  const std::vector<FootprintStrip> strips = slamStrips(footprints, engine);
  for (size_t k = 0; k < footprints.size(); ++k) {
    const SubframeFootprint& f = footprints[k];
    const FootprintStrip& strip = strips[k];
    if (strip.port_ne_m.size() < 2) continue;
    // Starboard edge forward, port edge back: counterclockwise seen from above (RFC 7946 §3.1.6);
    // counterClockwise() only guards it.
    std::vector<LonLat> ring;
    for (const auto& p : strip.starboard_ne_m) ring.push_back(lonLat(Eigen::Vector3d(p.x(), p.y(), 0.0)));
    for (auto it = strip.port_ne_m.rbegin(); it != strip.port_ne_m.rend(); ++it)
      ring.push_back(lonLat(Eigen::Vector3d(it->x(), it->y(), 0.0)));
    ring.push_back(ring.front());  // closed
    const std::vector<std::vector<LonLat>> rings = cutRingAtAntimeridian(counterClockwise(ring));
    if (rings.empty()) continue;
    polygons["features"].push_back(
        {{"type", "Feature"},
         {"properties", {{"subframe_id", f.id}, {"line_id", f.line_id}, {"swath_m", f.half_width_m},
                         {"start_utc", sss::core::formatUtimeIso8601(f.pings.front().utime_us)},
                         {"end_utc", sss::core::formatUtimeIso8601(f.pings.back().utime_us)}}},
         {"geometry", polygonGeometry(rings)}});
  }
  return write(dir + "/subframes.geojson", polygons);
}

}  // namespace sss::products
