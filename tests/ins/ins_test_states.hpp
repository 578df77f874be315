// A simulated straight run for the INS bridge tests: heading east at 2 m/s, 10 Hz epochs.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "drivers/ins/ixblue_nmea.hpp"
#include "pipeline/core/geodesy.hpp"

namespace sss::test {

constexpr double kOriginLatitudeDeg = 59.35;
constexpr double kOriginLongitudeDeg = 18.07;
constexpr int64_t kStartUtime = 1780300800000000LL;  // 2026-06-01T08:00:00Z

inline ins::InsState eastboundState(int epoch) {
  const sss::core::LocalTangentPlane plane(kOriginLatitudeDeg, kOriginLongitudeDeg);
  const double t_s = 0.1 * epoch;
  const sss::core::GeodeticPosition geo = plane.toGeodetic(Eigen::Vector3d(10.0, 2.0 * t_s, 40.0));
  ins::InsState s;
  s.utime_us = kStartUtime + epoch * 100000;
  s.latitude_deg = geo.latitude_deg;
  s.longitude_deg = geo.longitude_deg;
  s.depth_m = geo.depth_m;
  s.altitude_m = 18.0;
  s.heading_rad = M_PI / 2;
  s.roll_rad = 0.01;
  s.pitch_rad = -0.02;
  s.velocity_east_m_s = 2.0;
  s.latitude_std_m = 1.0;
  s.longitude_std_m = 1.0;
  s.depth_std_m = 0.1;
  s.heading_std_rad = 0.001;
  s.validity = ins::kValidAll;
  return s;
}

inline std::string eastboundStream(int epochs) {
  std::string stream;
  for (int e = 0; e < epochs; ++e) stream += ins::encodeInsState(eastboundState(e));
  return stream;
}

}  // namespace sss::test
