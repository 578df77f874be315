// Corrected copies of JSF and XTF files: read back by the project's own readers, every ping carries
// the navigation given (within the format's precision), and every byte outside the pings'
// navigation fields is unchanged, corrupt stretches and foreign records included.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "drivers/edgetech/jsf_file_reader.hpp"
#include "drivers/edgetech/jsf_format.hpp"
#include "drivers/xtf/xtf_reader.hpp"
#include "drivers/xtf/xtf_writer.hpp"
#include "products/corrected_copy.hpp"
#include "tests/support/status_assertions.hpp"
#include "tests/xtf/xtf_test_data.hpp"

namespace fs = std::filesystem;

namespace sss::products {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr int64_t kStartUs = 1780300800000000LL;

std::vector<uint8_t> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void writeBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

// The "SLAM" navigation of the tests: a track 3 m east of the recorded one, heading 2 deg more.
PingNavigation correctedAt(int64_t utime_us, bool projected) {
  const double t_s = (utime_us - kStartUs) * 1e-6;
  PingNavigation nav;
  nav.projected = projected;
  nav.latitude_deg = 59.35 + t_s * 1e-5;
  nav.longitude_deg = 18.07 + 3.0 / 56800.0;
  nav.easting_m = 650123.0 + 3.0;
  nav.northing_m = 6580456.0 + t_s * 2.0;
  nav.depth_m = 30.25 + 0.001 * t_s;
  nav.heading_rad = (12.0 + t_s) * kDegToRad;
  nav.pitch_rad = 1.5 * kDegToRad;
  nav.roll_rad = -2.0 * kDegToRad;
  return nav;
}

class CorrectedCopyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() / ("sss_corrected_copy_test_" + std::to_string(getpid()))).string();
    fs::create_directories(dir_ + "/out");
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir_;
};

