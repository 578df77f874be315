// Subframe footprints as products, see footprints.hpp.
#include "products/footprints.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>

#include "pipeline/core/geodesy.hpp"
#include "pipeline/core/time.hpp"

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

Status writeGeoJsonFiles(const std::string& dir, const std::vector<sss::optimiser::StampedPose>& slam,
                         const std::vector<sss::optimiser::StampedPose>& dr,
                         const std::vector<SubframeFootprint>& footprints, const sss::optimiser::OptimiserEngine& engine,
                         const std::optional<sss::core::MissionOrigin>& origin) {
  if (!origin) return Status::success();
  const sss::core::LocalTangentPlane plane(origin->latitude_deg, origin->longitude_deg);
  auto lonLat = [&](const Eigen::Vector3d& ned) {
    const sss::core::GeodeticPosition g = plane.toGeodetic(ned);
    // 1e-8 deg (~1 mm) is all a GIS needs and keeps the files small.
    return nlohmann::json::array({std::round(g.longitude_deg * 1e8) / 1e8, std::round(g.latitude_deg * 1e8) / 1e8});
  };
  auto write = [&](const std::string& path, const nlohmann::json& json) {
    std::ofstream out(path);
    out << json.dump() << "\n";
    return out ? Status::success() : Status::error("cannot write " + path);
  };
  nlohmann::json tracks = {{"type", "FeatureCollection"}, {"features", nlohmann::json::array()}};
  for (const auto& [name, poses] : {std::pair<const char*, const std::vector<sss::optimiser::StampedPose>*>{"SLAM", &slam},
                                    {"DR", &dr}}) {
    nlohmann::json line = nlohmann::json::array();
    for (size_t i = 0; i < poses->size(); ++i)
      if (i % 4 == 0 || i + 1 == poses->size()) line.push_back(lonLat((*poses)[i].T_world_body.translation));
    if (line.size() < 2) continue;
    tracks["features"].push_back({{"type", "Feature"},
                                  {"properties", {{"name", name},
                                                  {"start_utc", sss::core::formatUtimeIso8601(poses->front().utime_us)},
                                                  {"end_utc", sss::core::formatUtimeIso8601(poses->back().utime_us)}}},
                                  {"geometry", {{"type", "LineString"}, {"coordinates", line}}}});
  }
  if (const Status written = write(dir + "/track.geojson", tracks); !written) return written;

  nlohmann::json polygons = {{"type", "FeatureCollection"}, {"features", nlohmann::json::array()}};
  const std::vector<FootprintStrip> strips = slamStrips(footprints, engine);
  for (size_t k = 0; k < footprints.size(); ++k) {
    const SubframeFootprint& f = footprints[k];
    const FootprintStrip& strip = strips[k];
    if (strip.port_ne_m.size() < 2) continue;
    nlohmann::json ring = nlohmann::json::array();
    for (const auto& p : strip.port_ne_m) ring.push_back(lonLat(Eigen::Vector3d(p.x(), p.y(), 0.0)));
    for (auto it = strip.starboard_ne_m.rbegin(); it != strip.starboard_ne_m.rend(); ++it)
      ring.push_back(lonLat(Eigen::Vector3d(it->x(), it->y(), 0.0)));
    ring.push_back(ring.front());  // closed
    polygons["features"].push_back(
        {{"type", "Feature"},
         {"properties", {{"subframe_id", f.id}, {"line_id", f.line_id}, {"swath_m", f.half_width_m},
                         {"start_utc", sss::core::formatUtimeIso8601(f.pings.front().utime_us)},
                         {"end_utc", sss::core::formatUtimeIso8601(f.pings.back().utime_us)}}},
         {"geometry", {{"type", "Polygon"}, {"coordinates", nlohmann::json::array({ring})}}}});
  }
  return write(dir + "/subframes.geojson", polygons);
}

}  // namespace sss::products
