// Health figures: rates, percentiles, drops, errors logged once.
#include "pipeline/core/health.hpp"

#include <gtest/gtest.h>

namespace sss::core {
namespace {

TEST(Health, PercentileByNearestRank) {
  std::vector<int64_t> samples;
  for (int i = 100; i >= 1; --i) samples.push_back(i);
  EXPECT_DOUBLE_EQ(percentile(samples, 50.0), 50.0);
  EXPECT_DOUBLE_EQ(percentile(samples, 99.0), 99.0);
  EXPECT_DOUBLE_EQ(percentile(samples, 100.0), 100.0);
  std::vector<int64_t> empty;
  EXPECT_DOUBLE_EQ(percentile(empty, 50.0), 0.0);
}

TEST(Health, SnapshotGivesRatesOverThePeriodAndLatencies) {
  HealthMonitor health(0);
  for (int i = 0; i < 20; ++i) health.recordMessage("SSS_PING", false, 1000 * (i + 1));  // 1..20 ms
  health.recordDrop("SSS_PING", false, 3);
  health.setQueueDepth("SSS_PING", false, 7);
  const HealthSnapshot first = health.snapshot(2'000'000);  // 2 s
  ASSERT_EQ(first.channels.size(), 1u);
  EXPECT_DOUBLE_EQ(first.channels[0].rate_hz, 10.0);
  EXPECT_DOUBLE_EQ(first.channels[0].latency_p50_ms, 10.0);
  EXPECT_DOUBLE_EQ(first.channels[0].latency_max_ms, 20.0);
  EXPECT_EQ(first.channels[0].drops, 3);
  EXPECT_EQ(first.channels[0].queue_depth, 7);
  EXPECT_DOUBLE_EQ(first.uptime_s, 2.0);

  health.recordMessage("SSS_PING", false, 500);
  const HealthSnapshot second = health.snapshot(3'000'000);
  EXPECT_DOUBLE_EQ(second.channels[0].rate_hz, 1.0);
  EXPECT_EQ(second.channels[0].messages, 21);
  EXPECT_DOUBLE_EQ(second.channels[0].latency_max_ms, 0.5);
}

TEST(Health, IncomingAndOutgoingOfOneChannelAreKeptApart) {
  HealthMonitor health(0);
  health.recordMessage("SSS_NAV", true, 10);
  health.recordMessage("SSS_NAV", false, 20);
  health.recordMessage("SSS_NAV", false, 30);
  const HealthSnapshot snap = health.snapshot(1'000'000);
  ASSERT_EQ(snap.channels.size(), 2u);
  EXPECT_FALSE(snap.channels[0].outgoing);
  EXPECT_EQ(snap.channels[0].messages, 2);
  EXPECT_TRUE(snap.channels[1].outgoing);
  EXPECT_EQ(snap.channels[1].messages, 1);
}

TEST(Health, ErrorOfAKindIsReportedForLoggingOnlyOnce) {
  HealthMonitor health(0);
  EXPECT_TRUE(health.recordError("jsf_checksum", "bad checksum at byte 10", 1));
  EXPECT_FALSE(health.recordError("jsf_checksum", "bad checksum at byte 99", 2));
  EXPECT_TRUE(health.recordError("nmea_checksum", "bad NMEA", 3));
  const HealthSnapshot snap = health.snapshot(1'000'000);
  EXPECT_EQ(snap.errors_total, 3);
  EXPECT_EQ(snap.last_error, "bad NMEA");
  EXPECT_DOUBLE_EQ(health.counter("error.jsf_checksum"), 2.0);
}

TEST(Health, LatencyMemoryStaysBounded) {
  HealthMonitor health(0);
  for (int i = 0; i < 100000; ++i) health.recordMessage("X", true, 1);
  const HealthSnapshot snap = health.snapshot(1'000'000);
  EXPECT_EQ(snap.channels[0].messages, 100000);
  EXPECT_DOUBLE_EQ(snap.channels[0].latency_p99_ms, 0.001);
}

}  // namespace
}  // namespace sss::core
