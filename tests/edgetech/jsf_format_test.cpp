// JSF type 80 encoding at exact byte offsets, decoding, and bad bodies.
#include "drivers/edgetech/jsf_format.hpp"

#include <gtest/gtest.h>

#include <cstring>

#include "jsf_test_data.hpp"
#include "tests/support/status_assertions.hpp"

namespace sss::edgetech {
namespace {

template <typename T>
T at(const std::vector<uint8_t>& bytes, size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));  // the test host is little-endian x86-64
  return value;
}

TEST(JsfFormat, EncodesHeaderAndSonarFieldsAtTheirByteOffsets) {
  SonarChannelRecord record = test::makeRecord(1234, kChannelStarboard);
  record.weighting_factor = 3;
  const std::vector<uint16_t> codes = {0, 1, 65535, 4096};
  const std::vector<uint8_t> bytes = encodeSonarData(record, codes, 9);
  ASSERT_EQ(bytes.size(), 16u + 240u + 8u);
  // 16-byte message header.
  EXPECT_EQ(at<uint16_t>(bytes, 0), 0x1601);
  EXPECT_EQ(bytes[2], 0x0D);
  EXPECT_EQ(at<uint16_t>(bytes, 4), 80);
  EXPECT_EQ(bytes[6], 2);
  EXPECT_EQ(bytes[7], 20);
  EXPECT_EQ(bytes[8], 1);
  EXPECT_EQ(bytes[9], 9);
  EXPECT_EQ(at<int32_t>(bytes, 12), 248);
  // 240-byte sonar data header, offsets from the body start (16).
  const size_t b = 16;
  EXPECT_EQ(at<int32_t>(bytes, b + 0), 1780300800 + 308);  // 2026-06-01T08:05:08 (1234 pings x 0.25 s)
  EXPECT_EQ(at<uint32_t>(bytes, b + 8), 1234u);
  EXPECT_EQ(at<int16_t>(bytes, b + 28), 1);
  EXPECT_EQ(at<int16_t>(bytes, b + 34), 0);
  EXPECT_EQ(at<int32_t>(bytes, b + 80), static_cast<int32_t>(std::lround(18.071234 * 600000)));
  EXPECT_EQ(at<int32_t>(bytes, b + 84), static_cast<int32_t>(std::lround(59.351234 * 600000)));
  EXPECT_EQ(at<int16_t>(bytes, b + 88), 2);
  EXPECT_EQ(at<uint16_t>(bytes, b + 114), 4);
  EXPECT_EQ(at<uint32_t>(bytes, b + 116), 20000u);
  EXPECT_EQ(at<uint16_t>(bytes, b + 126), 39000);
  EXPECT_EQ(at<uint16_t>(bytes, b + 128), 42000);
  EXPECT_EQ(at<int32_t>(bytes, b + 136), 42125);
  EXPECT_EQ(at<int32_t>(bytes, b + 144), 18250);
  EXPECT_FLOAT_EQ(at<float>(bytes, b + 148), 1500.0f);
  EXPECT_EQ(at<int16_t>(bytes, b + 156), 2026);
  EXPECT_EQ(at<int16_t>(bytes, b + 158), 152);  // 1 June = day 152
  EXPECT_EQ(at<int16_t>(bytes, b + 160), 8);
  EXPECT_EQ(at<int16_t>(bytes, b + 162), 5);
  EXPECT_EQ(at<int16_t>(bytes, b + 164), 8);
  EXPECT_EQ(at<int16_t>(bytes, b + 168), 3);
  EXPECT_EQ(at<uint16_t>(bytes, b + 172), 7073);  // 1.2345 rad = 70.73 deg
  EXPECT_EQ(at<int16_t>(bytes, b + 174), static_cast<int16_t>(std::lround(0.02 * 180 / M_PI / (180.0 / 32768))));
  EXPECT_EQ(at<uint32_t>(bytes, b + 200), (8u * 3600 + 5 * 60 + 8) * 1000 + 623);  // .123 + 0.5 s
  EXPECT_EQ(at<uint16_t>(bytes, b + 240 + 4), 65535);
}

