// Estimates the offset between the sonar's clock and the host clock from ping times and
// arrival times. Arrival = ping time + acquisition + transport delay + offset, and the delay is
// never negative, so the minimum of (arrival - end of acquisition) over a sliding window tracks
// offset + smallest delay: robust to jitter and bursts (which only add delay), and it follows a
// slowly drifting sonar clock.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>

namespace sss::edgetech {

struct ClockOffsetOptions {
  double window_s = 60.0;       // sliding window of host time
  int min_samples = 5;          // before this many pings, no estimate
  double max_step_s = 5.0;      // a jump larger than this (sonar clock reset) restarts the estimate
};

class ClockOffsetEstimator {
 public:
  explicit ClockOffsetEstimator(ClockOffsetOptions options = {});

  // sonar_end_us: the sonar time at which the ping's last sample was recorded (ping time +
  // samples x interval); host_arrival_us: host wall-clock time its last byte arrived.
  void add(int64_t sonar_end_us, int64_t host_arrival_us);

  // host = sonar + offset; nullopt until min_samples pings were seen.
  std::optional<int64_t> offsetUs() const;
  uint64_t resets() const { return resets_; }

 private:
  struct Sample {
    int64_t host_us;
    int64_t difference_us;
  };
  ClockOffsetOptions options_;
  std::deque<Sample> window_;  // monotone: differences increasing from front to back
  int64_t samples_seen_ = 0;
  uint64_t resets_ = 0;
};

}  // namespace sss::edgetech
