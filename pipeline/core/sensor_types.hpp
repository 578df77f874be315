// The sensor samples every stage reads: one DR navigation sample (SSS_NAV without the middleware)
// and one side-scan ping (SSS_PING without the middleware). Written by the INS bridge, the sonar
// driver and the file readers; read by the subframe stage, the optimiser (which answers each nav
// sample with a corrected pose) and the offline runner. Core types, so that none of these includes
// another's headers (OpenVINS' ov_core/src/utils/sensor_data.h is the pattern).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/pose.hpp"

namespace sss::core {

// One DR navigation sample.
struct NavSample {
  int64_t utime_us = 0;
  Eigen::Vector3d position_ned_m = Eigen::Vector3d::Zero();  // body origin, local NED
  // False before the navigation's first fix (no position, so no frame yet): not fused.
  bool position_valid = true;
  // The mission origin position_ned_m is relative to, when the source says (SSS_NAV does).
  std::optional<MissionOrigin> origin;
  double roll_rad = 0.0;
  double pitch_rad = 0.0;
  double heading_rad = 0.0;
  double altitude_m = -1.0;        // body above seabed (DVL)
  bool altitude_valid = false;     // valid and not stale
  double distance_travelled_m = 0.0;
  // The INS's own 1-sigma accuracy of position_ned_m, north and east (0: not reported).
  double position_std_north_m = 0.0;
  double position_std_east_m = 0.0;
};

// The DR pose of a nav sample: T_world_body from its local NED position and attitude.
inline Pose poseOf(const NavSample& nav) {
  return Pose(quaternionFromEuler(nav.roll_rad, nav.pitch_rad, nav.heading_rad), nav.position_ned_m);
}

// One side-scan ping.
struct PingSample {
  int64_t utime_us = 0;
  int64_t ping_number = 0;
  double sound_speed_m_s = 1500.0;
  double sample_interval_s = 0.0;  // two-way travel time between samples
  double start_range_m = 0.0;      // slant range of sample 0
  double altitude_m = -1.0;        // the sonar's own altitude; < 0 when unknown
  std::vector<float> port;
  std::vector<float> starboard;
  int64_t arrival_monotonic_us = 0;  // when the ping reached this process (latency figures)

  double sampleSpacingM() const { return 0.5 * sound_speed_m_s * sample_interval_s; }
};

}  // namespace sss::core
