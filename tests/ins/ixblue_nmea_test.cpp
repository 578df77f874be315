// iXblue NMEA encoding and sentence parsing: exact bytes, sign conventions, field validation.
#include "drivers/ins/ixblue_nmea.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

namespace sss::ins {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Independent of the library: XOR of the body, two upper-case hex digits.
std::string framed(const std::string& body) {
  unsigned checksum = 0;
  for (unsigned char c : body) checksum ^= c;
  char hex[8];
  std::snprintf(hex, sizeof(hex), "%02X", checksum);
  return "$" + body + "*" + hex + "\r\n";
}

InsState knownState() {
  InsState s;
  s.utime_us = 1710506096789012;  // 2024-03-15T12:34:56.789012Z
  s.latitude_deg = 43.12345678;
  s.longitude_deg = -5.87654321;
  s.depth_m = 123.456;
  s.altitude_m = 18.5;
  s.roll_rad = 0.1;      // 5.7296 deg starboard down
  s.pitch_rad = -0.05;   // 2.8648 deg bow down
  s.heading_rad = 4.0;   // 229.1831 deg
  s.velocity_north_m_s = 1.5;
  s.velocity_east_m_s = -0.25;
  s.velocity_down_m_s = 0.1;
  s.latitude_std_m = 2.5;
  s.longitude_std_m = 3.25;
  s.depth_std_m = 0.1;
  s.heading_std_rad = 0.01;
  s.roll_std_rad = 0.001;
  s.pitch_std_rad = 0.002;
  s.velocity_north_std_m_s = 0.01;
  s.velocity_east_std_m_s = 0.02;
  s.velocity_down_std_m_s = 0.03;
  s.validity = kValidAll;
  return s;
}

TEST(IxblueNmea, EncodesKnownStateToExactBytes) {
  const std::string expected =
      framed("HEHDT,229.183,T") + framed("PIXSE,ATITUD,5.730,2.865") +
      framed("PIXSE,POSITI,43.12345678,-5.87654321,-123.456") +
      framed("PIXSE,SPEED_,-0.250,1.500,-0.100") + framed("PIXSE,TIME__,123456.789012") +
      framed("PIXSE,STDHRP,0.573,0.057,0.115") + framed("PIXSE,STDPOS,2.50,3.25,0.10") +
      framed("PIXSE,STDSPD,0.020,0.010,0.030") + framed("SDDPT,18.500,0.000") +
      framed("INZDA,123456.78,15,03,2024,00,00") +
      framed("PIXSE,ALGSTS,00000000,00000000") + framed("PIXSE,STATUS,00000000,00000000");
  EXPECT_EQ(encodeInsState(knownState()), expected);
}

TEST(IxblueNmea, ChecksumMatchesPublishedPhinsExample) {
  // Published PHINS output line (rock-drivers phins_ixsea parser comment).
  EXPECT_EQ(frameSentence("PIXSE,ATITUD,-1.641,-0.490"), "$PIXSE,ATITUD,-1.641,-0.490*6D\r\n");
  EXPECT_EQ(frameSentence("HEHDT,116.581,T"), "$HEHDT,116.581,T*25\r\n");
}

TEST(IxblueNmea, RollStarboardDownEncodesPositiveAndPitchBowUpEncodesNegative) {
  InsState s;
  s.utime_us = 1710506096000000;
  s.roll_rad = 0.1;   // starboard down = port up: iXblue positive
  s.pitch_rad = 0.1;  // bow up: iXblue negative (iXblue pitch is + bow down)
  s.validity = kValidAttitude;
  const std::string text = encodeInsState(s);
  EXPECT_NE(text.find("$PIXSE,ATITUD,5.730,-5.730*"), std::string::npos) << text;

  const SentenceParseResult parsed = parseSentence("PIXSE,ATITUD,5.730,-5.730");
  ASSERT_EQ(parsed.error, SentenceError::kNone);
  const auto& attitude = std::get<AttitudeSentence>(parsed.sentence);
  EXPECT_DOUBLE_EQ(attitude.roll_deg, 5.730);
  EXPECT_DOUBLE_EQ(attitude.pitch_deg, -5.730);
}

TEST(IxblueNmea, HeadingIsWrappedIntoZeroTo360) {
  InsState s;
  s.utime_us = 1710506096000000;
  s.validity = kValidHeading;
  s.heading_rad = -0.5 * kPi;  // west
  EXPECT_NE(encodeInsState(s).find("$HEHDT,270.000,T*"), std::string::npos);
  s.heading_rad = 2.0 * kPi - 1e-7;  // rounds to 360.000, which is 0.000
  EXPECT_NE(encodeInsState(s).find("$HEHDT,0.000,T*"), std::string::npos);
}

TEST(IxblueNmea, ParsesEverySupportedSentence) {
  EXPECT_EQ(parseSentence("HEHDT,116.581,T").error, SentenceError::kNone);
  EXPECT_EQ(parseSentence("PIXSE,POSITI,53.10245714,8.83994382,-0.115").error,
            SentenceError::kNone);
  EXPECT_EQ(parseSentence("PIXSE,SPEED_,-0.802,-1.243,0.000").error, SentenceError::kNone);
  EXPECT_EQ(parseSentence("PIXSE,STDHRP,1.997,0.082,0.101").error, SentenceError::kNone);
  EXPECT_EQ(parseSentence("PIXSE,STDPOS,20563.20,18004.65,50.00").error, SentenceError::kNone);
  EXPECT_EQ(parseSentence("PIXSE,STDSPD,19.747,13.032,10.002").error, SentenceError::kNone);
  EXPECT_EQ(parseSentence("PIXSE,ALGSTS,00000045,00004000").error, SentenceError::kNone);
  EXPECT_EQ(parseSentence("PIXSE,STATUS,00000000,00200000").error, SentenceError::kNone);
  EXPECT_EQ(parseSentence("SDDPT,18.20,0.5,200").error, SentenceError::kNone);
  EXPECT_EQ(parseSentence("GPZDA,201530.00,04,07,2002,00,00").error, SentenceError::kNone);
  EXPECT_TRUE(std::holds_alternative<IgnoredSentence>(
      parseSentence("PIXSE,UTMWGS,U,32,489284.019,5883680.109,-0.115").sentence));

  const auto time = parseSentence("PIXSE,TIME__,003356.016693");
  ASSERT_EQ(time.error, SentenceError::kNone);
  EXPECT_EQ(std::get<TimeSentence>(time.sentence).time_of_day_us,
            (33 * 60 + 56) * 1000000LL + 16693);
  const auto no_lock = parseSentence("SDDPT,,0.0");
  ASSERT_EQ(no_lock.error, SentenceError::kNone);
  EXPECT_FALSE(std::get<DepthBelowTransducerSentence>(no_lock.sentence).has_depth);
}

TEST(IxblueNmea, RejectsBadFieldsWithReason) {
  EXPECT_EQ(parseSentence("PIXSE,POSITI,95.0,8.8,-0.1").error, SentenceError::kOutOfRange);
  EXPECT_EQ(parseSentence("PIXSE,POSITI,,8.8,-0.1").error, SentenceError::kEmptyField);
  EXPECT_EQ(parseSentence("PIXSE,POSITI,4x.0,8.8,-0.1").error, SentenceError::kNotANumber);
  EXPECT_EQ(parseSentence("PIXSE,POSITI,1e1,8.8,-0.1").error, SentenceError::kNotANumber);
  EXPECT_EQ(parseSentence("PIXSE,POSITI,nan,8.8,-0.1").error, SentenceError::kNotANumber);
  EXPECT_EQ(parseSentence("PIXSE,POSITI,45.0,8.8").error, SentenceError::kWrongFieldCount);
  EXPECT_EQ(parseSentence("PIXSE,ATITUD,1.0,91.0").error, SentenceError::kOutOfRange);
  EXPECT_EQ(parseSentence("HEHDT,361.0,T").error, SentenceError::kOutOfRange);
  EXPECT_EQ(parseSentence("HEHDT,10.0,M").error, SentenceError::kOutOfRange);
  EXPECT_EQ(parseSentence("PIXSE,TIME__,246000.0").error, SentenceError::kOutOfRange);
  EXPECT_EQ(parseSentence("PIXSE,TIME__,12:00:00").error, SentenceError::kNotANumber);
  EXPECT_EQ(parseSentence("GPZDA,201530.00,30,02,2024,00,00").error, SentenceError::kOutOfRange);
  EXPECT_EQ(parseSentence("PIXSE,STDPOS,-1.0,1.0,1.0").error, SentenceError::kOutOfRange);
  EXPECT_EQ(parseSentence("PIXSE,ALGSTS,0000004G,0").error, SentenceError::kNotANumber);
  EXPECT_EQ(parseSentence("GPGGA,1,2,3").error, SentenceError::kUnsupported);
  EXPECT_EQ(parseSentence("").error, SentenceError::kUnsupported);

  const auto bad = parseSentence("PIXSE,POSITI,95.0,8.8,-0.1");
  EXPECT_NE(bad.error_text.find("latitude"), std::string::npos) << bad.error_text;
  EXPECT_NE(bad.error_text.find("95.0"), std::string::npos) << bad.error_text;
}

TEST(IxblueNmea, CalendarRoundTripsAcrossLeapYears) {
  EXPECT_EQ(daysFromCivil(1970, 1, 1), 0);
  EXPECT_EQ(daysFromCivil(2024, 3, 15), 1710460800LL / 86400);
  for (int64_t days = -800; days < 150000; days += 37) {
    int y = 0, m = 0, d = 0;
    civilFromDays(days, y, m, d);
    EXPECT_EQ(daysFromCivil(y, m, d), days);
  }
}

}  // namespace
}  // namespace sss::ins
