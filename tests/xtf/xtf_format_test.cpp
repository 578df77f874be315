// XTF file header parsing, side-scan pair selection, ping time and sonar packet decoding.
#include "drivers/xtf/xtf_format.hpp"
#include "drivers/xtf/xtf_writer.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/support/status_assertions.hpp"
#include "tests/xtf/xtf_test_data.hpp"

namespace sss {
namespace {

TEST(XtfFormat, ParsesFileHeaderChannels) {
  const xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f, 400.0f}, 1, xtf::kNavUnitsMetres);
  const std::vector<uint8_t> bytes = xtf::encodeFileHeader(options);
  const sss::core::Result<xtf::XtfFileInfo> header = xtf::parseFileHeader(bytes.data(), bytes.size());
  ASSERT_OK(header);
  const xtf::XtfFileInfo& info = *header;
  EXPECT_EQ(info.nav_units, xtf::kNavUnitsMetres);
  ASSERT_EQ(info.channels.size(), 4u);
  EXPECT_EQ(info.channels[2].type_of_channel, xtf::kChannelPort);
  EXPECT_EQ(info.channels[2].bytes_per_sample, 1);
  EXPECT_EQ(info.channels[2].sample_type, xtf::SampleType::kUnsigned8);
  EXPECT_EQ(info.channels[3].name, "Stbd");
  EXPECT_EQ(info.recording_program, "sss-slam");
}

TEST(XtfFormat, RejectsWhatIsNoXtfHeader) {
  std::vector<uint8_t> bytes(1024, 0);
  const sss::core::Result<xtf::XtfFileInfo> zeros = xtf::parseFileHeader(bytes.data(), bytes.size());
  EXPECT_FALSE(zeros.ok());
  EXPECT_NE(zeros.message().find("0x7B"), std::string::npos);
  const sss::core::Result<xtf::XtfFileInfo> short_header = xtf::parseFileHeader(bytes.data(), 100);
  EXPECT_FALSE(short_header.ok());
  EXPECT_FALSE(short_header.message().empty());
  bytes[0] = 0x7B;
  bytes[166] = 0xFF;  // 255 sonar channels
  const sss::core::Result<xtf::XtfFileInfo> corrupt = xtf::parseFileHeader(bytes.data(), bytes.size());
  EXPECT_FALSE(corrupt.ok());
  EXPECT_NE(corrupt.message().find("corrupt"), std::string::npos);
}

TEST(XtfFormat, EightChannelHeaderNeedsTwoBlocks) {
  const xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f, 200.0f, 300.0f, 400.0f}, 2);
  const std::vector<uint8_t> bytes = xtf::encodeFileHeader(options);
  EXPECT_EQ(xtf::requiredHeaderBytes(bytes.data(), 1024), 2048u);
  const sss::core::Result<xtf::XtfFileInfo> first_block = xtf::parseFileHeader(bytes.data(), 1024);
  EXPECT_FALSE(first_block.ok());
  EXPECT_NE(first_block.message().find("2048"), std::string::npos);
  const sss::core::Result<xtf::XtfFileInfo> header = xtf::parseFileHeader(bytes.data(), bytes.size());
  ASSERT_OK(header);
  const xtf::XtfFileInfo& info = *header;
  ASSERT_EQ(info.channels.size(), 8u);
  EXPECT_FLOAT_EQ(info.channels[7].frequency, 400.0f);
}

TEST(XtfFormat, PairsOrderedByFrequency) {
  // High-frequency pair first in the file: pair 0 must still be the low one.
  const xtf::XtfWriterOptions options = test::makeXtfOptions({410.0f, 120.0f}, 1);
  const std::vector<uint8_t> bytes = xtf::encodeFileHeader(options);
  const sss::core::Result<xtf::XtfFileInfo> header = xtf::parseFileHeader(bytes.data(), bytes.size());
  ASSERT_OK(header);
  const std::vector<xtf::ChannelPair> pairs = xtf::sideScanPairs(*header);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].port, 2);
  EXPECT_EQ(pairs[0].starboard, 3);
  EXPECT_EQ(pairs[1].port, 0);
  EXPECT_EQ(pairs[1].starboard, 1);
  EXPECT_FLOAT_EQ(xtf::frequencyHz(120.0f), 120000.0f);
  EXPECT_FLOAT_EQ(xtf::frequencyHz(455000.0f), 455000.0f);
}

