// Sonar clock offset: the sliding minimum of (arrival - end of acquisition) finds the offset
// plus the smallest transport delay despite jitter, and restarts after a clock reset.
#include "drivers/edgetech/clock_offset.hpp"

#include <gtest/gtest.h>

#include <random>

namespace sss::edgetech {
namespace {

TEST(ClockOffset, FindsTheOffsetUnderExponentialJitter) {
  ClockOffsetEstimator estimator;
  std::mt19937 rng(3);
  std::exponential_distribution<double> jitter_ms(1.0 / 20.0);  // mean 20 ms extra delay
  const int64_t offset_us = -3'250'000;                          // sonar clock 3.25 s ahead
  const int64_t min_delay_us = 2'000;
  EXPECT_FALSE(estimator.offsetUs());
  for (int i = 0; i < 400; ++i) {  // 100 s at 4 Hz
    const int64_t sonar_end = 1'780'000'000'000'000 + i * 250'000;
    const int64_t delay = min_delay_us + static_cast<int64_t>(jitter_ms(rng) * 1000.0);
    estimator.add(sonar_end, sonar_end + offset_us + delay);
  }
  ASSERT_TRUE(estimator.offsetUs());
  // Over a 60 s window (240 pings) the smallest exponential jitter is ~0.1 ms: within 1 ms.
  EXPECT_NEAR(static_cast<double>(*estimator.offsetUs()), static_cast<double>(offset_us + min_delay_us), 1000.0);
}

TEST(ClockOffset, FollowsADriftingSonarClock) {
  ClockOffsetOptions options;
  options.window_s = 10.0;
  ClockOffsetEstimator estimator(options);
  for (int i = 0; i < 4000; ++i) {  // 1000 s, sonar clock drifting 50 ppm
    const int64_t host = 1'780'000'000'000'000 + i * 250'000;
    const int64_t sonar = host - static_cast<int64_t>(i * 250'000 * 50e-6);
    estimator.add(sonar, host);
  }
  // True offset at the end: 50 ms; a 10 s window lags by at most 10 s x 50 ppm = 0.5 ms.
  EXPECT_NEAR(static_cast<double>(*estimator.offsetUs()), 50'000.0, 600.0);
}

TEST(ClockOffset, ClockResetRestartsTheEstimate) {
  ClockOffsetEstimator estimator;
  for (int i = 0; i < 10; ++i) estimator.add(1'000'000'000 + i * 250'000, 1'780'000'000'000'000 + i * 250'000);
  ASSERT_TRUE(estimator.offsetUs());
  // The sonar clock is set to the right time: the offset becomes ~0.
  for (int i = 10; i < 20; ++i) {
    const int64_t host = 1'780'000'000'000'000 + i * 250'000;
    estimator.add(host - 1000, host);
  }
  EXPECT_EQ(estimator.resets(), 1u);
  EXPECT_EQ(*estimator.offsetUs(), 1000);
}

}  // namespace
}  // namespace sss::edgetech
