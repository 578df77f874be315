// Time helpers.
#include "pipeline/core/time.hpp"

#include <gtest/gtest.h>

namespace sss::core {
namespace {

TEST(Time, FormatsIso8601WithMicroseconds) {
  EXPECT_EQ(formatUtimeIso8601(0), "1970-01-01T00:00:00.000000Z");
  EXPECT_EQ(formatUtimeIso8601(1795300125123456LL), "2026-11-21T22:28:45.123456Z");
  EXPECT_EQ(formatUtimeIso8601(-1), "1969-12-31T23:59:59.999999Z");
}

TEST(Time, SecondsConversionRoundsToNearestMicrosecond) {
  EXPECT_EQ(secondsToUtime(1.0000004), 1000000);
  EXPECT_EQ(secondsToUtime(1.0000006), 1000001);
  EXPECT_DOUBLE_EQ(utimeToSeconds(2500000), 2.5);
}

TEST(Time, PlausibilityRejectsUnsetClocks) {
  EXPECT_FALSE(isPlausibleUtime(0));
  EXPECT_FALSE(isPlausibleUtime(-5));
  EXPECT_FALSE(isPlausibleUtime(4102444800LL * 1000000));
  EXPECT_TRUE(isPlausibleUtime(nowUtime()));
}

TEST(Time, MonotonicNeverGoesBack) {
  int64_t previous = monotonicUtime();
  for (int i = 0; i < 1000; ++i) {
    const int64_t now = monotonicUtime();
    EXPECT_GE(now, previous);
    previous = now;
  }
}

}  // namespace
}  // namespace sss::core
