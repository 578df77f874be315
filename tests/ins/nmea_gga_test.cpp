// GGA sentences: the textbook example, hemispheres, checksums, no fix, other sentences.
#include "drivers/ins/nmea_gga.hpp"

#include <gtest/gtest.h>

namespace sss::ins {
namespace {

TEST(NmeaGga, ParsesTheTextbookFix) {
  const auto fix = parseGga("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n");
  ASSERT_TRUE(fix);
  EXPECT_DOUBLE_EQ(fix->seconds_of_day, 12 * 3600 + 35 * 60 + 19);
  EXPECT_NEAR(fix->latitude_deg, 48.0 + 7.038 / 60.0, 1e-12);
  EXPECT_NEAR(fix->longitude_deg, 11.0 + 31.0 / 60.0, 1e-12);
  EXPECT_EQ(fix->quality, 1);
  EXPECT_EQ(fix->satellites, 8);
  EXPECT_DOUBLE_EQ(fix->hdop, 0.9);
  EXPECT_DOUBLE_EQ(fix->altitude_m, 545.4);
}

TEST(NmeaGga, SouthAndWestAreNegativeAndAnyTalkerWorks) {
  const auto fix = parseGga("GNGGA,000001.50,3352.1234,S,15112.5000,W,4,12,0.6,3.1,M,,M,,");  // no checksum
  ASSERT_TRUE(fix);
  EXPECT_NEAR(fix->seconds_of_day, 1.5, 1e-9);
  EXPECT_NEAR(fix->latitude_deg, -(33.0 + 52.1234 / 60.0), 1e-12);
  EXPECT_NEAR(fix->longitude_deg, -(151.0 + 12.5 / 60.0), 1e-12);
  EXPECT_EQ(fix->quality, 4);
}

TEST(NmeaGga, RefusesBadChecksumsNoFixOtherSentencesAndGarbage) {
  EXPECT_FALSE(parseGga("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*48"));
  EXPECT_FALSE(parseGga("$GPGGA,123519,4807.038,N,01131.000,E,0,00,,,M,,M,,"));  // quality 0: no fix
  EXPECT_FALSE(parseGga("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A"));
  EXPECT_FALSE(parseGga("$GPGGA,123519,4807.038,X,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"));
  EXPECT_FALSE(parseGga("$GPGGA,123519,4865.000,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"));  // 65 minutes
  EXPECT_FALSE(parseGga("$GPGGA,,,,,,1"));
  EXPECT_FALSE(parseGga(""));
  EXPECT_FALSE(parseGga("\x01\x02GGA,,,"));
}

// A sonar file's NMEA feed with RMC or GLL only: the textbook sentences give their positions, GGA
// as before; status V (void), other sentences and bad checksums give none.
TEST(NmeaPosition, RmcAndGllGivePositionsLikeGga) {
  struct Case {
    const char* sentence;
    double seconds_of_day, latitude_deg, longitude_deg;
  };
  for (const Case& c : {Case{"$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A\r\n",
                             45319.0, 48.0 + 7.038 / 60.0, 11.0 + 31.0 / 60.0},
                        Case{"$GPGLL,4916.45,N,12311.12,W,225444,A,*1D", 82484.0, 49.0 + 16.45 / 60.0,
                             -(123.0 + 11.12 / 60.0)},
                        Case{"$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47", 45319.0,
                             48.0 + 7.038 / 60.0, 11.0 + 31.0 / 60.0}}) {
    const auto fix = parseNmeaPosition(c.sentence);
    ASSERT_TRUE(fix) << c.sentence;
    EXPECT_DOUBLE_EQ(fix->seconds_of_day, c.seconds_of_day) << c.sentence;
    EXPECT_NEAR(fix->latitude_deg, c.latitude_deg, 1e-12) << c.sentence;
    EXPECT_NEAR(fix->longitude_deg, c.longitude_deg, 1e-12) << c.sentence;
    EXPECT_EQ(fix->quality, 1) << c.sentence;
  }
  EXPECT_FALSE(parseNmeaPosition("GPRMC,123519,V,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W"));
  EXPECT_FALSE(parseNmeaPosition("GPGLL,4916.45,N,12311.12,W,225444,V"));
  EXPECT_FALSE(parseNmeaPosition("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6B"));
  EXPECT_FALSE(parseNmeaPosition("$GPVTG,054.7,T,034.4,M,005.5,N,010.2,K"));
  EXPECT_FALSE(parseNmeaPosition("GPRMC,1235,A"));
  EXPECT_FALSE(parseNmeaPosition(""));
}

}  // namespace
}  // namespace sss::ins