TEST(JsfFormat, DecodeGivesBackTheRecordWithinTheWireResolution) {
  const SonarChannelRecord sent = test::makeRecord(77, kChannelPort);
  const std::vector<uint8_t> bytes = test::encodeRecord(sent, 1000);
  const auto header = decodeHeader(bytes.data());
  ASSERT_TRUE(header);
  const sss::core::Result<SonarChannelRecord> result = decodeSonarData(*header, bytes.data() + 16, bytes.size() - 16);
  ASSERT_OK(result);
  const SonarChannelRecord& r = *result;
  EXPECT_EQ(r.ping_number, 77u);
  EXPECT_EQ(r.channel, kChannelPort);
  EXPECT_EQ(r.ping_time_us, sent.ping_time_us);  // whole milliseconds survive
  EXPECT_NEAR(r.latitude_deg, sent.latitude_deg, 1.0 / 600000);  // 0.0001 minute of arc
  EXPECT_NEAR(r.longitude_deg, sent.longitude_deg, 1.0 / 600000);
  EXPECT_NEAR(r.depth_m, sent.depth_m, 1e-3);
  EXPECT_NEAR(r.altitude_m, sent.altitude_m, 1e-3);
  EXPECT_NEAR(r.heading_rad, sent.heading_rad, 0.005 * M_PI / 180);
  EXPECT_NEAR(r.pitch_rad, sent.pitch_rad, 180.0 / 32768 * M_PI / 180);
  EXPECT_NEAR(r.roll_rad, sent.roll_rad, 180.0 / 32768 * M_PI / 180);
  EXPECT_DOUBLE_EQ(r.sample_interval_s, 20e-6);
  ASSERT_EQ(r.samples.size(), 1000u);
  const std::vector<float> magnitudes = test::makeMagnitudes(1000, 77);
  // 16-bit quantisation of values up to 150 with N chosen to fill the range: error <= 2^-N / 2.
  for (size_t i = 0; i < magnitudes.size(); ++i) EXPECT_NEAR(r.samples[i], magnitudes[i], 150.0 / 65535.0);
  EXPECT_NEAR(r.slantRangeM(100), 100 * 20e-6 * 750.0, 1e-9);
}

// Before protocol 8, bytes 0-3 of a sonar data message held a trace sequence number (always 0),
// and the ping time was the calendar at 156-164 (year, day of the year, hour, minute, second) plus
// the milliseconds of byte 200. Such a record gets the same time as with the epoch seconds; the
// course over ground (whole degrees, signed, byte 192) comes back too.
TEST(JsfFormat, RecordsBeforeProtocolEightTakeTheCalendarTime) {
  SonarChannelRecord sent = test::makeRecord(12, kChannelPort);
  sent.ping_time_us = 1780387199987000LL;  // 2026-06-02T07:59:59.987Z: day 153
  sent.course_rad = 271.0 * M_PI / 180.0;
  std::vector<uint8_t> bytes = test::encodeRecord(sent, 10);
  const int32_t trace_sequence = 0;
  std::memcpy(bytes.data() + 16, &trace_sequence, 4);
  const auto header = decodeHeader(bytes.data());
  ASSERT_TRUE(header);
  const sss::core::Result<SonarChannelRecord> result = decodeSonarData(*header, bytes.data() + 16, bytes.size() - 16);
  ASSERT_OK(result);
  EXPECT_EQ(result->ping_time_us, sent.ping_time_us);
  EXPECT_NEAR(result->course_rad, sent.course_rad, 1e-12);
}

// Coordinate units 1 (mm), 3 (dm) and 4 (cm) at byte 88: projected X (east) / Y (north), kept in
// metres with no latitude/longitude; unknown units give no position.
TEST(JsfFormat, ProjectedCoordinateUnitsGiveEastingAndNorthing) {
  for (const auto& [units, metres_per_unit] : {std::pair{int16_t(1), 1e-3}, std::pair{int16_t(3), 0.1},
                                               std::pair{int16_t(4), 0.01}, std::pair{int16_t(7), 0.0}}) {
    std::vector<uint8_t> bytes = test::encodeRecord(test::makeRecord(5, kChannelPort), 10);
    const int32_t x = 65012345, y = 658045678;
    std::memcpy(bytes.data() + 16 + 80, &x, 4);
    std::memcpy(bytes.data() + 16 + 84, &y, 4);
    std::memcpy(bytes.data() + 16 + 88, &units, 2);
    const auto header = decodeHeader(bytes.data());
    ASSERT_TRUE(header);
    const sss::core::Result<SonarChannelRecord> result = decodeSonarData(*header, bytes.data() + 16, bytes.size() - 16);
    ASSERT_OK(result);
    EXPECT_EQ(result->validity & kValidLatLon, 0) << units;
    EXPECT_EQ(result->projected_position, metres_per_unit > 0.0) << units;
    if (metres_per_unit > 0.0) {
      EXPECT_DOUBLE_EQ(result->easting_m, x * metres_per_unit);
      EXPECT_DOUBLE_EQ(result->northing_m, y * metres_per_unit);
    }
  }
}

