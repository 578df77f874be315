// Ties absolute position fixes to the navigation they correct: dates a fix that has a time of day
// only, places it in the mission's local NED frame, and takes the DR position and distance travelled
// at its time from the navigation samples around it (interpolated), so that the pose graph can tie
// it to a node through DR. A GNSS fix counts only while the vehicle is at the surface. Used by the
// INS bridge (live: fixes and navigation arrive interleaved, a USBL fix seconds late) and by the
// offline runner, so both place fixes the same way. No sockets, no LCM.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "drivers/ins/position_fix.hpp"
#include "pipeline/core/geodesy.hpp"
#include "pipeline/core/mission_origin.hpp"

namespace sss::ins {

struct FixAlignerOptions {
  // Under water a GNSS receiver reports stale positions: its fixes count above this depth only.
  double gnss_max_depth_m = 1.0;
  // A fix this far outside the navigation received so far has no DR position to tie it to.
  double max_extrapolation_s = 2.0;
  // Navigation kept for late fixes (USBL relayed through the acoustic modem): older fixes are dropped.
  double max_latency_s = 120.0;
};

// A fix in the mission frame with the DR state at its time.
struct AlignedFix {
  PositionFix fix;                                            // as read, dated
  Eigen::Vector2d position_ne_m = Eigen::Vector2d::Zero();    // local NED north, east
  Eigen::Matrix2d covariance_m2 = Eigen::Matrix2d::Identity();
  Eigen::Vector3d dr_position_m = Eigen::Vector3d::Zero();    // DR position at the fix time
  double dr_distance_m = 0.0;                                 // DR distance travelled then
  double depth_m = 0.0;                                       // the vehicle's (DR) depth then
};

struct FixAlignerCounters {
  uint64_t fixes_in = 0;
  uint64_t aligned = 0;
  uint64_t below_surface = 0;       // GNSS while deeper than gnss_max_depth_m
  uint64_t outside_navigation = 0;  // before the navigation started, after it ended, or too late
  uint64_t no_frame = 0;            // no geographic mission origin (yet)
};

class FixAligner {
 public:
  explicit FixAligner(const FixAlignerOptions& options = {});

  // A navigation sample in time order (others are ignored); origin: the mission frame's, when known.
  void addNav(int64_t utime_us, const Eigen::Vector3d& position_ned_m, double distance_travelled_m,
              const std::optional<sss::core::MissionOrigin>& origin);
  // A fix as read (dated, or dated here from the newest navigation time).
  void addFix(const PositionFix& fix);
  // The fixes the navigation has passed, in time order; final: all of them (end of input: those
  // within max_extrapolation_s of the last sample are extrapolated, the rest counted and dropped).
  std::vector<AlignedFix> take(bool final = false);

  const FixAlignerCounters& counters() const { return counters_; }

 private:
  struct NavPoint {
    int64_t utime_us = 0;
    Eigen::Vector3d position_ned_m = Eigen::Vector3d::Zero();
    double distance_m = 0.0;
  };
  // Ties one fix; false when it was counted and dropped.
  bool align(const PositionFix& fix, AlignedFix& out);

  FixAlignerOptions options_;
  std::deque<NavPoint> history_;
  std::vector<PositionFix> waiting_;  // dated, not yet passed by the navigation
  std::vector<PositionFix> undated_;  // before any navigation time to date them by
  std::optional<sss::core::MissionOrigin> origin_;
  std::optional<sss::core::LocalTangentPlane> plane_;
  FixAlignerCounters counters_;
};

}  // namespace sss::ins