TEST_F(CorrectedCopyTest, JsfPingsCarryTheNewNavigationAndNothingElseChanges) {
  // 20 pings of port + starboard, a pitch/roll message between pings and garbage in the middle.
  std::vector<uint8_t> file;
  std::vector<size_t> sonar_offsets;  // of each type 80 message
  for (int i = 0; i < 20; ++i) {
    for (uint8_t channel : {sss::sonar::kChannelPort, sss::sonar::kChannelStarboard}) {
      sss::sonar::SonarChannelRecord record;
      record.channel = channel;
      record.ping_number = static_cast<uint32_t>(i);
      record.ping_time_us = kStartUs + i * 250000LL;
      record.sample_interval_s = 2e-5;
      record.validity = sss::sonar::kValidLatLon | sss::sonar::kValidAltitude;
      record.latitude_deg = 59.35 + i * 2.5e-6;
      record.longitude_deg = 18.07;
      record.depth_m = 30.0;
      record.altitude_m = 15.0;
      const std::vector<uint16_t> codes(500, static_cast<uint16_t>(100 + i));
      const std::vector<uint8_t> message = sss::edgetech::encodeSonarData(record, codes);
      sonar_offsets.push_back(file.size());
      file.insert(file.end(), message.begin(), message.end());
    }
    if (i == 10) file.insert(file.end(), {0x01, 0x16, 0xDE, 0xAD, 0xBE, 0xEF, 0x00, 0x42});  // a false start marker
    std::vector<uint8_t> other(16 + 24, 0x5A);  // a message of another type (2020), body 24 bytes
    sss::edgetech::JsfMessageHeader header;
    header.message_type = sss::edgetech::kJsfPitchRoll;
    header.byte_count = 24;
    sss::edgetech::encodeHeader(header, other.data());
    file.insert(file.end(), other.begin(), other.end());
  }
  const std::string in = dir_ + "/line.jsf", out = dir_ + "/out/line.jsf";
  writeBytes(in, file);

  CorrectedCopyCounters counters;
  const auto navigation = [](int64_t t) -> std::optional<PingNavigation> {
    if (t >= kStartUs + 19 * 250000LL) return std::nullopt;  // the last ping has no pose
    return correctedAt(t, false);
  };
  ASSERT_OK(writeCorrectedJsf(in, out, navigation, counters));
  EXPECT_EQ(counters.records_corrected, 38u);
  EXPECT_EQ(counters.records_without_pose, 2u);

  // Read back: the navigation given, to the format's quanta (1e-4 minute, 1 mm, 0.01 deg, 180/32768 deg).
  sss::edgetech::JsfFileReader reader(out);
  ASSERT_TRUE(reader.isOpen()) << reader.error();
  sss::edgetech::JsfMessage message;
  int pings = 0;
  while (reader.next(message)) {
    if (message.header.message_type != sss::edgetech::kJsfSonarData) continue;
    const auto decoded = sss::edgetech::decodeSonarData(message.header, message.body.data(), message.body.size());
    ASSERT_OK(decoded);
    const auto& r = *decoded;
    ++pings;
    if (r.ping_number == 19) {
      EXPECT_NEAR(r.latitude_deg, 59.35 + 19 * 2.5e-6, 1e-6) << "no pose: left as recorded";
      continue;
    }
    const PingNavigation want = correctedAt(r.ping_time_us, false);
    EXPECT_NEAR(r.latitude_deg, want.latitude_deg, 0.5e-4 / 60.0 + 1e-12);
    EXPECT_NEAR(r.longitude_deg, want.longitude_deg, 0.5e-4 / 60.0 + 1e-12);
    EXPECT_NEAR(r.depth_m, want.depth_m, 0.0005 + 1e-9);
    EXPECT_NEAR(r.heading_rad, want.heading_rad, 0.005 * kDegToRad + 1e-9);
    EXPECT_NEAR(r.pitch_rad, want.pitch_rad, 0.5 * 180.0 / 32768.0 * kDegToRad + 1e-9);
    EXPECT_NEAR(r.roll_rad, want.roll_rad, 0.5 * 180.0 / 32768.0 * kDegToRad + 1e-9);
    EXPECT_NEAR(r.altitude_m, 15.0, 1e-9) << "the altitude is the sonar's own measurement: kept";
    EXPECT_TRUE(r.validity & sss::sonar::kValidHeading);
    EXPECT_TRUE(r.validity & sss::sonar::kValidAltitude) << "validity bits are added, never cleared";
  }
  EXPECT_EQ(pings, 40);

  // Byte for byte: only the navigation fields of the type 80 headers differ.
  const std::vector<uint8_t> before = readBytes(in), after = readBytes(out);
  ASSERT_EQ(before.size(), after.size());
  std::set<size_t> allowed;
  for (size_t offset : sonar_offsets) {
    for (size_t field : {30, 31}) allowed.insert(offset + 16 + field);
    for (size_t k = 80; k < 90; ++k) allowed.insert(offset + 16 + k);
    for (size_t k = 136; k < 140; ++k) allowed.insert(offset + 16 + k);
    for (size_t k = 172; k < 178; ++k) allowed.insert(offset + 16 + k);
  }
  size_t changed = 0;
  for (size_t i = 0; i < before.size(); ++i) {
    if (before[i] == after[i]) continue;
    ++changed;
    EXPECT_TRUE(allowed.count(i)) << "byte " << i << " changed outside a navigation field";
  }
  EXPECT_GT(changed, 38u * 4) << "every corrected ping changed";
}

