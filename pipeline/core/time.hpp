// Time: microseconds since the Unix epoch ("utime", as in every LCM message) and conversions.
#pragma once

#include <cstdint>
#include <string>

namespace sss::core {

constexpr int64_t kMicrosecondsPerSecond = 1000000;

// Wall-clock time (CLOCK_REALTIME), for message stamps.
int64_t nowUtime();
// Monotonic time in microseconds (CLOCK_MONOTONIC), for latencies, rates and timers.
int64_t monotonicUtime();

inline double utimeToSeconds(int64_t utime_us) { return static_cast<double>(utime_us) * 1e-6; }
int64_t secondsToUtime(double seconds);

// "2026-11-21T22:28:45.123456Z"
std::string formatUtimeIso8601(int64_t utime_us);

// A time window check for stamps from the field: rejects zero, negative and absurd values
// (before 2000 or after 2100) that a corrupt message or a sonar with an unset clock would carry.
bool isPlausibleUtime(int64_t utime_us);

}  // namespace sss::core
