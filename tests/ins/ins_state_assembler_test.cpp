// InsStateAssembler: epochs from bursts, round trip through the encoder, staleness and recovery.
#include "drivers/ins/ins_state_assembler.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "drivers/ins/ixblue_nmea.hpp"
#include "drivers/ins/nmea_stream_parser.hpp"

namespace sss::ins {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;
constexpr int64_t kStartUtime = 1710506096789012;  // 2024-03-15T12:34:56.789012Z

InsState fullState(int64_t utime_us) {
  InsState s;
  s.utime_us = utime_us;
  s.latitude_deg = -33.87654321;
  s.longitude_deg = 151.12345678;
  s.depth_m = 512.3456;
  s.altitude_m = 17.25;
  s.roll_rad = 0.1;
  s.pitch_rad = -0.2;
  s.heading_rad = 5.5;
  s.velocity_north_m_s = 1.234;
  s.velocity_east_m_s = -0.567;
  s.velocity_down_m_s = 0.089;
  s.latitude_std_m = 1.5;
  s.longitude_std_m = 2.25;
  s.depth_std_m = 0.05;
  s.roll_std_rad = 0.0002;
  s.pitch_std_rad = 0.0003;
  s.heading_std_rad = 0.001;
  s.velocity_north_std_m_s = 0.011;
  s.velocity_east_std_m_s = 0.012;
  s.velocity_down_std_m_s = 0.013;
  s.validity = kValidAll;
  return s;
}

// Bytes -> stream parser -> assembler, as the bridge does it.
std::vector<InsState> decode(const std::string& bytes, InsStateAssembler& assembler) {
  NmeaStreamParser parser;
  std::vector<InsState> states;
  for (const std::string& sentence : parser.feed(bytes)) {
    for (const InsState& state : assembler.addSentence(sentence)) states.push_back(state);
  }
  EXPECT_EQ(parser.rejectedSentences(), 0);
  return states;
}

TEST(InsStateAssembler, RoundTripsStateWithinEncodingResolution) {
  const InsState in = fullState(kStartUtime);
  InsStateAssembler assembler;
  const auto states = decode(encodeInsState(in), assembler);
  ASSERT_EQ(states.size(), 1u);
  const InsState& out = states[0];

  // Tolerances are half the last printed digit of each field.
  constexpr double kLatLonTolDeg = 0.5e-8;     // 8 decimals
  constexpr double kAngleTolRad = 0.5e-3 * kDegToRad;  // 3 decimals of a degree
  constexpr double kMetreTol = 0.5e-3;         // 1 mm
  constexpr double kSpeedTol = 0.5e-3;         // 1 mm/s
  constexpr double kPositionStdTol = 0.5e-2;   // 1 cm
  EXPECT_EQ(out.utime_us, in.utime_us);        // TIME__ carries microseconds
  EXPECT_NEAR(out.latitude_deg, in.latitude_deg, kLatLonTolDeg);
  EXPECT_NEAR(out.longitude_deg, in.longitude_deg, kLatLonTolDeg);
  EXPECT_NEAR(out.depth_m, in.depth_m, kMetreTol);
  EXPECT_NEAR(out.altitude_m, in.altitude_m, kMetreTol);
  EXPECT_NEAR(out.roll_rad, in.roll_rad, kAngleTolRad);
  EXPECT_NEAR(out.pitch_rad, in.pitch_rad, kAngleTolRad);
  EXPECT_NEAR(out.heading_rad, in.heading_rad, kAngleTolRad);
  EXPECT_NEAR(out.velocity_north_m_s, in.velocity_north_m_s, kSpeedTol);
  EXPECT_NEAR(out.velocity_east_m_s, in.velocity_east_m_s, kSpeedTol);
  EXPECT_NEAR(out.velocity_down_m_s, in.velocity_down_m_s, kSpeedTol);
  EXPECT_NEAR(out.latitude_std_m, in.latitude_std_m, kPositionStdTol);
  EXPECT_NEAR(out.longitude_std_m, in.longitude_std_m, kPositionStdTol);
  EXPECT_NEAR(out.depth_std_m, in.depth_std_m, kPositionStdTol);
  EXPECT_NEAR(out.roll_std_rad, in.roll_std_rad, kAngleTolRad);
  EXPECT_NEAR(out.pitch_std_rad, in.pitch_std_rad, kAngleTolRad);
  EXPECT_NEAR(out.heading_std_rad, in.heading_std_rad, kAngleTolRad);
  EXPECT_NEAR(out.velocity_north_std_m_s, in.velocity_north_std_m_s, kSpeedTol);
  EXPECT_NEAR(out.velocity_east_std_m_s, in.velocity_east_std_m_s, kSpeedTol);
  EXPECT_NEAR(out.velocity_down_std_m_s, in.velocity_down_std_m_s, kSpeedTol);
  // Not carried by NMEA: the configured DVL figure.
  EXPECT_DOUBLE_EQ(out.altitude_std_m, InsAssemblerOptions{}.altitude_std_m);
  EXPECT_EQ(out.validity, kValidAll);
  EXPECT_EQ(assembler.counters().epochs, 1);
  EXPECT_EQ(assembler.counters().epochs_without_terminator, 0);
}

TEST(InsStateAssembler, RollStarboardDownDecodesBackWithSign) {
  InsState in = fullState(kStartUtime);
  in.roll_rad = 0.1;    // starboard down
  in.pitch_rad = 0.05;  // bow up
  InsStateAssembler assembler;
  const auto states = decode(encodeInsState(in), assembler);
  ASSERT_EQ(states.size(), 1u);
  EXPECT_NEAR(states[0].roll_rad, 0.1, 1e-5);
  EXPECT_NEAR(states[0].pitch_rad, 0.05, 1e-5);

  // A hand-written iXblue line: port up 2 deg, bow down 3 deg.
  InsStateAssembler by_hand;
  decode(encodeInsState(fullState(kStartUtime)), by_hand);  // provides the date
  const auto hand = decode(frameSentence("PIXSE,ATITUD,2.000,3.000") +
                               frameSentence("PIXSE,TIME__,123500.000000") +
                               frameSentence("PIXSE,STATUS,00000000,00000000"),
                           by_hand);
  ASSERT_EQ(hand.size(), 1u);
  EXPECT_NEAR(hand[0].roll_rad, 2.0 * kDegToRad, 1e-12);    // starboard down in FRD
  EXPECT_NEAR(hand[0].pitch_rad, -3.0 * kDegToRad, 1e-12);  // bow down is negative in FRD
}

TEST(InsStateAssembler, GarbageAndByteByByteChunkingGiveIdenticalStates) {
  std::string clean, dirty;
  for (int i = 0; i < 5; ++i) {
    const std::string burst = encodeInsState(fullState(kStartUtime + i * 200000));
    clean += burst;
    dirty += std::string("\x00\xff garbage $junk*ZZ\r\n", 21) + burst;
  }
  InsStateAssembler clean_assembler;
  const auto expected = decode(clean, clean_assembler);
  ASSERT_EQ(expected.size(), 5u);

  NmeaStreamParser parser;
  InsStateAssembler assembler;
  std::vector<InsState> states;
  for (char c : dirty) {
    std::vector<std::string> sentences;
    const auto byte = static_cast<uint8_t>(c);
    parser.feed(&byte, 1, sentences);
    for (const auto& sentence : sentences) {
      for (const auto& state : assembler.addSentence(sentence)) states.push_back(state);
    }
  }
  ASSERT_EQ(states.size(), expected.size());
  for (size_t i = 0; i < states.size(); ++i) {
    EXPECT_EQ(states[i].utime_us, expected[i].utime_us);
    EXPECT_EQ(states[i].latitude_deg, expected[i].latitude_deg);
    EXPECT_EQ(states[i].heading_rad, expected[i].heading_rad);
    EXPECT_EQ(states[i].validity, expected[i].validity);
  }
  EXPECT_EQ(parser.counters().bad_checksum, 5);
}

TEST(InsStateAssembler, FlagsStaleHeadingAfterTimeoutAndRecovers) {
  InsStateAssembler assembler;  // heading timeout 1 s
  constexpr int64_t kPeriodUs = 200000;  // 5 Hz output
  int64_t t = kStartUtime;
  ASSERT_EQ(decode(encodeInsState(fullState(t)), assembler).size(), 1u);

  // Heading drops out: not stale until more than 1 s has passed since the last heading.
  InsState no_heading = fullState(t);
  no_heading.validity = kValidAll & ~kValidHeading;
  for (int i = 1; i <= 5; ++i) {
    no_heading.utime_us = t + i * kPeriodUs;
    const auto states = decode(encodeInsState(no_heading), assembler);
    ASSERT_EQ(states.size(), 1u);
    EXPECT_FALSE(states[0].validity & kValidHeading);
    EXPECT_FALSE(states[0].validity & kStaleHeading) << "at " << i * 0.2 << " s";
    EXPECT_NEAR(states[0].heading_rad, 5.5, 1e-4);  // held
  }
  no_heading.utime_us = t + 6 * kPeriodUs;
  auto states = decode(encodeInsState(no_heading), assembler);
  ASSERT_EQ(states.size(), 1u);
  EXPECT_TRUE(states[0].validity & kStaleHeading);
  EXPECT_FALSE(states[0].validity & kStalePosition);
  EXPECT_TRUE(states[0].validity & kValidPosition);

  // Heading returns: stale clears at once.
  states = decode(encodeInsState(fullState(t + 7 * kPeriodUs)), assembler);
  ASSERT_EQ(states.size(), 1u);
  EXPECT_EQ(states[0].validity & kStaleAll, 0u);
  EXPECT_TRUE(states[0].validity & kValidHeading);
}

TEST(InsStateAssembler, FlagsStalePositionAndAltitudeWithConfiguredTimeouts) {
  InsAssemblerOptions options;
  options.position_timeout_s = 5.0;
  options.altitude_timeout_s = 2.0;
  InsStateAssembler assembler(options);
  int64_t t = kStartUtime;
  decode(encodeInsState(fullState(t)), assembler);

  InsState partial = fullState(t);
  partial.validity = kValidHeading | kValidAttitude | kValidVelocity;
  partial.utime_us = t + 2100000;
  auto states = decode(encodeInsState(partial), assembler);
  ASSERT_EQ(states.size(), 1u);
  EXPECT_TRUE(states[0].validity & kStaleAltitude);
  EXPECT_DOUBLE_EQ(states[0].altitude_m, -1.0);  // a stale altitude is unknown
  EXPECT_FALSE(states[0].validity & kStalePosition);

  partial.utime_us = t + 5100000;
  states = decode(encodeInsState(partial), assembler);
  ASSERT_EQ(states.size(), 1u);
  EXPECT_TRUE(states[0].validity & kStalePosition);
  EXPECT_TRUE(states[0].validity & kStaleDepth);

  states = decode(encodeInsState(fullState(t + 5300000)), assembler);
  ASSERT_EQ(states.size(), 1u);
  EXPECT_EQ(states[0].validity & kStaleAll, 0u);
  EXPECT_NEAR(states[0].altitude_m, 17.25, 1e-3);
}

TEST(InsStateAssembler, StaleFlagsWhenInsGoesSilent) {
  InsStateAssembler assembler;
  EXPECT_EQ(assembler.staleFlags(kStartUtime), kStaleAll);  // nothing received yet
  decode(encodeInsState(fullState(kStartUtime)), assembler);
  EXPECT_EQ(assembler.staleFlags(kStartUtime + 500000), 0u);
  EXPECT_EQ(assembler.staleFlags(kStartUtime + 1500000), kStaleHeading | kStaleAttitude);
  EXPECT_EQ(assembler.staleFlags(kStartUtime + 6000000), kStaleAll);
}

TEST(InsStateAssembler, ClosesEpochOnRepeatedSentenceWhenStatusIsMissing) {
  InsStateAssembler assembler;
  decode(encodeInsState(fullState(kStartUtime)), assembler);  // date from ZDA
  const std::string burst1 = frameSentence("HEHDT,10.000,T") +
                             frameSentence("PIXSE,TIME__,123457.000000");
  const std::string burst2 = frameSentence("HEHDT,20.000,T") +
                             frameSentence("PIXSE,TIME__,123457.200000");
  auto states = decode(burst1 + burst2, assembler);
  ASSERT_EQ(states.size(), 1u);
  EXPECT_NEAR(states[0].heading_rad, 10.0 * kDegToRad, 1e-12);
  EXPECT_EQ(states[0].utime_us, 1710506097000000);
  const auto last = assembler.flush();
  ASSERT_TRUE(last.has_value());
  EXPECT_NEAR(last->heading_rad, 20.0 * kDegToRad, 1e-12);
  EXPECT_EQ(assembler.counters().epochs_without_terminator, 1);
}

TEST(InsStateAssembler, DropsEpochsUntilDateKnownAndCarriesDateOverMidnight) {
  InsStateAssembler assembler;
  auto states = decode(frameSentence("HEHDT,10.000,T") +
                           frameSentence("PIXSE,TIME__,235959.800000") +
                           frameSentence("PIXSE,STATUS,00000000,00000000"),
                       assembler);
  EXPECT_TRUE(states.empty());
  EXPECT_EQ(assembler.counters().epochs_without_date, 1);

  states = decode(frameSentence("PIXSE,TIME__,235959.900000") +
                      frameSentence("GPZDA,235959.90,31,12,2024,00,00") +
                      frameSentence("PIXSE,STATUS,00000000,00000000") +
                      frameSentence("PIXSE,TIME__,000000.100000") +
                      frameSentence("PIXSE,STATUS,00000000,00000000"),
                  assembler);
  ASSERT_EQ(states.size(), 2u);
  EXPECT_EQ(states[0].utime_us, 1735689599900000);  // 2024-12-31T23:59:59.9Z
  EXPECT_EQ(states[1].utime_us, 1735689600100000);  // 2025-01-01T00:00:00.1Z
}

TEST(InsStateAssembler, CountsRejectedSentencesByReasonAndKeepsFirstText) {
  InsStateAssembler assembler;
  assembler.addSentence("PIXSE,POSITI,95.0,8.8,-0.1");
  assembler.addSentence("PIXSE,POSITI,96.0,8.8,-0.1");
  assembler.addSentence("PIXSE,ATITUD,,1.0");
  assembler.addSentence("GPGSV,1,1,00");
  const auto& counters = assembler.counters();
  EXPECT_EQ(counters.rejected[static_cast<size_t>(SentenceError::kOutOfRange)], 2);
  EXPECT_EQ(counters.rejected[static_cast<size_t>(SentenceError::kEmptyField)], 1);
  EXPECT_EQ(counters.rejected[static_cast<size_t>(SentenceError::kUnsupported)], 1);
  EXPECT_NE(assembler.firstError(SentenceError::kOutOfRange).find("95.0"), std::string::npos);
}

TEST(InsStateAssembler, ValidatesOptions) {
  EXPECT_TRUE(validateOptions(InsAssemblerOptions{}).empty());
  InsAssemblerOptions bad;
  bad.heading_timeout_s = -1.0;
  EXPECT_NE(validateOptions(bad).find("heading_timeout_s"), std::string::npos);
}

}  // namespace
}  // namespace sss::ins
