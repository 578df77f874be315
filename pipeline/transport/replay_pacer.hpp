// Paces the replay of recorded data: a sample with sensor time t is due at
// start + (t - t_first) / speed on the monotonic clock; speed 0 means as fast as possible.
#pragma once

#include <cstdint>

namespace sss::transport {

class ReplayPacer {
 public:
  explicit ReplayPacer(double speed) : speed_(speed) {}
  // True when the sample is due at now_monotonic_us (the first sample always is).
  bool due(int64_t sensor_time_us, int64_t now_monotonic_us) {
    if (speed_ <= 0.0) return true;
    if (first_sensor_us_ < 0) {
      first_sensor_us_ = sensor_time_us;
      start_monotonic_us_ = now_monotonic_us;
    }
    const double elapsed_us = static_cast<double>(sensor_time_us - first_sensor_us_) / speed_;
    return now_monotonic_us >= start_monotonic_us_ + static_cast<int64_t>(elapsed_us);
  }

 private:
  double speed_;
  int64_t first_sensor_us_ = -1;
  int64_t start_monotonic_us_ = 0;
};

}  // namespace sss::transport