// Navigation packets laid out byte by byte after pyxtf's structures (types 3, 42, 107).
TEST(XtfFormat, DecodesAttitudeNavigationAndRawPositionPackets) {
  using namespace sss::xtf;
  std::vector<uint8_t> attitude = encodeOtherPacket(kHeaderAttitude, 64);
  writeU32(attitude.data(), 22, 250000);      // EpochMicroseconds
  writeU32(attitude.data(), 26, 1780300800);  // SourceEpoch: 2026-06-01T08:00:00Z
  writeF32(attitude.data(), 30, 2.0f);        // pitch, nose up
  writeF32(attitude.data(), 34, -3.0f);       // roll, port down
  writeF32(attitude.data(), 50, -90.0f);      // heading: west
  auto a = decodeNavigationPacket(attitude.data(), attitude.size());
  ASSERT_TRUE(a);
  EXPECT_EQ(a->utime_us, 1780300800250000LL);
  EXPECT_NEAR(*a->pitch_rad, 2.0 * M_PI / 180.0, 1e-7);
  EXPECT_NEAR(*a->roll_rad, -3.0 * M_PI / 180.0, 1e-7);
  EXPECT_NEAR(*a->heading_rad, 1.5 * M_PI, 1e-6);
  EXPECT_FALSE(a->y);

  // Types 42 and 107 both start their time with year (u16), month, day, hour at offset 14.
  auto writeDateAndHour = [](std::vector<uint8_t>& packet) {  // 2026-06-01, 08 h
    writeU16(packet.data(), 14, 2026);
    packet[16] = 6;
    packet[17] = 1;
    packet[18] = 8;
  };
  std::vector<uint8_t> navigation = encodeOtherPacket(kHeaderNavigation, 64);
  writeDateAndHour(navigation);
  navigation[19] = 0;
  navigation[20] = 1;
  writeU32(navigation.data(), 21, 123456);  // microseconds
  writeF64(navigation.data(), 33, 6580456.25);
  writeF64(navigation.data(), 41, 650123.5);
  auto n = decodeNavigationPacket(navigation.data(), navigation.size());
  ASSERT_TRUE(n);
  EXPECT_EQ(n->utime_us, 1780300801123456LL);
  EXPECT_DOUBLE_EQ(*n->y, 6580456.25);
  EXPECT_DOUBLE_EQ(*n->x, 650123.5);
  EXPECT_FALSE(n->heading_rad);

  std::vector<uint8_t> raw = encodeOtherPacket(kHeaderPosRawNavigation, 64);
  writeDateAndHour(raw);
  writeU16(raw.data(), 21, 5000);  // 0.5 s in units of 100 us
  writeF64(raw.data(), 23, 59.35);
  writeF64(raw.data(), 31, 18.07);
  writeF32(raw.data(), 59, 370.0f);
  auto p = decodeNavigationPacket(raw.data(), raw.size());
  ASSERT_TRUE(p);
  EXPECT_EQ(p->utime_us, 1780300800500000LL);
  EXPECT_DOUBLE_EQ(*p->y, 59.35);
  EXPECT_NEAR(*p->heading_rad, 10.0 * M_PI / 180.0, 1e-6);
  // Too short, another type, an impossible date: nothing.
  EXPECT_FALSE(decodeNavigationPacket(raw.data(), 63));
  std::vector<uint8_t> notes = encodeOtherPacket(1, 64);
  EXPECT_FALSE(decodeNavigationPacket(notes.data(), notes.size()));
  raw[16] = 13;
  EXPECT_FALSE(decodeNavigationPacket(raw.data(), raw.size()));
}

TEST(XtfFormat, CalendarToUtc) {
  EXPECT_EQ(*xtf::utcFromCalendar(1970, 1, 1, 0, 0, 0, 0), 0);
  EXPECT_EQ(*xtf::utcFromCalendar(2023, 11, 14, 22, 13, 20, 25), 1700000000250000);
  EXPECT_EQ(*xtf::utcFromCalendar(2024, 2, 29, 0, 0, 0, 0), 1709164800000000);
  EXPECT_FALSE(xtf::utcFromCalendar(2023, 13, 1, 0, 0, 0, 0));
  EXPECT_FALSE(xtf::utcFromCalendar(2023, 1, 1, 0, 0, 0, 100));
  EXPECT_FALSE(xtf::utcFromCalendar(0, 1, 1, 0, 0, 0, 0));
}