TEST(JsfFormat, QuantiseChoosesTheWeightingThatFillsSixteenBits) {
  int16_t n = 0;
  const std::vector<uint16_t> codes = quantiseEnvelope({0.0f, 1.0f, 2.0f}, n);
  EXPECT_EQ(n, 14);  // 2 * 2^14 = 32768 <= 65535 < 2 * 2^15
  EXPECT_EQ(codes[2], 32768);
  const std::vector<uint16_t> loud = quantiseEnvelope({1e6f, -5.0f, NAN}, n);
  EXPECT_EQ(n, -4);
  EXPECT_EQ(loud[0], 62500);
  EXPECT_EQ(loud[1], 0);  // negatives and NaN become silence, not garbage
  EXPECT_EQ(loud[2], 0);
}

TEST(JsfFormat, DecodesAnalyticIqAsMagnitude) {
  std::vector<uint8_t> bytes = test::encodeRecord(test::makeRecord(1, kChannelPort), 2);
  // Rewrite as I/Q: format 1, two samples of (3, 4) and (-6, 8), weighting 0.
  bytes[16 + 34] = 1;
  bytes[16 + 168] = 0;
  bytes[16 + 169] = 0;
  bytes.resize(16 + 240);
  for (int16_t v : {int16_t(3), int16_t(4), int16_t(-6), int16_t(8)}) {
    bytes.push_back(static_cast<uint8_t>(v & 0xFF));
    bytes.push_back(static_cast<uint8_t>((v >> 8) & 0xFF));
  }
  const auto header = decodeHeader(bytes.data());
  const sss::core::Result<SonarChannelRecord> result = decodeSonarData(*header, bytes.data() + 16, bytes.size() - 16);
  ASSERT_OK(result);
  EXPECT_FLOAT_EQ(result->samples[0], 5.0f);
  EXPECT_FLOAT_EQ(result->samples[1], 10.0f);
}

TEST(JsfFormat, BadBodiesAreErrorsNotCrashes) {
  const std::vector<uint8_t> bytes = test::encodeRecord(test::makeRecord(1, kChannelPort), 100);
  const auto header = decodeHeader(bytes.data());
  EXPECT_NE(decodeSonarData(*header, bytes.data() + 16, 100).message().find("shorter than its 240-byte header"),
            std::string::npos);
  EXPECT_NE(decodeSonarData(*header, bytes.data() + 16, 240 + 10).message().find("needs 440 bytes"), std::string::npos);
  std::vector<uint8_t> odd = bytes;
  odd[16 + 34] = 7;
  EXPECT_NE(decodeSonarData(*header, odd.data() + 16, odd.size() - 16).message().find("format 7"), std::string::npos);
  std::vector<uint8_t> wrong_marker = bytes;
  wrong_marker[1] = 0x17;
  EXPECT_FALSE(decodeHeader(wrong_marker.data()));
}

