// Sonar clock offset, see clock_offset.hpp.
#include "drivers/edgetech/clock_offset.hpp"

#include <cstdlib>

namespace sss::edgetech {

ClockOffsetEstimator::ClockOffsetEstimator(ClockOffsetOptions options) : options_(options) {}

void ClockOffsetEstimator::add(int64_t sonar_end_us, int64_t host_arrival_us) {
  const int64_t difference = host_arrival_us - sonar_end_us;
  const auto current = offsetUs();
  if (current && std::llabs(difference - *current) > static_cast<int64_t>(options_.max_step_s * 1e6)) {
    // The sonar clock was set or reset: the old window describes another clock.
    window_.clear();
    samples_seen_ = 0;
    ++resets_;
  }
  // Monotone deque for a sliding-window minimum: O(1) amortised per ping.
  while (!window_.empty() && window_.back().difference_us >= difference) window_.pop_back();
  window_.push_back({host_arrival_us, difference});
  const int64_t oldest_allowed = host_arrival_us - static_cast<int64_t>(options_.window_s * 1e6);
  while (window_.size() > 1 && window_.front().host_us < oldest_allowed) window_.pop_front();
  ++samples_seen_;
}

std::optional<int64_t> ClockOffsetEstimator::offsetUs() const {
  if (samples_seen_ < options_.min_samples || window_.empty()) return std::nullopt;
  return window_.front().difference_us;
}

}  // namespace sss::edgetech