xtf::SonarDecodeResult decodeOne(float sound_velocity, float slant_range_m, float duration_s, float delay_s = 0.0f) {
  const xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f}, 2);
  xtf::XtfPingInput input = test::makeXtfPing(options, 1, 100);
  input.sound_velocity = sound_velocity;
  for (auto& channel : input.channels) {
    channel.slant_range_m = slant_range_m;
    channel.time_duration_s = duration_s;
    channel.time_delay_s = delay_s;
  }
  const std::vector<uint8_t> header = xtf::encodeFileHeader(options);
  const std::vector<uint8_t> packet = xtf::encodeSonarPacket(options, input);
  const sss::core::Result<xtf::XtfFileInfo> parsed = xtf::parseFileHeader(header.data(), header.size());
  EXPECT_OK(parsed);
  if (!parsed) return {};
  const xtf::XtfFileInfo& info = *parsed;
  xtf::SonarDecodeOptions decode;
  decode.port_channel = 0;
  decode.starboard_channel = 1;
  return xtf::decodeSonarPacket(info, decode, packet.data(), packet.size());
}

TEST(XtfFormat, SoundVelocityHalfOrFullGivesTheSameRanges) {
  // 750 (Isis, half speed) and 1500 must both give c = 1500 and the last sample at 99/100 of 75 m.
  for (const float stored : {750.0f, 1500.0f}) {
    const xtf::SonarDecodeResult result = decodeOne(stored, 75.0f, 0.0f);
    ASSERT_TRUE(result.ping) << result.error;
    const sonar::SonarChannelRecord& port = *result.ping->ping.port;
    EXPECT_FLOAT_EQ(port.sound_speed_m_s, 1500.0f);
    EXPECT_NEAR(port.slantRangeM(99), 75.0 * 99 / 100, 1e-9);
    EXPECT_TRUE(port.validity & sonar::kValidSoundSpeed);
  }
  const xtf::SonarDecodeResult odd = decodeOne(0.0f, 75.0f, 0.0f);
  ASSERT_TRUE(odd.ping);
  EXPECT_TRUE(odd.sound_speed_fallback);
  EXPECT_NEAR(odd.ping->ping.port->slantRangeM(50), 37.5, 1e-9);  // range still from SlantRange
}

TEST(XtfFormat, RangeFromTimeDurationWithoutSlantRange) {
  // TimeDuration is two-way: 0.1 s at 1500 m/s is 75 m.
  const xtf::SonarDecodeResult result = decodeOne(750.0f, 0.0f, 0.1f);
  ASSERT_TRUE(result.ping) << result.error;
  EXPECT_NEAR(result.ping->ping.starboard->slantRangeM(100), 75.0, 1e-4);
  const xtf::SonarDecodeResult none = decodeOne(750.0f, 0.0f, -1.0f);
  EXPECT_FALSE(none.ping);
  EXPECT_NE(none.error.find("slant range"), std::string::npos);
}

// A record that starts after a delay (the water column left out): SlantRange is the far range,
// TimeDelay the two-way time to the first sample, TimeDuration the time the samples span. 15 m to
// 80 m over 100 samples: spaced by TimeDuration / 100, the first at the delay (to the nearest
// sample: start_depth_samples is whole), the last at 80 m, not at 80 m plus the delay.
TEST(XtfFormat, DelayedRecordSpansTimeDurationFromTheDelay) {
  const float delay_s = 2.0f * 15.0f / 1500.0f, duration_s = 2.0f * 65.0f / 1500.0f;
  const xtf::SonarDecodeResult result = decodeOne(750.0f, 80.0f, duration_s, delay_s);
  ASSERT_TRUE(result.ping) << result.error;
  const sonar::SonarChannelRecord& port = *result.ping->ping.port;
  const double spacing_m = 0.65;
  EXPECT_NEAR(port.sample_interval_s, duration_s / 100.0, 1e-9);
  EXPECT_NEAR(port.slantRangeM(0), 15.0, 0.5 * spacing_m);
  EXPECT_NEAR(port.slantRangeM(100), 80.0, 0.5 * spacing_m);
}


