// Geodesy on GeographicLib, see geodesy.hpp.
#include "pipeline/core/geodesy.hpp"

#include <GeographicLib/LocalCartesian.hpp>

namespace sss::core {

struct LocalTangentPlane::Impl {
  GeographicLib::LocalCartesian enu;
};

LocalTangentPlane::LocalTangentPlane(double origin_latitude_deg, double origin_longitude_deg)
    : origin_latitude_deg_(origin_latitude_deg),
      origin_longitude_deg_(origin_longitude_deg),
      impl_(std::make_unique<Impl>(Impl{GeographicLib::LocalCartesian(origin_latitude_deg, origin_longitude_deg, 0.0)})) {}

LocalTangentPlane::~LocalTangentPlane() = default;

LocalTangentPlane::LocalTangentPlane(const LocalTangentPlane& other)
    : origin_latitude_deg_(other.origin_latitude_deg_),
      origin_longitude_deg_(other.origin_longitude_deg_),
      impl_(std::make_unique<Impl>(*other.impl_)) {}

LocalTangentPlane& LocalTangentPlane::operator=(const LocalTangentPlane& other) {
  if (this != &other) {
    origin_latitude_deg_ = other.origin_latitude_deg_;
    origin_longitude_deg_ = other.origin_longitude_deg_;
    impl_ = std::make_unique<Impl>(*other.impl_);
  }
  return *this;
}

Eigen::Vector3d LocalTangentPlane::toNed(const GeodeticPosition& position) const {
  double east = 0.0, north = 0.0, up = 0.0;
  impl_->enu.Forward(position.latitude_deg, position.longitude_deg, -position.depth_m, east, north, up);
  return {north, east, -up};
}

GeodeticPosition LocalTangentPlane::toGeodetic(const Eigen::Vector3d& position_ned_m) const {
  GeodeticPosition position;
  double height = 0.0;
  impl_->enu.Reverse(position_ned_m.y(), position_ned_m.x(), -position_ned_m.z(), position.latitude_deg,
                     position.longitude_deg, height);
  position.depth_m = -height;
  return position;
}

}  // namespace sss::core
