// The writer lays bytes out as the public XTF description says: offsets checked by hand here,
// independently of the reader's decoding.
#include "drivers/xtf/xtf_writer.hpp"

#include <gtest/gtest.h>

#include <cstring>

#include "tests/xtf/xtf_test_data.hpp"

namespace sss {
namespace {

uint16_t u16(const std::vector<uint8_t>& b, size_t at) { return static_cast<uint16_t>(b[at] | (b[at + 1] << 8)); }
uint32_t u32(const std::vector<uint8_t>& b, size_t at) {
  return static_cast<uint32_t>(b[at]) | (static_cast<uint32_t>(b[at + 1]) << 8) |
         (static_cast<uint32_t>(b[at + 2]) << 16) | (static_cast<uint32_t>(b[at + 3]) << 24);
}
double f64(const std::vector<uint8_t>& b, size_t at) {
  double value;
  std::memcpy(&value, b.data() + at, 8);  // the test host is little-endian, like XTF
  return value;
}
float f32(const std::vector<uint8_t>& b, size_t at) {
  float value;
  std::memcpy(&value, b.data() + at, 4);
  return value;
}

TEST(XtfWriter, FileHeaderFieldsAtDocumentedOffsets) {
  const xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f, 400.0f}, 1, xtf::kNavUnitsLatLon);
  const std::vector<uint8_t> header = xtf::encodeFileHeader(options);
  ASSERT_EQ(header.size(), 1024u);
  EXPECT_EQ(header[0], 0x7B);
  EXPECT_EQ(u16(header, 164), 3);  // NavUnits
  EXPECT_EQ(u16(header, 166), 4);  // NumberOfSonarChannels
  // CHANINFO 1 at 256 + 128: starboard, 1 byte per sample, frequency 100 at +32.
  EXPECT_EQ(header[256 + 128 + 0], 2);
  EXPECT_EQ(u16(header, 256 + 128 + 6), 1);
  EXPECT_FLOAT_EQ(f32(header, 256 + 128 + 32), 100.0f);
  EXPECT_EQ(header[256 + 3 * 128 + 0], 2);
  EXPECT_FLOAT_EQ(f32(header, 256 + 3 * 128 + 32), 400.0f);
}

TEST(XtfWriter, HeaderGrowsBy1024ForMoreThanSixChannels) {
  const xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f, 200.0f, 300.0f, 400.0f}, 2);
  const std::vector<uint8_t> header = xtf::encodeFileHeader(options);
  EXPECT_EQ(header.size(), 2048u);
  EXPECT_EQ(header[256 + 7 * 128], 2);  // CHANINFO 7 (starboard) continues in the second block
}

TEST(XtfWriter, SonarPacketFieldsAtDocumentedOffsets) {
  const xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f}, 2);
  const xtf::XtfPingInput ping = test::makeXtfPing(options, 7, 100);
  const std::vector<uint8_t> packet = xtf::encodeSonarPacket(options, ping);
  const size_t expected_size = 256 + 2 * (64 + 100 * 2);
  ASSERT_EQ(packet.size(), expected_size);
  EXPECT_EQ(packet[0], 0xCE);  // 0xFACE little-endian
  EXPECT_EQ(packet[1], 0xFA);
  EXPECT_EQ(packet[2], 0);                   // HeaderType sonar
  EXPECT_EQ(u16(packet, 4), 2);              // NumChansToFollow
  EXPECT_EQ(u32(packet, 10), expected_size); // NumBytesThisRecord
  EXPECT_EQ(u16(packet, 14), 2023);          // Year
  EXPECT_EQ(u32(packet, 28), 7u);            // PingNumber
  EXPECT_FLOAT_EQ(f32(packet, 32), 750.0f);  // SoundVelocity
  EXPECT_DOUBLE_EQ(f64(packet, 160), ping.sensor_y);  // SensorYcoordinate (latitude)
  EXPECT_DOUBLE_EQ(f64(packet, 168), ping.sensor_x);  // SensorXcoordinate (longitude)
  EXPECT_FLOAT_EQ(f32(packet, 192), 80.0f);  // SensorDepth
  EXPECT_FLOAT_EQ(f32(packet, 196), 18.0f);  // SensorPrimaryAltitude
  EXPECT_FLOAT_EQ(f32(packet, 204), 2.0f);   // SensorPitch
  EXPECT_FLOAT_EQ(f32(packet, 208), -1.5f);  // SensorRoll
  EXPECT_FLOAT_EQ(f32(packet, 212), 350.0f); // SensorHeading
  // First channel header at 256: ChannelNumber 0, SlantRange at +4, NumSamples at +42.
  EXPECT_EQ(u16(packet, 256), 0);
  EXPECT_FLOAT_EQ(f32(packet, 256 + 4), 75.0f);
  EXPECT_EQ(u32(packet, 256 + 42), 100u);
  EXPECT_EQ(u16(packet, 256 + 64), static_cast<uint16_t>(test::xtfSample(0, 0, 7, 2)));
  // Second channel header after 100 two-byte samples.
  EXPECT_EQ(u16(packet, 256 + 64 + 200), 1);
  EXPECT_EQ(u32(packet, 256 + 64 + 200 + 42), 100u);
}

TEST(XtfWriter, OtherPacketCarriesItsSize) {
  const std::vector<uint8_t> packet = xtf::encodeOtherPacket(3, 64);
  EXPECT_EQ(u16(packet, 0), 0xFACE);
  EXPECT_EQ(packet[2], 3);
  EXPECT_EQ(u32(packet, 10), 64u);
}

}  // namespace
}  // namespace sss
