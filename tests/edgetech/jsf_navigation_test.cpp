// JSF navigation messages decoded from bodies laid out byte by byte from the published layout.
#include "drivers/edgetech/jsf_navigation.hpp"
#include "tests/support/status_assertions.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

namespace sss::edgetech {
namespace {

template <typename T>
void put(std::vector<uint8_t>& body, size_t offset, T value) {
  std::memcpy(body.data() + offset, &value, sizeof(T));
}

JsfMessageHeader headerOf(uint16_t type, size_t size) {
  JsfMessageHeader header;
  header.message_type = type;
  header.byte_count = static_cast<int32_t>(size);
  return header;
}

std::vector<uint8_t> timedBody(size_t size) {
  std::vector<uint8_t> body(size, 0);
  put<int32_t>(body, 0, 1780300800);
  put<int32_t>(body, 4, 250);  // milliseconds
  return body;
}

constexpr double kDeg = M_PI / 180.0;

TEST(JsfNavigation, PitchRoll2020) {
  std::vector<uint8_t> body = timedBody(44);
  put<int16_t>(body, 24, 1024);     // pitch 5.625 deg bow up
  put<int16_t>(body, 26, -512);     // roll -2.8125 deg (port down)
  put<int16_t>(body, 32, 150);      // heave 0.15 m down
  put<uint16_t>(body, 34, 27050);   // heading 270.50 deg
  put<int32_t>(body, 36, (1 << 6) | (1 << 7) | (1 << 8) | (1 << 9));
  const auto result = decodeNavigation(headerOf(kJsfPitchRoll, body.size()), body.data(), body.size());
  ASSERT_OK(result);
  const JsfNavigationRecord& r = *result;
  EXPECT_EQ(r.time_us, 1780300800250000LL);
  EXPECT_NEAR(*r.pitch_rad, 5.625 * kDeg, 1e-12);
  EXPECT_NEAR(*r.roll_rad, -2.8125 * kDeg, 1e-12);
  EXPECT_NEAR(*r.heave_m, 0.15, 1e-12);
  EXPECT_NEAR(*r.heading_rad, 270.5 * kDeg, 1e-12);
}

TEST(JsfNavigation, Dvl2080ShipCoordinatesAndBeamAltitude) {
  std::vector<uint8_t> body = timedBody(72);
  put<uint32_t>(body, 12, (1u << 0) | (1u << 1) | (1u << 2) | (1u << 5) | (1u << 6) | (1u << 10));
  put<int32_t>(body, 16, 1800);  // beams in cm; one invalid (0)
  put<int32_t>(body, 20, 1900);
  put<int32_t>(body, 24, 0);
  put<int32_t>(body, 28, 2000);
  put<int16_t>(body, 32, 50);    // starboard 0.05 m/s
  put<int16_t>(body, 34, 2000);  // forward 2 m/s
  put<int16_t>(body, 36, -100);  // up -0.1 m/s = down 0.1
  put<uint16_t>(body, 44, 425);  // depth 42.5 m
  put<uint16_t>(body, 50, 9000); // heading 90 deg
  const auto result = decodeNavigation(headerOf(kJsfDvl, body.size()), body.data(), body.size());
  ASSERT_OK(result);
  const JsfNavigationRecord& r = *result;
  EXPECT_NEAR(*r.altitude_m, 19.0, 1e-12);
  EXPECT_NEAR(*r.velocity_forward_m_s, 2.0, 1e-12);
  EXPECT_NEAR(*r.velocity_starboard_m_s, 0.05, 1e-12);
  EXPECT_NEAR(*r.velocity_down_m_s, 0.1, 1e-12);
  EXPECT_NEAR(*r.depth_m, 42.5, 1e-12);
  EXPECT_NEAR(*r.heading_rad, M_PI / 2, 1e-12);
  EXPECT_FALSE(r.velocity_north_m_s);
  EXPECT_FALSE(r.pitch_rad);  // its validity bit is clear
}

TEST(JsfNavigation, Situation2090AndVersion2) {
  std::vector<uint8_t> body = timedBody(276);
  put<uint32_t>(body, 12, 0x7Fu | (1u << 13) | (1u << 14) | (1u << 15));
  put<uint64_t>(body, 20, 1780300800123456ULL);
  put<double>(body, 28, 59.351);
  put<double>(body, 36, 18.072);
  put<double>(body, 44, 41.25);
  put<double>(body, 52, 45.0);
  put<double>(body, 60, 1.5);
  put<double>(body, 68, -0.5);
  put<double>(body, 124, 1.4);
  put<double>(body, 132, 1.3);
  put<double>(body, 140, 0.02);
  auto result = decodeNavigation(headerOf(kJsfSituation, body.size()), body.data(), body.size());
  ASSERT_OK(result);
  EXPECT_EQ(result->time_us, 1780300800123456LL);
  EXPECT_DOUBLE_EQ(*result->latitude_deg, 59.351);
  EXPECT_DOUBLE_EQ(*result->longitude_deg, 18.072);
  EXPECT_NEAR(*result->heading_rad, M_PI / 4, 1e-12);
  EXPECT_NEAR(*result->velocity_east_m_s, 1.3, 1e-12);

  std::vector<uint8_t> v2 = timedBody(100);
  put<uint32_t>(v2, 12, 0x7FFu);
  v2[16] = 0;  // north/east velocities
  put<uint64_t>(v2, 20, 178030080012345678ULL);  // 0.01 us units
  put<double>(v2, 28, -33.5);
  put<double>(v2, 36, 151.25);
  put<float>(v2, 44, 100.5f);
  put<float>(v2, 48, 17.75f);
  put<float>(v2, 56, 2.0f);
  put<float>(v2, 60, -1.0f);
  put<float>(v2, 76, 359.0f);
  result = decodeNavigation(headerOf(kJsfSituation2, v2.size()), v2.data(), v2.size());
  ASSERT_OK(result);
  EXPECT_EQ(result->time_us, 1780300800123456LL);
  EXPECT_DOUBLE_EQ(*result->latitude_deg, -33.5);
  EXPECT_DOUBLE_EQ(*result->longitude_deg, 151.25);
  EXPECT_FLOAT_EQ(static_cast<float>(*result->altitude_m), 17.75f);
  EXPECT_FLOAT_EQ(static_cast<float>(*result->velocity_east_m_s), -1.0f);
  EXPECT_NEAR(*result->heading_rad, 359.0 * kDeg, 1e-6);
}

TEST(JsfNavigation, NmeaStringAndBadBodies) {
  std::vector<uint8_t> body = timedBody(12);
  const std::string sentence = "$GPZDA,080000.25,01,06,2026,00,00*6A\r\n";
  body.insert(body.end(), sentence.begin(), sentence.end());
  auto result = decodeNavigation(headerOf(kJsfNmea, body.size()), body.data(), body.size());
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(*result->nmea, "$GPZDA,080000.25,01,06,2026,00,00*6A");
  // Too short for its layout: an error, not a read past the end.
  result = decodeNavigation(headerOf(kJsfSituation, 100), body.data(), 100 > body.size() ? body.size() : 100);
  EXPECT_FALSE(result.ok());
  EXPECT_NE(result.message().find("shorter than its 244-byte layout"), std::string::npos);
  // Impossible values are dropped, the rest kept.
  std::vector<uint8_t> bad = timedBody(276);
  put<uint32_t>(bad, 12, 0x6u);
  put<double>(bad, 28, 123.0);  // latitude 123 deg
  put<double>(bad, 36, 18.0);
  result = decodeNavigation(headerOf(kJsfSituation, bad.size()), bad.data(), bad.size());
  ASSERT_TRUE(result.ok());
  EXPECT_FALSE(result->latitude_deg);
  EXPECT_DOUBLE_EQ(*result->longitude_deg, 18.0);
}

}  // namespace
}  // namespace sss::edgetech
