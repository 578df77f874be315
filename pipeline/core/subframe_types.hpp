// A subframe: N consecutive canonical pings of one survey line with their DR poses, the image the
// matcher matches and the ground-range axis that geo-references it (paper Sec. "Subframe Pose
// Estimation"). Built by the subframe stage, read by the matcher and the optimiser: a core type so
// that neither includes the subframe stage.
#pragma once

#include <cstdint>
#include <vector>

#include "pipeline/core/pose.hpp"

namespace sss::core {

// Mask codes of a canonical pixel, equal to subframe_t's MASK_ constants.
enum MaskCode : uint8_t {
  kMaskValid = 0,
  kMaskNadir = 1,
  kMaskWaterColumn = 2,
  kMaskFarRange = 3,
  kMaskTurn = 4,
  kMaskNoData = 5,
};

// Column of a side's ground-range bin, and back: column c < bins_per_side is port bin
// (bins_per_side - 1 - c), the rest starboard (subframe_t layout).
inline int columnOf(int bins_per_side, bool port, int bin) { return port ? bins_per_side - 1 - bin : bins_per_side + bin; }
inline int binOf(int bins_per_side, int column, bool& port) {
  port = column < bins_per_side;
  return port ? bins_per_side - 1 - column : column - bins_per_side;
}

// The ground-range axis and the sonar mounting of a subframe's image.
struct SubframeGeometry {
  int bins_per_side = 0;
  double bin_size_m = 0.0;
  double first_bin_range_m = 0.0;
  Pose T_body_sonar;

  int columns() const { return 2 * bins_per_side; }
  // Signed across-track ground range of a (fractional) column: port negative, starboard positive.
  double signedGroundRangeM(double column) const {
    if (column < bins_per_side) return -(first_bin_range_m + (bins_per_side - 1 - column) * bin_size_m);
    return first_bin_range_m + (column - bins_per_side) * bin_size_m;
  }
};

struct SubframePing {
  int64_t utime_us = 0;
  int64_t ping_number = 0;
  Pose T_world_body;             // DR
  double altitude_m = 0.0;       // the sonar's height above the seabed (the h of the transform)
  double distance_travelled_m = 0.0;
};

struct Subframe {
  int64_t id = 0;
  int line_id = 0;
  int centre_ping_index = 0;     // row of the centre ping
  std::vector<SubframePing> pings;
  SubframeGeometry geometry;
  std::vector<float> image;      // rows = pings, columns = geometry.columns(), normalised intensity
  std::vector<uint8_t> mask;     // MaskCode per pixel
  int64_t last_ping_arrival_monotonic_us = 0;

  int rows() const { return static_cast<int>(pings.size()); }
  int cols() const { return geometry.columns(); }
  const SubframePing& centre() const { return pings[centre_ping_index]; }
};

}  // namespace sss::core
