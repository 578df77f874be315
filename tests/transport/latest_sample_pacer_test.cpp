// The DDS correction's pacing: at most one write per period, the newest sample kept, the held one
// written from the timer only once the stream has been quiet for half a period.
#include "pipeline/transport/latest_sample_pacer.hpp"

#include <gtest/gtest.h>

namespace sss::transport {
namespace {

constexpr int64_t kPeriodUs = 100'000;  // 10 Hz

TEST(LatestSamplePacer, WritesTheFirstSampleAndAtMostOnePerPeriod) {
  LatestSamplePacer<int> pacer(kPeriodUs);
  EXPECT_EQ(pacer.offer(1, 1'000'000), 1);
  // 200 Hz nav: the next 19 samples fall within the period and wait, the newest replacing the older.
  for (int i = 2; i <= 20; ++i) EXPECT_FALSE(pacer.offer(i, 1'000'000 + (i - 1) * 5'000).has_value()) << i;
  // The next sample after a period is written fresh; the held one (20) is dropped, not written late.
  EXPECT_EQ(pacer.offer(21, 1'100'000), 21);
  EXPECT_FALSE(pacer.poll(1'300'000).has_value());
}

TEST(LatestSamplePacer, TheTimerWritesTheHeldSampleOnceTheStreamIsQuiet) {
  LatestSamplePacer<int> pacer(kPeriodUs);
  EXPECT_EQ(pacer.offer(1, 0), 1);
  EXPECT_FALSE(pacer.offer(2, 60'000).has_value());
  EXPECT_FALSE(pacer.poll(90'000).has_value());   // within the period of the last write
  EXPECT_FALSE(pacer.poll(105'000).has_value());  // a period since the write, but the stream spoke 45 ms ago
  EXPECT_EQ(pacer.poll(110'000), 2);              // quiet for half a period: written
  EXPECT_FALSE(pacer.poll(400'000).has_value());  // once
  EXPECT_FALSE(pacer.offer(3, 150'000).has_value());  // within the period of that write
  EXPECT_EQ(pacer.poll(260'000), 3);
}

}  // namespace
}  // namespace sss::transport
