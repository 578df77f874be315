// Ping-navigation fusion: keeps a bounded navigation history and pings waiting (bounded) for the
// nav samples that bracket them, and gives each ping its interpolated DR pose and altitude.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "pipeline/core/config.hpp"
#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/core/sensor_types.hpp"
#include "pipeline/subframe/bottom_tracker.hpp"

namespace sss::subframe {

// The sensor samples are core types (pipeline/core/sensor_types.hpp); the stage's names for them.
using NavInput = sss::core::NavSample;
using PingInput = sss::core::PingSample;
using sss::core::poseOf;

// Where a ping's altitude came from.
enum class AltitudeSource { kNav, kPingHeader, kBottomTrack };
const char* altitudeSourceName(AltitudeSource source);

// Which altitude the fusion uses (subframe_buffer.fusion.altitude_source):
//   nav: the navigation's (DVL), else the sonar's own header field, else the ping is dropped;
//   bottom_track: tracked in the sonar returns only;
//   auto: nav, else the header, else the bottom track (files without any altitude still work).
enum class AltitudePolicy { kNav, kBottomTrack, kAuto };

// A ping with its DR pose at the ping time.
struct FusedPing {
  PingInput ping;
  sss::core::Pose T_world_body;
  double altitude_m = 0.0;           // the sonar's height above the seabed (canonical h)
  bool altitude_from_ping = false;   // nav altitude was invalid or stale
  AltitudeSource altitude_source = AltitudeSource::kNav;
  double bottom_track_quality = 0.0; // of the bottom track when it was used (0..1, see BottomTrack)
  double heading_rad = 0.0;
  double roll_rad = 0.0;
  double heading_rate_rad_s = 0.0;   // over heading_rate_window_s centred on the ping (LS slope)
  double steady_heading_rad = 0.0;   // the LS fit's heading at the ping: noise averaged out
  double distance_travelled_m = 0.0;
};

struct PingNavFusionOptions {
  // Sonar mounting T_body_sonar: lever arm (FRD, m) and rotation (roll, pitch, yaw, rad).
  Eigen::Vector3d sonar_position_body_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d sonar_rpy_body_rad = Eigen::Vector3d::Zero();
  double nav_history_s = 60.0;        // nav kept behind the newest sample
  double max_nav_gap_s = 0.5;         // bracketing nav samples further apart: the ping is dropped
  // A ping waits this long (in ping time) for its nav, then drops: nav may lag the pings by this
  // less half the heading-rate window (an INS that stalled and carries on late).
  double max_ping_wait_s = 30.0;
  // Waiting pings beyond this: the oldest is dropped. Bounds memory (a raw 2205 ping of 2 x 20k
  // samples is 160 KB: 40 MB) whatever the ping rate: 64 s of pings at 4 Hz.
  int max_pending_pings = 256;
  // Heading rate (turn detection) over this span centred on the ping; pings wait for nav half of
  // it past them (latency). 8 s keeps 0.05 rad of INS heading noise below the turn threshold
  // (slope sigma ~0.004 rad/s) and still flags a 0.05 rad/s survey turn within ~2 s.
  double heading_rate_window_s = 8.0;
  // The ping's pose takes the fitted (steady) heading of that window instead of the interpolated
  // INS heading: INS heading noise then neither smears the image nor rotates subframe frames.
  bool pose_heading_from_fit = true;
  double min_altitude_m = 0.5;        // altitudes below this are treated as invalid
  AltitudePolicy altitude_source = AltitudePolicy::kAuto;
  BottomTrackerOptions bottom_track;
  // A side-scan's first strong return often comes from the inner edge of its beam, not from
  // nadir: on a real Marine Sonic record it reads 10-20 % above the DVL's altitude. While the
  // navigation's altitude and the bottom track both exist, their ratio is learned (median of the
  // last bottom_track_calibration_pings); when the navigation's altitude stops, the bottom track
  // is scaled by it. Before min_bottom_track_calibration_pings of them, and with no altitude in
  // the whole file, the first-return range is used as it is.
  int bottom_track_calibration_pings = 200;
  int min_bottom_track_calibration_pings = 20;
  int duplicate_memory_pings = 256;   // recent ping numbers remembered to catch duplicates