TEST_F(CorrectedCopyTest, XtfPingsInProjectedMetresCarryTheNewGridPosition) {
  // One 100 kHz port/starboard pair of 16-bit samples, navigation in projected metres.
  const sss::xtf::XtfWriterOptions options = sss::test::makeXtfOptions({100.0f}, 2, sss::xtf::kNavUnitsMetres);
  const std::string in = dir_ + "/line.xtf", out = dir_ + "/out/line.xtf";
  std::vector<size_t> ping_offsets;
  {
    sss::xtf::XtfWriter writer(in, options);
    ASSERT_TRUE(writer.isOpen());
    size_t offset = sss::xtf::encodeFileHeader(options).size();
    for (int i = 0; i < 12; ++i) {
      sss::xtf::XtfPingInput ping;
      ping.ping_number = static_cast<uint32_t>(i);
      ping.ping_time_us = kStartUs + i * 250000LL;
      ping.sensor_x = 650123.0;
      ping.sensor_y = 6580456.0 + 0.5 * i;
      ping.depth_m = 30.0f;
      ping.altitude_m = 15.0f;
      ping.heading_deg = 10.0f;
      for (uint16_t channel = 0; channel < 2; ++channel) {
        sss::xtf::XtfChannelData data;
        data.channel_number = channel;
        data.samples.assign(300, 50.0f + i);
        ping.channels.push_back(data);
      }
      ping_offsets.push_back(offset);
      offset += sss::xtf::encodeSonarPacket(options, ping).size();
      ASSERT_TRUE(writer.write(ping));
      const std::vector<uint8_t> attitude = sss::xtf::encodeOtherPacket(3, 64);
      ASSERT_TRUE(writer.writeBytes(attitude));
      offset += attitude.size();
    }
  }
  CorrectedCopyCounters counters;
  ASSERT_OK(writeCorrectedXtf(in, out, [](int64_t t) { return std::optional(correctedAt(t, true)); }, counters));
  EXPECT_EQ(counters.records_corrected, 12u);
  EXPECT_EQ(counters.records_without_pose, 0u);

  sss::xtf::XtfReader reader(out);
  ASSERT_TRUE(reader.isOpen()) << reader.error();
  sss::sonar::DriverPing ping;
  int pings = 0;
  while (reader.next(ping)) {
    ++pings;
    const PingNavigation want = correctedAt(ping.utime_us, true);
    const auto& side = *ping.ping.port;
    ASSERT_TRUE(side.projected_position);
    EXPECT_DOUBLE_EQ(side.easting_m, want.easting_m) << "f64 in XTF: exact";
    EXPECT_DOUBLE_EQ(side.northing_m, want.northing_m);
    EXPECT_NEAR(side.depth_m, want.depth_m, 1e-5);
    EXPECT_NEAR(side.heading_rad, want.heading_rad, 1e-6);
    EXPECT_NEAR(side.pitch_rad, want.pitch_rad, 1e-6);
    EXPECT_NEAR(side.roll_rad, want.roll_rad, 1e-6);
    EXPECT_NEAR(side.altitude_m, 15.0, 1e-6);
  }
  EXPECT_EQ(pings, 12);

  const std::vector<uint8_t> before = readBytes(in), after = readBytes(out);
  ASSERT_EQ(before.size(), after.size());
  std::set<size_t> allowed;
  for (size_t offset : ping_offsets) {
    for (size_t k = 160; k < 176; ++k) allowed.insert(offset + k);  // SensorY, SensorX
    for (size_t k = 192; k < 196; ++k) allowed.insert(offset + k);  // SensorDepth
    for (size_t k = 204; k < 216; ++k) allowed.insert(offset + k);  // pitch, roll, heading
  }
  std::set<size_t> pings_changed;
  for (size_t i = 0; i < before.size(); ++i) {
    if (before[i] == after[i]) continue;
    EXPECT_TRUE(allowed.count(i)) << "byte " << i << " changed outside a navigation field";
    pings_changed.insert(std::upper_bound(ping_offsets.begin(), ping_offsets.end(), i) - ping_offsets.begin());
  }
  EXPECT_EQ(pings_changed.size(), 12u) << "every ping's navigation rewritten";
}

TEST_F(CorrectedCopyTest, UnreadableInputOrTheInputItselfAsOutputAreRefused) {
  CorrectedCopyCounters counters;
  const auto navigation = [](int64_t t) { return std::optional(correctedAt(t, false)); };
  const sss::core::Status missing =
      writeCorrectedJsf(dir_ + "/missing.jsf", dir_ + "/out/missing.jsf", navigation, counters);
  EXPECT_FALSE(missing.ok);
  EXPECT_NE(missing.message.find("missing.jsf"), std::string::npos) << missing.message;
  writeBytes(dir_ + "/tiny.jsf", {1, 2, 3});
  const sss::core::Status onto_itself = writeCorrectedJsf(dir_ + "/tiny.jsf", dir_ + "/tiny.jsf", navigation, counters);
  EXPECT_FALSE(onto_itself.ok);
  EXPECT_NE(onto_itself.message.find("would overwrite its input"), std::string::npos) << onto_itself.message;
  EXPECT_EQ(readBytes(dir_ + "/tiny.jsf"), (std::vector<uint8_t>{1, 2, 3}));
  EXPECT_FALSE(writeCorrectedXtf(dir_ + "/tiny.jsf", dir_ + "/out/tiny.xtf", navigation, counters).ok);
  EXPECT_FALSE(fs::exists(dir_ + "/out/tiny.xtf"));
}

}  // namespace
}  // namespace sss::products
