// Bottom tracking: the sonar's altitude above the seabed from its own returns, for files and
// vehicles whose navigation carries none (a towed fish, no DVL, a header field left at 0).
//
// Per side, the first seabed return is the strongest rise of the log-intensity envelope: the
// contrast between the mean level over `after_window_m` past a candidate range and the mean
// level of the whole water column before it. Taking the whole column before (not a short window)
// keeps a fish or a surface echo, bright but short, from outscoring the seabed, and makes a later
// bright patch of seabed (rock after mud) score low, because its "before" already holds seabed.
// Of the candidates within `first_return_fraction` of the best contrast, the nearest wins (the
// first return, not the brightest). Both sides see the same nadir: two agreeing sides are
// averaged; a dead or disagreeing side gives way to the one nearer the track. Along track, the
// median of the recent accepted detections gates the next one: further than the gate from it is
// an outlier (counted) unless the track keeps disagreeing for a whole window, which is a real
// change (a step in the seabed), and restarts the track. The altitude given is a straight line
// fitted to the recent accepted detections, at this ping: smoothed, without the lag a running
// median has on a slope.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "pipeline/core/config.hpp"

namespace sss::subframe {

struct BottomTrackerOptions {
  double min_altitude_m = 0.5;          // returns nearer are the transmit pulse and ringing
  double bin_m = 0.1;                   // samples averaged before the search (speckle, speed)
  double after_window_m = 2.0;          // the seabed level is measured over this much past the edge
  double min_contrast_db = 3.0;         // weaker rises are no seabed (a dead side, all water)
  double first_return_fraction = 0.7;   // candidates this close to the best contrast: the nearest wins
  double sides_agree_m = 0.3;           // two sides within max(this, sides_agree_fraction x altitude)
  double sides_agree_fraction = 0.05;   //   are one detection
  int smoothing_pings = 9;              // median over the last accepted detections
  double gate_m = 1.0;                  // a detection further from the track than max(gate_m,
  double gate_fraction = 0.2;           //   gate_fraction x altitude) is an outlier
};

void readBottomTrackerOptions(sss::core::ConfigSection& section, BottomTrackerOptions& options);

// One side's detection.
struct SideDetection {
  bool valid = false;
  double slant_range_m = 0.0;
  double contrast_db = 0.0;
};

// Finds the first seabed return in one side's envelope (sample 0 at start_range_m, spacing_m apart).
SideDetection detectFirstReturn(const std::vector<float>& envelope, double start_range_m, double spacing_m,
                                const BottomTrackerOptions& options);

struct BottomTrack {
  bool valid = false;
  double altitude_m = 0.0;      // smoothed along track (median)
  double raw_altitude_m = 0.0;  // this ping's detection
  // Share of the last smoothing_pings pings whose detection was accepted, times the share of
  // sides that saw the seabed: 1 is a clean track on both sides, 0.5 one dead side or every
  // other ping lost.
  double quality = 0.0;
};

struct BottomTrackerCounters {
  uint64_t pings = 0;
  uint64_t detected = 0;        // a seabed return on at least one side
  uint64_t one_side_only = 0;   // of those, seen on one side only (a dead or shadowed side)
  uint64_t outliers = 0;        // detections off the track (fish, surface echo), not used
  uint64_t restarts = 0;        // the track followed a lasting change
};

class BottomTracker {
 public:
  explicit BottomTracker(const BottomTrackerOptions& options = {});
  // Pings in time order. Invalid before the first detection and while detections are outliers.
  BottomTrack track(const std::vector<float>& port, const std::vector<float>& starboard, double start_range_m,
                    double spacing_m);
  const BottomTrackerCounters& counters() const { return counters_; }

 private:
  double median() const;
  double lineAtNewest() const;

  BottomTrackerOptions options_;
  std::deque<double> accepted_m_;   // the last accepted detections
  std::deque<uint64_t> accepted_ping_;  // their ping numbers (counters_.pings when detected)
  std::deque<double> recent_score_; // per recent ping: 0 lost, 0.5 one side, 1 both sides
  int consecutive_outliers_ = 0;
  std::deque<double> outlier_run_m_;
  std::deque<uint64_t> outlier_run_ping_;
  BottomTrackerCounters counters_;
};

}  // namespace sss::subframe
