// Paces a stream of samples of which only the newest matters (the navigation correction on DDS):
// at most one write per period. A sample that comes within a period of the last write waits, the
// newer replacing the older; the timer writes it only once the stream has been quiet for half a
// period, because otherwise the next sample, a few ms later, is written fresh instead. Times are
// the caller's monotonic clock, so that the rule is testable without waiting.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>

namespace sss::transport {

template <typename Sample>
class LatestSamplePacer {
 public:
  explicit LatestSamplePacer(int64_t period_us) : period_us_(period_us) {}

  // A new sample at now_us: the sample to write now, or nothing (it waits).
  std::optional<Sample> offer(const Sample& sample, int64_t now_us) {
    last_offer_us_ = now_us;
    if (now_us - last_write_us_ >= period_us_) return written(sample, now_us);
    pending_ = sample;
    return std::nullopt;
  }

  // From a timer (a quarter period is enough): the waiting sample, when it is due.
  std::optional<Sample> poll(int64_t now_us) {
    if (!pending_ || now_us - last_write_us_ < period_us_ || now_us - last_offer_us_ < period_us_ / 2) {
      return std::nullopt;
    }
    const Sample sample = *pending_;
    return written(sample, now_us);
  }

 private:
  std::optional<Sample> written(const Sample& sample, int64_t now_us) {
    last_write_us_ = now_us;
    pending_.reset();
    return sample;
  }

  int64_t period_us_;
  int64_t last_write_us_ = std::numeric_limits<int64_t>::min() / 2;
  int64_t last_offer_us_ = 0;
  std::optional<Sample> pending_;
};

}  // namespace sss::transport
