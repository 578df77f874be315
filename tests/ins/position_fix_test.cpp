// Position fixes from NMEA: GGA + GST + ZDA/RMC, sources by talker, sigma models, dates, bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "drivers/ins/ixblue_nmea.hpp"
#include "drivers/ins/position_fix.hpp"

namespace sss::ins {
namespace {

std::string sentence(const std::string& body) {
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X\r\n", nmeaChecksum(body));
  return "$" + body + tail;
}

std::vector<PositionFix> read(const std::string& text, PositionFixReader& reader) {
  reader.feed(text);
  return reader.finish();
}

constexpr int64_t kJune1st0800 = 1780300800000000;  // 2026-06-01T08:00:00Z

TEST(PositionFix, EncodedFixReadsBackWithItsSigmaAndDate) {
  PositionFix fix;
  fix.utime_us = kJune1st0800 + 1234560000;  // 08:20:34.56
  fix.latitude_deg = -33.123456789;
  fix.longitude_deg = 151.987654321;
  fix.sigma_north_m = 0.8;
  fix.sigma_east_m = 1.1;
  fix.quality = 2;
  fix.satellites = 11;
  fix.hdop = 0.9;
  PositionFixReader reader;
  const std::vector<PositionFix> fixes = read(encodePositionFix(fix), reader);
  ASSERT_EQ(fixes.size(), 1u) << reader.firstProblem();
  EXPECT_TRUE(fixes[0].dated);
  EXPECT_EQ(fixes[0].utime_us, fix.utime_us);
  // 1e-7 minute of arc is 0.2 mm.
  EXPECT_NEAR(fixes[0].latitude_deg, fix.latitude_deg, 2e-9);
  EXPECT_NEAR(fixes[0].longitude_deg, fix.longitude_deg, 2e-9);
  EXPECT_TRUE(fixes[0].sigma_from_gst);
  EXPECT_DOUBLE_EQ(fixes[0].sigma_north_m, 0.8);
  EXPECT_DOUBLE_EQ(fixes[0].sigma_east_m, 1.1);
  EXPECT_EQ(fixes[0].source, FixSource::kGnss);
  EXPECT_EQ(fixes[0].quality, 2);
  EXPECT_EQ(fixes[0].satellites, 11);
  EXPECT_EQ(reader.counters().gst, 1u);
  EXPECT_EQ(reader.counters().date_sentences, 1u);
  EXPECT_EQ(reader.counters().malformed, 0u);
  EXPECT_TRUE(reader.firstProblem().empty());
}

TEST(PositionFix, TalkerSaysGnssOrUsblUnlessTheFileIsNamed) {
  const std::string text = sentence("GNGGA,080000.00,5921.0,N,01804.2,E,1,09,1.0,0.0,M,0.0,M,,") +
                           sentence("U0GGA,080001.00,5921.0,N,01804.2,E,1,00,,0.0,M,0.0,M,,") +
                           sentence("IIGGA,080002.00,5921.0,N,01804.2,E,2,00,,0.0,M,0.0,M,,");
  PositionFixReader by_talker;
  const auto fixes = read(text, by_talker);
  ASSERT_EQ(fixes.size(), 3u);
  EXPECT_EQ(fixes[0].source, FixSource::kGnss);
  EXPECT_EQ(fixes[1].source, FixSource::kUsbl);
  EXPECT_EQ(fixes[2].source, FixSource::kUsbl);
  // No GST: GNSS from HDOP x the quality's error, USBL the configured sigma.
  const FixReaderOptions defaults;
  EXPECT_DOUBLE_EQ(fixes[0].sigma_north_m, 1.0 * defaults.gnss_sigma_per_hdop_m);
  EXPECT_DOUBLE_EQ(fixes[1].sigma_east_m, defaults.usbl_default_sigma_m);
  EXPECT_FALSE(fixes[0].dated);

  PositionFixReader forced(FixReaderOptions{}, FixSource::kUsbl);
  for (const PositionFix& f : read(text, forced)) EXPECT_EQ(f.source, FixSource::kUsbl);
}

TEST(PositionFix, HdopModelFollowsFixQuality) {
  const std::string text = sentence("GPGGA,080000.00,5921.0,N,01804.2,E,2,09,1.2,0.0,M,0.0,M,,") +
                           sentence("GPGGA,080001.00,5921.0,N,01804.2,E,4,09,0.8,0.0,M,0.0,M,,") +
                           sentence("GPGGA,080002.00,5921.0,N,01804.2,E,1,09,,0.0,M,0.0,M,,");
  PositionFixReader reader;
  const auto fixes = read(text, reader);
  ASSERT_EQ(fixes.size(), 3u);
  const FixReaderOptions o;
  EXPECT_DOUBLE_EQ(fixes[0].sigma_north_m, 1.2 * o.dgnss_sigma_per_hdop_m);
  EXPECT_DOUBLE_EQ(fixes[1].sigma_north_m, 0.8 * o.rtk_fixed_sigma_per_hdop_m);
  EXPECT_DOUBLE_EQ(fixes[2].sigma_north_m, o.missing_hdop * o.gnss_sigma_per_hdop_m);
}

TEST(PositionFix, NoFixAndBadSentencesAreCountedAndNamed) {
  const std::string text = sentence("GPGGA,080000.00,5921.0,N,01804.2,E,0,00,,0.0,M,0.0,M,,") +   // no fix
                           sentence("GPGGA,080001.00,5921.0,N,01804.2,E,6,04,2.0,0.0,M,0.0,M,,") +  // DR
                           sentence("GPGGA,080002.00,5975.0,N,01804.2,E,1,09,1.0,0.0,M,0.0,M,,") +  // 75 minutes
                           "$GPGGA,080003.00,5921.0,N,01804.2,E,1,09,1.0,0.0,M,0.0,M,,*00\r\n" +   // checksum
                           sentence("GPGST,080004.00,1.0,1.0,1.0,0.0,-1.0,1.0,1.0") +                 // sigma < 0
                           sentence("GPZDA,080005.00,31,04,2026,00,00") +                             // 31 April
                           sentence("GPHDT,123.4,T") +
                           sentence("GPGGA,080006.00,5921.0,N,01804.2,E,1,09,1.0,0.0,M,0.0,M,,");
  PositionFixReader reader;
  const auto fixes = read(text, reader);
  ASSERT_EQ(fixes.size(), 1u);
  EXPECT_DOUBLE_EQ(fixes[0].seconds_of_day, 8 * 3600.0 + 6.0);
  const FixReaderCounters& c = reader.counters();
  EXPECT_EQ(c.no_fix, 2u);
  EXPECT_EQ(c.malformed, 3u);
  EXPECT_EQ(c.rejected_sentences, 1u);
  EXPECT_EQ(c.other_sentences, 1u);
  EXPECT_EQ(c.date_sentences, 0u);
  EXPECT_NE(reader.firstProblem().find("malformed GGA"), std::string::npos) << reader.firstProblem();
}

TEST(PositionFix, DatesFromZdaAndRmcRollOverMidnight) {
  const std::string text = sentence("GPRMC,235958.00,A,5921.0,N,01804.2,E,0.0,0.0,311226,,") +
                           sentence("GPGGA,235959.00,5921.0,N,01804.2,E,1,09,1.0,0.0,M,0.0,M,,") +
                           sentence("GPGGA,000001.00,5921.0,N,01804.2,E,1,09,1.0,0.0,M,0.0,M,,");
  PositionFixReader reader;
  const auto fixes = read(text, reader);
  ASSERT_EQ(fixes.size(), 2u);
  const int64_t new_year_2027_us = 1798761600000000;  // 2027-01-01T00:00:00Z
  EXPECT_EQ(fixes[0].utime_us, new_year_2027_us - 1000000);
  EXPECT_EQ(fixes[1].utime_us, new_year_2027_us + 1000000);
}

TEST(PositionFix, UndatedFixesTakeTheMissionsDay) {
  std::vector<PositionFix> fixes(3);
  fixes[0].seconds_of_day = 23 * 3600.0 + 59 * 60.0;  // 23:59, mission started 23:50 on day D
  fixes[1].seconds_of_day = 30.0;                      // 00:00:30 of D + 1
  fixes[2].seconds_of_day = 60.0;
  const int64_t day_s = 20605;  // 2026-06-01 in days
  const int64_t reference_us = (day_s * 86400 + 23 * 3600 + 50 * 60) * 1000000;
  resolveFixDates(fixes, reference_us);
  EXPECT_EQ(fixes[0].utime_us, (day_s * 86400 + 23 * 3600 + 59 * 60) * 1000000);
  EXPECT_EQ(fixes[1].utime_us, ((day_s + 1) * 86400 + 30) * 1000000);
  EXPECT_EQ(fixes[2].utime_us, ((day_s + 1) * 86400 + 60) * 1000000);
  // A fix just after midnight with a mission reference just before it: the next day, not 24 h back.
  std::vector<PositionFix> early(1);
  early[0].seconds_of_day = 10.0;
  resolveFixDates(early, reference_us);
  EXPECT_EQ(early[0].utime_us, ((day_s + 1) * 86400 + 10) * 1000000);
}

TEST(PositionFix, ByteByByteGivesTheSameFixes) {
  PositionFix fix;
  fix.utime_us = kJune1st0800;
  fix.latitude_deg = 59.35;
  fix.longitude_deg = 18.07;
  fix.sigma_north_m = fix.sigma_east_m = 0.5;
  fix.quality = 1;
  fix.hdop = 1.0;
  std::string text;
  for (int i = 0; i < 5; ++i) {
    fix.utime_us += 1000000;
    text += encodePositionFix(fix, i % 2 ? "GP" : "U1");
  }
  PositionFixReader whole;
  const auto expected = read(text, whole);
  ASSERT_EQ(expected.size(), 5u);
  PositionFixReader bytes;
  for (char c : text) bytes.feed(std::string_view(&c, 1));
  const auto got = bytes.finish();
  ASSERT_EQ(got.size(), expected.size());
  for (size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].utime_us, expected[i].utime_us);
    EXPECT_EQ(got[i].source, expected[i].source);
    EXPECT_EQ(got[i].latitude_deg, expected[i].latitude_deg);
  }
  EXPECT_EQ(got[0].source, FixSource::kUsbl);
  EXPECT_EQ(got[1].source, FixSource::kGnss);
}

TEST(PositionFix, MissingFileNamesThePathAndTheForm) {
  const sss::core::Result<FixFileContents> read = readPositionFixFile("usbl:/nonexistent/fixes.nmea", FixReaderOptions{});
  EXPECT_FALSE(read.ok());
  const std::string& error = read.message();
  EXPECT_NE(error.find("/nonexistent/fixes.nmea"), std::string::npos) << error;
  EXPECT_NE(error.find("usbl:PATH"), std::string::npos) << error;
}

}  // namespace
}  // namespace sss::ins
