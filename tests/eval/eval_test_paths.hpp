// Hand-built trajectories shared by the evaluation tests: straight lines and a lawnmower with
// semicircular turns, sampled at a fixed rate, heading along the path.
#pragma once

#include "pipeline/core/pose.hpp"
#include "tools/eval/trajectory_io.hpp"

#include <cmath>
#include <cstdint>

namespace sss::eval::test {

constexpr int64_t kStartUtimeUs = 1780300800000000;

// Northbound straight line from the origin at speed_m_s, one pose per 1/rate_hz.
inline Trajectory straightLine(double length_m, double speed_m_s = 2.0, double rate_hz = 4.0, double depth_m = 30.0) {
  Trajectory poses;
  const int count = static_cast<int>(std::floor(length_m / speed_m_s * rate_hz)) + 1;
  for (int i = 0; i < count; ++i) {
    const double t = i / rate_hz;
    poses.push_back({kStartUtimeUs + static_cast<int64_t>(std::llround(t * 1e6)),
                     sss::core::Pose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(speed_m_s * t, 0.0, depth_m))});
  }
  return poses;
}

// Lines of line_length_m along north (alternating north/south), spacing_m apart to the east,
// joined by semicircles (radius spacing/2); depth varies gently so the path is not planar.
inline Trajectory lawnmower(int lines, double line_length_m, double spacing_m, double speed_m_s = 2.0,
                            double rate_hz = 4.0) {
  const double radius = 0.5 * spacing_m;
  const double turn_length = M_PI * radius;
  const double total = lines * line_length_m + (lines - 1) * turn_length;
  Trajectory poses;
  for (int i = 0;; ++i) {
    const double t = i / rate_hz;
    const double s = speed_m_s * t;
    if (s > total + 1e-9) break;
    const int k = std::min(static_cast<int>(s / (line_length_m + turn_length)), lines - 1);
    const double a = s - k * (line_length_m + turn_length);
    const bool north = k % 2 == 0;
    double n = 0.0, e = k * spacing_m, heading = north ? 0.0 : M_PI;
    if (a <= line_length_m || k == lines - 1) {
      n = north ? a : line_length_m - a;
    } else {
      // Turn: clockwise at the north end after a northbound line, anticlockwise at the south end.
      const double phi = (a - line_length_m) / radius;
      const double centre_e = e + radius;
      if (north) {
        n = line_length_m + radius * std::sin(phi);
        e = centre_e - radius * std::cos(phi);
        heading = phi;
      } else {
        n = -radius * std::sin(phi);
        e = centre_e - radius * std::cos(phi);
        heading = M_PI - phi;
      }
    }
    const double depth = 30.0 + 2.0 * std::sin(s / 150.0);
    poses.push_back({kStartUtimeUs + static_cast<int64_t>(std::llround(t * 1e6)),
                     sss::core::Pose(sss::core::quaternionFromEuler(0.0, 0.0, heading), Eigen::Vector3d(n, e, depth))});
  }
  return poses;
}

}  // namespace sss::eval::test