// Layback (Isis: "distance over ground from ship to fish"; non-zero means SensorY/X still need
// moving back). Handed on with the ping when the sensor position is the ship's (SensorY/X equal to
// ShipY/X, unset so that ShipY/X stand in, or no ShipY/X to tell); not when the writer already put
// the fish apart from the ship; never with apply_layback false, a layback beyond kMaxLaybackM or no
// position at all.
TEST(XtfFormat, LaybackIsHandedOnOnlyOverTheShipsOwnPosition) {
  const xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f}, 2);
  const std::vector<uint8_t> header = xtf::encodeFileHeader(options);
  const sss::core::Result<xtf::XtfFileInfo> info = xtf::parseFileHeader(header.data(), header.size());
  ASSERT_OK(info);
  struct Case {
    const char* name;
    double sensor_y, sensor_x, ship_y, ship_x;
    float layback_m;
    bool apply;
    double expected_layback_m;  // handed on
    bool in_position;           // counted as applied by the writer
  };
  const double lat = 59.91, lon = 10.71;
  const Case cases[] = {
      {"sensor equal to ship", lat, lon, lat, lon, 42.5f, true, 42.5, false},
      {"sensor unset, ship used", 0.0, 0.0, lat, lon, 42.5f, true, 42.5, false},
      {"no ship position", lat, lon, 0.0, 0.0, 42.5f, true, 42.5, false},
      {"fish already apart from the ship", lat - 3e-4, lon, lat, lon, 42.5f, true, 0.0, true},
      {"ignored by configuration", lat, lon, lat, lon, 42.5f, false, 0.0, false},
      {"no layback", lat, lon, lat, lon, 0.0f, true, 0.0, false},
      {"negative layback", lat, lon, lat, lon, -5.0f, true, 0.0, false},
      {"beyond any tow cable", lat, lon, lat, lon, 2.0f * xtf::kMaxLaybackM, true, 0.0, false},
      {"no position at all", 0.0, 0.0, 0.0, 0.0, 42.5f, true, 0.0, false},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    xtf::XtfPingInput input = test::makeXtfPing(options, 1, 100);
    input.sensor_y = c.sensor_y;
    input.sensor_x = c.sensor_x;
    input.ship_y = c.ship_y;
    input.ship_x = c.ship_x;
    input.layback_m = c.layback_m;
    const std::vector<uint8_t> packet = xtf::encodeSonarPacket(options, input);
    xtf::SonarDecodeOptions decode;
    decode.port_channel = 0;
    decode.starboard_channel = 1;
    decode.apply_layback = c.apply;
    const xtf::SonarDecodeResult result = xtf::decodeSonarPacket(*info, decode, packet.data(), packet.size());
    ASSERT_TRUE(result.ping) << result.error;
    EXPECT_FLOAT_EQ(result.ping->ping.port->layback_m, c.expected_layback_m);
    EXPECT_FLOAT_EQ(result.ping->ping.starboard->layback_m, c.expected_layback_m);
    EXPECT_EQ(result.layback_to_apply, c.expected_layback_m > 0.0);
    EXPECT_EQ(result.layback_in_position, c.in_position);
  }
}

// EdgeTech sonar types (24, 35, 38, 48) store the ADC's block floating point exponent in each
// channel header's Weight, "mandatory" to apply: sample x 2^-Weight, as JSF's weighting factor. A
// ping-to-ping change of Weight is then no step in the image. Other sonar types keep their samples
// as stored whatever the field holds.
TEST(XtfFormat, EdgeTechSonarTypesScaleSamplesByTheirWeight) {
  for (const uint16_t sonar_type : {uint16_t{35}, uint16_t{0}}) {
    SCOPED_TRACE(sonar_type);
    xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f}, 2);
    options.sonar_type = sonar_type;
    const std::vector<uint8_t> header = xtf::encodeFileHeader(options);
    const sss::core::Result<xtf::XtfFileInfo> info = xtf::parseFileHeader(header.data(), header.size());
    ASSERT_OK(info);
    EXPECT_EQ(info->sonar_type, sonar_type);
    for (const int16_t weight : {int16_t{0}, int16_t{3}, int16_t{-2}}) {
      xtf::XtfPingInput input = test::makeXtfPing(options, 1, 100);
      for (auto& channel : input.channels) channel.weight = weight;
      const std::vector<uint8_t> packet = xtf::encodeSonarPacket(options, input);
      xtf::SonarDecodeOptions decode;
      decode.port_channel = 0;
      decode.starboard_channel = 1;
      const xtf::SonarDecodeResult result = xtf::decodeSonarPacket(*info, decode, packet.data(), packet.size());
      ASSERT_TRUE(result.ping) << result.error;
      const bool scaled = sonar_type == 35 && weight != 0;
      EXPECT_EQ(result.weight_applied, scaled);
      const double factor = scaled ? std::ldexp(1.0, -weight) : 1.0;
      for (const size_t s : {size_t{1}, size_t{57}, size_t{99}}) {
        EXPECT_FLOAT_EQ(result.ping->ping.port->samples[s], input.channels[0].samples[s] * factor) << s;
        EXPECT_FLOAT_EQ(result.ping->ping.starboard->samples[s], input.channels[1].samples[s] * factor) << s;
      }
    }
  }
}

}  // namespace
}  // namespace sss
