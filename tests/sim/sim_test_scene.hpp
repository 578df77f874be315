// Test scene shared by the sonar and geometry tests: a flat bed at 40 m with one tall bright
// boulder 40 m to starboard of a northbound vehicle flying at 18 m altitude.
#pragma once

#include "tools/sim/seabed.hpp"
#include "tools/sim/sonar_model.hpp"

#include <vector>

namespace sss::sim::test {

constexpr double kBedDepthM = 40.0;
constexpr double kAltitudeM = 18.0;
constexpr double kObjectEastM = 40.0;
constexpr double kObjectRadiusM = 1.0;
constexpr double kObjectHeightM = 1.5;

inline SeabedOptions boulderScene() {
  SeabedOptions options;
  options.enable_texture = false;
  options.mean_depth_m = kBedDepthM;
  options.north_min_m = -40.0;
  options.east_min_m = -90.0;
  options.size_north_m = 80.0;
  options.size_east_m = 180.0;
  options.resolution_m = 0.1;
  options.objects.push_back({0.0, kObjectEastM, kObjectRadiusM, kObjectHeightM, 1.2});
  return options;
}

// Northbound, level, at 18 m altitude over the flat bed.
inline sss::core::Pose levelPoseAt(double north_m) {
  return sss::core::Pose(sss::core::quaternionFromEuler(0.0, 0.0, 0.0),
                         Eigen::Vector3d(north_m, 0.0, kBedDepthM - kAltitudeM));
}

// Pings every 0.5 m from -10 m to +10 m north.
inline std::vector<sss::core::Pose> passOverObject() {
  std::vector<sss::core::Pose> poses;
  for (int i = 0; i <= 40; ++i) poses.push_back(levelPoseAt(-10.0 + 0.5 * i));
  return poses;
}

inline double mean(const std::vector<float>& values, int first, int last) {
  double sum = 0.0;
  for (int i = first; i < last; ++i) sum += values[i];
  return sum / (last - first);
}

}  // namespace sss::sim::test
