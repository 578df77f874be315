// Port/starboard joining by ping number, timeouts for a missing side, bounded pending state.
#include "drivers/edgetech/ping_assembler.hpp"

#include <gtest/gtest.h>

#include "jsf_test_data.hpp"

namespace sss::edgetech {
namespace {

TEST(PingAssembler, JoinsBothSidesOfAPingInEitherOrder) {
  PingAssembler assembler;
  std::vector<AssembledPing> out;
  assembler.add(test::makeRecord(5, kChannelStarboard), 100, out);
  EXPECT_TRUE(out.empty());
  assembler.add(test::makeRecord(5, kChannelPort), 200, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].complete());
  EXPECT_EQ(out[0].ping_number, 5u);
  EXPECT_EQ(out[0].last_arrival_us, 200);
  EXPECT_EQ(assembler.pending(), 0u);
}

TEST(PingAssembler, LoneSideGoesOutAfterTheTimeoutWithoutThePartner) {
  PingAssemblerOptions options;
  options.missing_side_timeout_s = 0.5;
  PingAssembler assembler(options);
  std::vector<AssembledPing> out;
  assembler.add(test::makeRecord(7, kChannelPort), 1'000'000, out);
  assembler.expire(1'400'000, out);
  EXPECT_TRUE(out.empty());
  assembler.expire(1'500'000, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].port);
  EXPECT_FALSE(out[0].starboard);
  EXPECT_EQ(assembler.counters().incomplete_pings, 1u);
}

TEST(PingAssembler, InterleavedPingsCompleteIndependentlyAndPendingStaysBounded) {
  PingAssemblerOptions options;
  options.max_pending_pings = 3;
  PingAssembler assembler(options);
  std::vector<AssembledPing> out;
  for (uint32_t p = 0; p < 10; ++p) assembler.add(test::makeRecord(p, kChannelPort), p, out);
  EXPECT_EQ(assembler.pending(), 3u);
  EXPECT_EQ(out.size(), 7u);  // the oldest ones, one side each
  assembler.add(test::makeRecord(8, kChannelStarboard), 20, out);
  ASSERT_EQ(out.size(), 8u);
  EXPECT_TRUE(out.back().complete());
  EXPECT_EQ(out.back().ping_number, 8u);
}

TEST(PingAssembler, OtherSubsystemsAreIgnoredAndDuplicatesCounted) {
  PingAssembler assembler;
  std::vector<AssembledPing> out;
  SonarChannelRecord high = test::makeRecord(1, kChannelPort);
  high.subsystem = kSubsystemSideScanHigh;
  assembler.add(high, 0, out);
  EXPECT_EQ(assembler.pending(), 0u);
  assembler.add(test::makeRecord(2, kChannelPort), 0, out);
  EXPECT_EQ(assembler.counters().other_subsystem, 1u) << "the configured subsystem is there: the other is ignored";
  assembler.add(test::makeRecord(2, kChannelPort), 1, out);
  EXPECT_EQ(assembler.counters().duplicate_channels, 1u);
  assembler.flush(out);
  EXPECT_EQ(out.size(), 1u);
  EXPECT_EQ(assembler.counters().adopted_subsystem, -1);
}

// A sonar recording its high frequency only (subsystem 21) with the default subsystem 20
// configured: after 64 such records and none of 20, subsystem 21 is used, the records held
// meanwhile included; a short file of it is taken at its end. Two other frequencies and not the
// configured one: nothing says which is meant, so none is taken.
TEST(PingAssembler, AFileOfAnotherSideScanFrequencyOnlyIsTakenWhole) {
  auto records = [](uint8_t subsystem, uint32_t pings, std::vector<SonarChannelRecord>& into) {
    for (uint32_t p = 0; p < pings; ++p) {
      for (uint8_t channel : {kChannelPort, kChannelStarboard}) {
        SonarChannelRecord r = test::makeRecord(p, channel);
        r.subsystem = subsystem;
        into.push_back(r);
      }
    }
  };
  for (const uint32_t pings : {50u, 5u}) {
    std::vector<SonarChannelRecord> high;
    records(kSubsystemSideScanHigh, pings, high);
    PingAssembler assembler;
    std::vector<AssembledPing> out;
    for (const auto& r : high) assembler.add(r, 0, out);
    assembler.flush(out);
    ASSERT_EQ(out.size(), pings);
    for (uint32_t p = 0; p < pings; ++p) {
      EXPECT_TRUE(out[p].complete());
      EXPECT_EQ(out[p].ping_number, p);
      EXPECT_EQ(out[p].port->subsystem, kSubsystemSideScanHigh);
    }
    EXPECT_EQ(assembler.counters().adopted_subsystem, kSubsystemSideScanHigh);
    EXPECT_EQ(assembler.counters().other_subsystem, 0u);
  }
  {
    std::vector<SonarChannelRecord> two;
    records(kSubsystemSideScanHigh, 1, two);
    records(kSubsystemSideScanHigh + 1, 40, two);
    PingAssembler assembler;
    std::vector<AssembledPing> out;
    for (const auto& r : two) assembler.add(r, 0, out);
    assembler.flush(out);
    EXPECT_TRUE(out.empty());
    EXPECT_EQ(assembler.counters().adopted_subsystem, -1);
    EXPECT_EQ(assembler.counters().other_subsystem, two.size());
  }
  {
    PingAssemblerOptions never;
    never.adopt_other_side_scan_after = 0;
    PingAssembler assembler(never);
    std::vector<SonarChannelRecord> high;
    records(kSubsystemSideScanHigh, 50, high);
    std::vector<AssembledPing> out;
    for (const auto& r : high) assembler.add(r, 0, out);
    assembler.flush(out);
    EXPECT_TRUE(out.empty());
    EXPECT_EQ(assembler.counters().other_subsystem, high.size());
  }
}

}  // namespace
}  // namespace sss::edgetech