// Message 82 of older EdgeTech side-scan systems, at its byte offsets (MB-System's mbsys_jstar.h):
// the 80-byte header and the samples. Time from the calendar fields and the milliseconds of the
// day, heading, pitch and roll in minutes of arc, depth in cm, samples scaled by 2^-N; no position.
TEST(JsfFormat, OlderSideScanMessage82DecodesAtItsByteOffsets) {
  SonarChannelRecord sent;
  sent.subsystem = kSubsystemSideScanHigh;
  sent.channel = kChannelStarboard;
  sent.ping_number = 4711;
  sent.ping_time_us = 1780358399987000LL;  // 2026-06-01T23:59:59.987Z: day 152
  sent.sample_interval_s = 2.5e-5;
  sent.start_depth_samples = 12;
  sent.heading_rad = 250.5 * M_PI / 180.0;
  sent.pitch_rad = -1.5 * M_PI / 180.0;
  sent.roll_rad = 2.25 * M_PI / 180.0;
  sent.depth_m = 31.27;
  sent.weighting_factor = 3;
  const std::vector<uint16_t> codes = {0, 8, 800, 65535};
  const std::vector<uint8_t> bytes = encodeOldSideScanData(sent, codes, 9);
  ASSERT_EQ(bytes.size(), 16u + 80u + 8u);
  EXPECT_EQ(at<uint16_t>(bytes, 4), 82);
  EXPECT_EQ(bytes[7], kSubsystemSideScanHigh);
  EXPECT_EQ(bytes[8], kChannelStarboard);
  EXPECT_EQ(at<int32_t>(bytes, 12), 88);
  const size_t b = 16;
  EXPECT_EQ(at<uint32_t>(bytes, b + 4), 4711u);
  EXPECT_EQ(at<uint32_t>(bytes, b + 12), 4u);        // samples
  EXPECT_EQ(at<uint32_t>(bytes, b + 16), 25000u);    // ns
  EXPECT_EQ(at<uint32_t>(bytes, b + 20), 12u);
  EXPECT_EQ(at<int16_t>(bytes, b + 24), 3);
  EXPECT_EQ(at<uint32_t>(bytes, b + 40), 86399987u);  // ms of the day
  EXPECT_EQ(at<int16_t>(bytes, b + 44), 2026);
  EXPECT_EQ(at<uint16_t>(bytes, b + 46), 152);
  EXPECT_EQ(at<uint16_t>(bytes, b + 48), 23);
  EXPECT_EQ(at<uint16_t>(bytes, b + 50), 59);
  EXPECT_EQ(at<uint16_t>(bytes, b + 52), 59);
  EXPECT_EQ(at<int16_t>(bytes, b + 54), 15030);       // 250.5 deg in minutes
  EXPECT_EQ(at<int16_t>(bytes, b + 56), -90);
  EXPECT_EQ(at<int16_t>(bytes, b + 58), 135);
  EXPECT_EQ(at<uint32_t>(bytes, b + 64), 3127u);
  EXPECT_EQ(at<uint16_t>(bytes, b + 80 + 6), 65535);

  const auto header = decodeHeader(bytes.data());
  ASSERT_TRUE(header);
  const sss::core::Result<SonarChannelRecord> r = decodeOldSideScanData(*header, bytes.data() + 16, bytes.size() - 16);
  ASSERT_OK(r);
  EXPECT_EQ(r->subsystem, kSubsystemSideScanHigh);
  EXPECT_EQ(r->channel, kChannelStarboard);
  EXPECT_EQ(r->ping_number, 4711u);
  EXPECT_EQ(r->ping_time_us, sent.ping_time_us);
  EXPECT_DOUBLE_EQ(r->sample_interval_s, 2.5e-5);
  EXPECT_EQ(r->start_depth_samples, 12u);
  EXPECT_NEAR(r->heading_rad, sent.heading_rad, 1e-12);
  EXPECT_NEAR(r->pitch_rad, sent.pitch_rad, 1e-12);
  EXPECT_NEAR(r->roll_rad, sent.roll_rad, 1e-12);
  EXPECT_NEAR(r->depth_m, 31.27, 1e-9);
  EXPECT_EQ(r->validity, kValidHeading | kValidPitchRoll | kValidDepth);  // no position, altitude or sound speed
  ASSERT_EQ(r->samples.size(), 4u);
  EXPECT_FLOAT_EQ(r->samples[1], 1.0f);   // 8 x 2^-3
  EXPECT_FLOAT_EQ(r->samples[3], 65535.0f / 8.0f);

  // Heading exactly 0 is no heading (no validity flags); bad bodies are errors, not crashes.
  SonarChannelRecord north = sent;
  north.heading_rad = 0.0;
  const std::vector<uint8_t> north_bytes = encodeOldSideScanData(north, codes);
  const auto no_heading = decodeOldSideScanData(*header, north_bytes.data() + 16, north_bytes.size() - 16);
  ASSERT_OK(no_heading);
  EXPECT_FALSE(no_heading->validity & kValidHeading);
  EXPECT_NE(decodeOldSideScanData(*header, bytes.data() + 16, 60).message().find("shorter than its 80-byte header"),
            std::string::npos);
  EXPECT_NE(decodeOldSideScanData(*header, bytes.data() + 16, 84).message().find("needs 88 bytes"), std::string::npos);
  std::vector<uint8_t> odd = bytes;
  odd[b + 36] = 7;
  EXPECT_NE(decodeOldSideScanData(*header, odd.data() + 16, odd.size() - 16).message().find("format 7"), std::string::npos);
  std::vector<uint8_t> no_date = bytes;
  no_date[b + 46] = 0;
  no_date[b + 47] = 0;  // day 0
  EXPECT_NE(decodeOldSideScanData(*header, no_date.data() + 16, no_date.size() - 16).message().find("impossible date"),
            std::string::npos);
}

}  // namespace
}  // namespace sss::edgetech