  sss::core::Pose T_body_sonar() const;
};

void readPingNavFusionOptions(sss::core::ConfigSection& section, PingNavFusionOptions& options);

struct PingNavFusionCounters {
  uint64_t nav_in = 0;
  uint64_t nav_out_of_order = 0;     // not newer than the newest nav: ignored
  uint64_t nav_without_position = 0; // before the first fix (no position, no frame): ignored
  uint64_t pings_in = 0;
  uint64_t pings_out = 0;
  uint64_t pings_reordered = 0;      // arrived late but within the waiting window: put in order
  uint64_t pings_out_of_order = 0;   // older than a ping already released: dropped
  uint64_t pings_duplicate = 0;      // ping number seen recently: dropped
  uint64_t dropped_no_nav = 0;       // waited max_ping_wait_s / overflow without bracketing nav
  uint64_t dropped_too_old = 0;      // older than the nav history
  uint64_t dropped_before_first_fix = 0;  // older than the first nav sample with a position
  uint64_t dropped_nav_gap = 0;      // bracketing nav samples more than max_nav_gap_s apart
  uint64_t dropped_no_altitude = 0;  // neither nav nor ping altitude usable
  uint64_t altitude_from_nav = 0;
  uint64_t altitude_from_ping = 0;   // nav altitude invalid/stale, the ping's own altitude used
  uint64_t altitude_from_bottom_track = 0;
  uint64_t altitude_implausible = 0; // nav or header altitude beyond the ping's range: not used
  double bottom_track_scale = 1.0;   // the last scale applied to the bottom track (see options)

  uint64_t droppedWithoutNav() const {
    return dropped_no_nav + dropped_too_old + dropped_nav_gap + dropped_before_first_fix;
  }
};

// Pings are released in time order, each once its bracketing nav has arrived (nav is assumed to
// arrive in time order; older nav is counted and ignored). Out-of-order pings: a ping older than
// one already waiting is put in order (counted as reordered); older than one already released
// it is dropped (counted). Nothing is extrapolated: no bracketing nav, no ping.
class PingNavFusion {
 public:
  explicit PingNavFusion(const PingNavFusionOptions& options);

  void addNav(const NavInput& nav, std::vector<FusedPing>& out);
  void addPing(PingInput ping, std::vector<FusedPing>& out);
  // End of input: pings still waiting are dropped (counted as no nav).
  void finish(std::vector<FusedPing>& out);

  const PingNavFusionCounters& counters() const { return counters_; }
  const BottomTrackerCounters& bottomTrackCounters() const { return bottom_tracker_.counters(); }
  size_t pendingPings() const { return pending_.size(); }
  size_t navHistorySize() const { return history_.size(); }
  size_t memoryBytes() const;

 private:
  void release(std::vector<FusedPing>& out, bool flush);
  bool resolve(PingInput&& ping, std::vector<FusedPing>& out);
  bool seenRecently(int64_t ping_number) const;

  PingNavFusionOptions options_;
  sss::core::Pose T_body_sonar_;
  BottomTracker bottom_tracker_;
  std::deque<double> altitude_ratios_;  // recorded altitude / bottom track, recent pings
  std::deque<NavInput> history_;
  std::deque<PingInput> pending_;   // sorted by utime
  std::deque<int64_t> recent_numbers_;
  int64_t last_released_utime_us_ = INT64_MIN;
  int64_t first_nav_utime_us_ = INT64_MIN;  // of the first nav with a position; MIN: none yet
  PingNavFusionCounters counters_;
};

}  // namespace sss::subframe
