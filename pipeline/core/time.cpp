// Time helpers, see time.hpp.
#include "pipeline/core/time.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>

namespace sss::core {

namespace {
int64_t clockUtime(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<int64_t>(ts.tv_sec) * kMicrosecondsPerSecond + ts.tv_nsec / 1000;
}
}  // namespace

int64_t nowUtime() { return clockUtime(CLOCK_REALTIME); }
int64_t monotonicUtime() { return clockUtime(CLOCK_MONOTONIC); }

int64_t secondsToUtime(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e6)); }

std::string formatUtimeIso8601(int64_t utime_us) {
  int64_t seconds = utime_us / kMicrosecondsPerSecond;
  int64_t micros = utime_us % kMicrosecondsPerSecond;
  if (micros < 0) {
    micros += kMicrosecondsPerSecond;
    seconds -= 1;
  }
  const time_t t = static_cast<time_t>(seconds);
  tm utc{};
  gmtime_r(&t, &utc);
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%04d-%02d-%02dT%02d:%02d:%02d.%06lldZ", utc.tm_year + 1900, utc.tm_mon + 1,
                utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec, static_cast<long long>(micros));
  return buffer;
}

bool isPlausibleUtime(int64_t utime_us) {
  constexpr int64_t kYear2000 = 946684800LL * kMicrosecondsPerSecond;
  constexpr int64_t kYear2100 = 4102444800LL * kMicrosecondsPerSecond;
  return utime_us >= kYear2000 && utime_us < kYear2100;
}

}  // namespace sss::core
