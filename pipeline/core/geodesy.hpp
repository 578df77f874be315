// Geodesy: WGS-84 latitude/longitude/depth <-> local NED tangent plane at a mission origin.
// Uses GeographicLib's LocalCartesian (ENU internally), exact, not a flat-earth approximation.
#pragma once

#include <Eigen/Core>
#include <memory>

namespace sss::core {

struct GeodeticPosition {
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
  double depth_m = 0.0;  // below the ellipsoid surface at the origin's height, positive down
};

class LocalTangentPlane {
 public:
  // The origin lies at depth 0 below (latitude_deg, longitude_deg) on the WGS-84 ellipsoid.
  LocalTangentPlane(double origin_latitude_deg, double origin_longitude_deg);
  ~LocalTangentPlane();
  LocalTangentPlane(const LocalTangentPlane& other);
  LocalTangentPlane& operator=(const LocalTangentPlane& other);

  // (north, east, down) in metres.
  Eigen::Vector3d toNed(const GeodeticPosition& position) const;
  GeodeticPosition toGeodetic(const Eigen::Vector3d& position_ned_m) const;

  double originLatitudeDeg() const { return origin_latitude_deg_; }
  double originLongitudeDeg() const { return origin_longitude_deg_; }

 private:
  struct Impl;
  double origin_latitude_deg_;
  double origin_longitude_deg_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sss::core
