// The driver logic end to end on bytes: every good ping of a corrupted stream comes out, with
// its time in the vehicle time base, and the raw stream is recorded byte for byte.
#include "drivers/edgetech/sonar_driver.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "drivers/edgetech/ping_message.hpp"
#include "jsf_test_data.hpp"

namespace sss::edgetech {
namespace {

TEST(SonarDriver, CorruptStreamStillYieldsEveryGoodPingInOrder) {
  auto messages = test::makeMessages(20);
  // Garbage before ping 1005 port, and ping 1010 starboard truncated.
  std::vector<uint8_t> garbage(100, 0xAB);
  messages[19].resize(200);
  messages.insert(messages.begin() + 10, garbage);
  SonarDriverOptions options;
  options.time_source = TimeSource::kSonarClock;
  SonarDriver driver(options);
  std::vector<DriverPing> pings;
  const std::vector<uint8_t> stream = test::concatenate(messages);
  for (size_t offset = 0; offset < stream.size(); offset += 1000) {
    driver.onBytes(stream.data() + offset, std::min<size_t>(1000, stream.size() - offset), 0, 0, pings);
  }
  driver.finish(0, 0, pings);
  ASSERT_EQ(pings.size(), 20u);
  int complete = 0;
  for (size_t i = 0; i < pings.size(); ++i) complete += pings[i].ping.complete();
  EXPECT_EQ(complete, 19);  // 1009 lost its starboard side
  EXPECT_EQ(driver.parserCounters().bytes_skipped, 100u);
  EXPECT_EQ(driver.parserCounters().truncated_messages, 1u);
  EXPECT_EQ(driver.assemblerCounters().incomplete_pings, 1u);
  EXPECT_EQ(pings[0].utime_us, test::makeRecord(1000, 0).ping_time_us);
  EXPECT_FALSE(driver.takeNewFaultMessages().empty());
}

TEST(SonarDriver, EstimatedTimeBaseAppliesTheClockOffset) {
  SonarDriverOptions options;
  options.clock.min_samples = 2;
  SonarDriver driver(options);
  const int64_t offset_us = 5'000'000;  // host clock 5 s ahead of the sonar
  std::vector<DriverPing> pings;
  const auto messages = test::makeMessages(6, 500);
  for (size_t i = 0; i < messages.size(); ++i) {
    const int ping = static_cast<int>(i / 2);
    const SonarChannelRecord r = test::makeRecord(static_cast<uint32_t>(1000 + ping), 0);
    // Ping p has 500 + p samples at 20 us; each arrives 3 ms after its acquisition ends.
    const int64_t arrival = r.ping_time_us + (500 + ping) * 20 + offset_us + 3000;
    driver.onBytes(messages[i].data(), messages[i].size(), arrival, 0, pings);
  }
  // Both channels of the first ping reach the clock before it completes: min_samples 2 is met.
  EXPECT_EQ(driver.pingsWithoutOffset(), 0u);
  ASSERT_EQ(pings.size(), 6u);
  EXPECT_EQ(pings[1].utime_us - pings[1].sonar_utime_us, offset_us + 3000);
}

TEST(SonarDriver, RecordsTheRawStreamExactlyWithRotation) {
  const std::string dir = ::testing::TempDir() + "/sonar_record_test";
  std::filesystem::remove_all(dir);
  SonarDriverOptions options;
  options.time_source = TimeSource::kSonarClock;
  options.recorder.directory = dir;
  options.recorder.max_file_bytes = 5000;
  SonarDriver driver(options);
  const std::vector<uint8_t> stream = test::concatenate(test::makeMessages(10));
  std::vector<DriverPing> pings;
  for (size_t offset = 0; offset < stream.size(); offset += 777) {
    driver.onBytes(stream.data() + offset, std::min<size_t>(777, stream.size() - offset), 1780300800000000, 0, pings);
  }
  EXPECT_GT(driver.recorder().filesOpened(), 2u);
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) files.push_back(entry.path());
  std::sort(files.begin(), files.end(), [](const auto& a, const auto& b) {
    auto index = [](const std::filesystem::path& p) {
      const std::string stem = p.stem().string();
      return std::stoi(stem.substr(stem.rfind('-') + 1));
    };
    return index(a) < index(b);
  });
  std::vector<uint8_t> recorded;
  for (const auto& file : files) {
    std::ifstream in(file, std::ios::binary);
    EXPECT_LE(std::filesystem::file_size(file), 5000u);
    recorded.insert(recorded.end(), std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  EXPECT_EQ(recorded, stream);
}

TEST(SonarDriver, RecordDirectoryFallsBackToSystemdsLogsDirectory) {
  // The config leaves it empty: systemd's LogsDirectory= ($LOGS_DIRECTORY), its first entry.
  EXPECT_EQ(resolveRecordDirectory("", "/var/log/sss-slam/jsf"), "/var/log/sss-slam/jsf");
  EXPECT_EQ(resolveRecordDirectory("", "/var/log/sss-slam/jsf:/var/log/other"), "/var/log/sss-slam/jsf");
  // The config wins; neither set (or an empty variable): recording off.
  EXPECT_EQ(resolveRecordDirectory("/data/jsf", "/var/log/sss-slam/jsf"), "/data/jsf");
  EXPECT_EQ(resolveRecordDirectory("/data/jsf", nullptr), "/data/jsf");
  EXPECT_EQ(resolveRecordDirectory("", nullptr), "");
  EXPECT_EQ(resolveRecordDirectory("", ""), "");
}

TEST(PingMessage, CarriesBothSidesNavAndMissingFlags) {
  DriverPing ping;
  ping.utime_us = 42;
  ping.ping.ping_number = 9;
  SonarChannelRecord port = test::makeRecord(9, kChannelPort);
  port.samples = {1.0f, 2.0f, 3.0f};
  port.start_depth_samples = 10;
  ping.ping.port = port;
  const sss_msgs::ping_t message = toPingMessage(ping);
  EXPECT_EQ(message.utime, 42);
  EXPECT_EQ(message.num_port_samples, 3);
  EXPECT_EQ(message.num_starboard_samples, 0);
  EXPECT_EQ(message.flags, sss_msgs::ping_t::FLAG_STARBOARD_MISSING);
  EXPECT_TRUE(message.has_nav);
  EXPECT_DOUBLE_EQ(message.start_range_m, 10 * 20e-6 * 750.0);
  EXPECT_FLOAT_EQ(message.altitude_m, 18.25f);
  EXPECT_NEAR(message.heading_rad, 1.2345, 1e-3);
}

}  // namespace
}  // namespace sss::edgetech
