// sss-sonar-driver's inputs on real descriptors: .jsf and .xtf files replayed whole, in order and
// at their recorded pace, with the end said once; a TCP link on loopback that reconnects after the
// peer closes; each failure says what and where.
#include "drivers/edgetech/sonar_input_source.hpp"

#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "jsf_test_data.hpp"
#include "pipeline/core/time.hpp"
#include "tests/support/loopback_socket.hpp"
#include "tools/fixtures/poll_until.hpp"
#include "tests/support/status_assertions.hpp"
#include "tests/xtf/xtf_test_data.hpp"

namespace sss::edgetech {
namespace {

namespace fs = std::filesystem;

// What a source handed over. events: log lines and faults in the order they came.
struct Recorder {
  std::vector<DriverPing> pings;
  std::vector<std::string> info;
  std::vector<std::string> warnings;
  std::vector<std::string> faults;
  std::vector<std::string> events;

  SonarInputHooks hooks() {
    SonarInputHooks hooks;
    hooks.ping = [this](const DriverPing& ping) { pings.push_back(ping); };
    hooks.info = [this](const std::string& line) {
      info.push_back(line);
      events.push_back("info: " + line);
    };
    hooks.warning = [this](const std::string& line) {
      warnings.push_back(line);
      events.push_back("warning: " + line);
    };
    hooks.faults = [this](const std::vector<std::string>& new_faults) {
      for (const std::string& fault : new_faults) {
        faults.push_back(fault);
        events.push_back("fault: " + fault);
      }
    };
    return hooks;
  }
};

using sss::test::within1s;

void writeFile(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                              static_cast<std::streamsize>(bytes.size()));
}

TEST(SonarInputSource, RecognisesXtfFilesByTheirExtensionInAnyCase) {
  EXPECT_TRUE(isXtfPath("/data/line_01.xtf"));
  EXPECT_TRUE(isXtfPath("/data/LINE_01.XTF"));
  EXPECT_TRUE(isXtfPath("a.Xtf"));
  EXPECT_FALSE(isXtfPath("/data/line_01.jsf"));
  EXPECT_FALSE(isXtfPath(".xtf"));  // a name is needed before the extension
  EXPECT_FALSE(isXtfPath("xtf"));
  EXPECT_FALSE(isXtfPath("/data/line_01.xtf.gz"));
}

class SonarInputFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    stem_ = (fs::temp_directory_path() / ("sss_sonar_input_" + std::to_string(::getpid()))).string();
  }
  void TearDown() override {
    for (const char* extension : {".jsf", ".XTF", ".xtf"}) fs::remove(stem_ + extension);
  }
  std::string stem_;
  sss::core::HealthMonitor health_{0};
};

TEST_F(SonarInputFileTest, JsfReplayDeliversEveryPingInOrderOnTheSonarClockAndSaysWhenItIsDone) {
  constexpr int kPings = 100;  // ~250 kB: several 64 KiB reads
  const std::string path = stem_ + ".jsf";
  writeFile(path, test::concatenate(test::makeMessages(kPings)));
  SonarInputOptions options;
  options.replay_file = path;
  options.replay_speed = 0.0;
  options.replay_pings_per_step = 30;
  ASSERT_EQ(options.driver.time_source, TimeSource::kEstimateOffset);  // the live default
  Recorder recorder;
  SonarInputSource input(options, health_, recorder.hooks());
  ASSERT_OK(input.open());
  EXPECT_EQ(input.fd(), -1);
  EXPECT_EQ(input.stepPeriodS(), 0.002);

  input.step();
  EXPECT_EQ(recorder.pings.size(), 30u);  // at most replay_pings_per_step, however many are due
  ASSERT_TRUE(within1s([&] { input.step(); }, [&] { return input.done(); }));

  ASSERT_EQ(recorder.pings.size(), static_cast<size_t>(kPings));
  for (int p = 0; p < kPings; ++p) {
    const DriverPing& ping = recorder.pings[static_cast<size_t>(p)];
    EXPECT_EQ(ping.ping.ping_number, static_cast<uint32_t>(1000 + p));
    EXPECT_TRUE(ping.ping.complete());
    // A file has no arrival time to estimate a clock offset against: the sonar's time is used.
    EXPECT_EQ(ping.sonar_utime_us, test::makeRecord(static_cast<uint32_t>(1000 + p), 0).ping_time_us);
    EXPECT_EQ(ping.utime_us, ping.sonar_utime_us);
    EXPECT_GT(ping.ping.last_arrival_us, 0);  // the time it was handed over, for the latency figures
  }
  EXPECT_EQ(recorder.info, std::vector<std::string>({"replay of '" + path + "' finished: 100 pings"}));
  EXPECT_TRUE(recorder.warnings.empty());
  EXPECT_TRUE(recorder.faults.empty());
  // The last status has every ping of the file without waiting for the 1 Hz update.
  EXPECT_EQ(health_.counter("jsf_messages"), 2.0 * kPings);
  EXPECT_EQ(health_.counter("pings_complete"), kPings);
  EXPECT_EQ(health_.counter("pings_one_side_missing"), 0.0);
  EXPECT_EQ(health_.counter("pings_before_clock_estimate"), 0.0);
  EXPECT_EQ(input.driver().assemblerCounters().complete_pings, static_cast<uint64_t>(kPings));

  input.step();  // after the end: nothing more, and the end is said once
  EXPECT_EQ(recorder.pings.size(), static_cast<size_t>(kPings));
  EXPECT_EQ(recorder.info.size(), 1u);
}

TEST_F(SonarInputFileTest, JsfReplayHandsOverALoneLastSideAndReportsTheFaultBeforeTheLastLine) {
  auto messages = test::makeMessages(10);
  const size_t cut_offset = test::concatenate(messages).size() - messages.back().size();
  const size_t message_bytes = messages.back().size();
  messages.back().resize(200);  // ping 1009's starboard side ends with the file
  const std::string path = stem_ + ".jsf";
  writeFile(path, test::concatenate(messages));
  SonarInputOptions options;
  options.replay_file = path;
  options.replay_speed = 0.0;
  Recorder recorder;
  SonarInputSource input(options, health_, recorder.hooks());
  ASSERT_OK(input.open());
  ASSERT_TRUE(within1s([&] { input.step(); }, [&] { return input.done(); }));

  ASSERT_EQ(recorder.pings.size(), 10u);
  EXPECT_TRUE(recorder.pings[8].ping.complete());
  EXPECT_EQ(recorder.pings[9].ping.ping_number, 1009u);
  EXPECT_TRUE(recorder.pings[9].ping.port.has_value());
  EXPECT_FALSE(recorder.pings[9].ping.starboard.has_value());
  const std::string fault = "JSF message at byte " + std::to_string(cut_offset) + " ends with the stream after 200 of " +
                            std::to_string(message_bytes) + " bytes; dropped";
  EXPECT_EQ(recorder.events, std::vector<std::string>({"fault: " + fault,
                                                       "info: replay of '" + path + "' finished: 10 pings"}));
  EXPECT_EQ(health_.counter("jsf_truncated_messages"), 1.0);
  EXPECT_EQ(health_.counter("pings_one_side_missing"), 1.0);
  EXPECT_EQ(health_.counter("pings_complete"), 9.0);
}

TEST_F(SonarInputFileTest, JsfReplayKeepsTheRecordedPace) {
  const std::string path = stem_ + ".jsf";
  writeFile(path, test::concatenate(test::makeMessages(4)));  // pings 250 ms apart
  SonarInputOptions options;
  options.replay_file = path;
  options.replay_speed = 10.0;  // 25 ms apart
  Recorder recorder;
  SonarInputSource input(options, health_, recorder.hooks());
  ASSERT_OK(input.open());
  input.step();
  // The whole file is decoded, but only the first ping is due: the next one is 25 ms later.
  EXPECT_EQ(recorder.pings.size(), 1u);
  ASSERT_TRUE(within1s([&] { input.step(); }, [&] { return input.done(); }));
  ASSERT_EQ(recorder.pings.size(), 4u);
  for (size_t p = 1; p < 4; ++p) {
    EXPECT_GE(recorder.pings[p].ping.last_arrival_us - recorder.pings[0].ping.last_arrival_us,
              static_cast<int64_t>(p) * 25'000);
  }
}

TEST_F(SonarInputFileTest, MissingJsfFileSaysWhich) {
  SonarInputOptions options;
  options.replay_file = stem_ + ".jsf";
  Recorder recorder;
  SonarInputSource input(options, health_, recorder.hooks());
  EXPECT_EQ(input.open().message, "cannot open sonar file '" + stem_ + ".jsf'");
  input.step();  // harmless: the process exits instead
  EXPECT_FALSE(input.done());
  EXPECT_TRUE(recorder.pings.empty());
}

TEST_F(SonarInputFileTest, XtfReplayDeliversEveryPingWithTheFilesSummaryFaultsAndCounters) {
  const xtf::XtfWriterOptions writer = test::makeXtfOptions({100.0f}, 2);
  std::vector<uint8_t> bytes = xtf::encodeFileHeader(writer);
  size_t garbage_offset = 0;
  for (uint32_t p = 0; p < 12; ++p) {
    if (p == 6) {
      garbage_offset = bytes.size();
      bytes.insert(bytes.end(), 100, 0xAB);  // belongs to no packet
    }
    test::appendBytes(bytes, xtf::encodeSonarPacket(writer, test::makeXtfPing(writer, p)));
  }
  const std::string path = stem_ + ".XTF";  // the extension decides, in any case
  writeFile(path, bytes);
  SonarInputOptions options;
  options.replay_file = path;
  options.replay_speed = 0.0;
  Recorder recorder;
  SonarInputSource input(options, health_, recorder.hooks());
  ASSERT_OK(input.open());
  ASSERT_EQ(recorder.info.size(), 1u);  // the file's facts, said on opening
  EXPECT_EQ(recorder.info[0].rfind("XTF '" + path + "'", 0), 0u) << recorder.info[0];
  EXPECT_NE(recorder.info[0].find("0 pings"), std::string::npos) << recorder.info[0];
  ASSERT_TRUE(within1s([&] { input.step(); }, [&] { return input.done(); }));

  ASSERT_EQ(recorder.pings.size(), 12u);
  for (uint32_t p = 0; p < 12; ++p) {
    const DriverPing& ping = recorder.pings[p];
    EXPECT_EQ(ping.sonar_utime_us, test::kXtfFirstPingUs + test::kXtfPingPeriodUs * p);
    EXPECT_TRUE(ping.ping.complete());  // XTF packets carry both sides
    EXPECT_GT(ping.ping.last_arrival_us, 0);
  }
  ASSERT_EQ(recorder.info.size(), 3u);
  EXPECT_NE(recorder.info[1].find("12 pings"), std::string::npos) << recorder.info[1];
  EXPECT_NE(recorder.info[1].find("100 bytes skipped"), std::string::npos) << recorder.info[1];
  EXPECT_EQ(recorder.info[2], "replay of '" + path + "' finished: 12 pings");
  EXPECT_EQ(recorder.faults, std::vector<std::string>({"XTF '" + path + "' at byte " + std::to_string(garbage_offset) +
                                                       ": bytes that belong to no packet; skipping to the next "
                                                       "0xFACE packet"}));
  EXPECT_EQ(health_.counter("xtf_pings"), 12.0);
  EXPECT_EQ(health_.counter("xtf_bytes_skipped"), 100.0);
  EXPECT_EQ(health_.counter("xtf_corrupt_records"), 0.0);
  // The JSF driver is bypassed: its counters stay for the 1 Hz update to set.
  EXPECT_EQ(input.driver().parserCounters().messages, 0u);
}

TEST_F(SonarInputFileTest, MissingXtfFileSaysWhichAndWhy) {
  SonarInputOptions options;
  options.replay_file = stem_ + ".xtf";
  Recorder recorder;
  SonarInputSource input(options, health_, recorder.hooks());
  EXPECT_EQ(input.open().message, "cannot open XTF file '" + stem_ + ".xtf': No such file or directory");
  EXPECT_TRUE(recorder.info.empty());
}

using sss::test::boundPort;
using sss::test::boundSocket;

class SonarInputLinkTest : public ::testing::Test {
 protected:
  void SetUp() override {
    listener_ = boundSocket(SOCK_STREAM);
    ASSERT_EQ(::listen(listener_, 4), 0);
    options_.tcp.host = "127.0.0.1";
    options_.tcp.port = boundPort(listener_);
    options_.tcp.reconnect_min_s = 0.01;  // the default 0.2 s would only slow the test
    options_.driver.time_source = TimeSource::kSonarClock;  // a sonar on PTP: no offset to learn first
  }
  void TearDown() override { ::close(listener_); }

  // Steps the source until it connects; the accepted peer.
  int connect(SonarInputSource& input) {
    EXPECT_TRUE(within1s([&] { input.step(); }, [&] { return input.fd() >= 0; }));
    const int peer = ::accept4(listener_, nullptr, nullptr, SOCK_CLOEXEC);
    EXPECT_GE(peer, 0);
    return peer;
  }
  static void send(int peer, const std::vector<uint8_t>& bytes) {
    ASSERT_EQ(::send(peer, bytes.data(), bytes.size(), 0), static_cast<ssize_t>(bytes.size()));
  }
  sss::core::HealthSnapshot status() { return health_.snapshot(sss::core::monotonicUtime()); }

  int listener_ = -1;
  SonarInputOptions options_;
  sss::core::HealthMonitor health_{0};
};

TEST_F(SonarInputLinkTest, DeliversPingsAndReconnectsAfterThePeerCloses) {
  Recorder recorder;
  SonarInputSource input(options_, health_, recorder.hooks());
  ASSERT_OK(input.open());
  EXPECT_EQ(input.fd(), -1);  // connects in step(), not before
  EXPECT_EQ(input.stepPeriodS(), 0.05);

  const auto messages = test::makeMessages(5);
  const int first_peer = connect(input);
  const std::string connected = "sonar link: connected to 127.0.0.1:" + std::to_string(options_.tcp.port);
  EXPECT_EQ(status().state, sss::core::HealthState::kOk);
  EXPECT_EQ(status().state_text, connected);
  // Three pings, then the first 100 bytes of the fourth one's port side: the drop cuts it.
  std::vector<uint8_t> first = test::concatenate(std::vector<std::vector<uint8_t>>(messages.begin(), messages.begin() + 6));
  first.insert(first.end(), messages[6].begin(), messages[6].begin() + 100);
  send(first_peer, first);
  ASSERT_TRUE(within1s([&] { input.onReadable(); }, [&] { return recorder.pings.size() >= 3; }));
  ::close(first_peer);
  ASSERT_TRUE(within1s([&] { input.onReadable(); }, [&] { return input.fd() < 0; }));
  EXPECT_EQ(recorder.warnings, std::vector<std::string>({"sonar link: peer closed the connection"}));
  EXPECT_EQ(status().state, sss::core::HealthState::kWarning);
  EXPECT_EQ(status().state_text, "sonar link: peer closed the connection");
  // The cut message ends with its stream rather than swallowing the next link's first bytes.
  EXPECT_EQ(input.driver().parserCounters().truncated_messages, 1u);

  const int second_peer = connect(input);
  send(second_peer, test::concatenate(std::vector<std::vector<uint8_t>>(messages.begin() + 6, messages.end())));
  ASSERT_TRUE(within1s([&] { input.onReadable(); }, [&] { return recorder.pings.size() >= 5; }));
  input.step();
  ::close(second_peer);

  ASSERT_EQ(recorder.pings.size(), 5u);
  for (uint32_t p = 0; p < 5; ++p) {
    EXPECT_EQ(recorder.pings[p].ping.ping_number, 1000 + p);
    EXPECT_TRUE(recorder.pings[p].ping.complete());
    EXPECT_EQ(recorder.pings[p].utime_us, test::makeRecord(1000 + p, 0).ping_time_us);
  }
  EXPECT_EQ(recorder.info, std::vector<std::string>({connected, connected}));
  EXPECT_EQ(health_.counter("link_connects"), 2.0);
  EXPECT_EQ(health_.counter("link_disconnects"), 1.0);
  EXPECT_EQ(input.driver().parserCounters().bytes_skipped, 0u);
  EXPECT_FALSE(input.done());  // a link never ends by itself
  input.updateStatus();
  EXPECT_EQ(health_.counter("pings_complete"), 5.0);
  EXPECT_EQ(recorder.faults.size(), 1u);  // the cut message, once
}

TEST_F(SonarInputLinkTest, HandsOverALoneSideAfterTheMissingSideTimeout) {
  options_.driver.assembler.missing_side_timeout_s = 0.02;
  Recorder recorder;
  SonarInputSource input(options_, health_, recorder.hooks());
  ASSERT_OK(input.open());
  const int peer = connect(input);
  send(peer, test::encodeRecord(test::makeRecord(1000, kChannelPort), 500));  // the starboard side never comes
  ASSERT_TRUE(within1s([&] { input.onReadable(); }, [&] { return input.driver().parserCounters().messages >= 1; }));
  EXPECT_TRUE(recorder.pings.empty());  // waits for its other side first
  ASSERT_TRUE(within1s([&] { input.step(); }, [&] { return !recorder.pings.empty(); }));
  ::close(peer);

  ASSERT_EQ(recorder.pings.size(), 1u);
  EXPECT_EQ(recorder.pings[0].ping.ping_number, 1000u);
  EXPECT_TRUE(recorder.pings[0].ping.port.has_value());
  EXPECT_FALSE(recorder.pings[0].ping.starboard.has_value());
  input.updateStatus();
  EXPECT_EQ(health_.counter("pings_one_side_missing"), 1.0);
}

TEST_F(SonarInputLinkTest, RefusedConnectionIsAWarningNamingTheLink) {
  const int closed = boundSocket(SOCK_STREAM);  // bound, not listening: connections are refused
  options_.tcp.port = boundPort(closed);
  Recorder recorder;
  SonarInputSource input(options_, health_, recorder.hooks());
  ASSERT_OK(input.open());
  ASSERT_TRUE(within1s([&] { input.step(); }, [&] { return !recorder.warnings.empty(); }));
  ::close(closed);
  EXPECT_EQ(recorder.warnings[0].rfind("sonar link: ", 0), 0u) << recorder.warnings[0];
  EXPECT_NE(recorder.warnings[0].find("Connection refused"), std::string::npos) << recorder.warnings[0];
  EXPECT_EQ(status().state, sss::core::HealthState::kWarning);
  EXPECT_EQ(status().state_text, recorder.warnings[0]);
  EXPECT_EQ(input.fd(), -1);
  EXPECT_TRUE(recorder.info.empty());
  EXPECT_TRUE(recorder.pings.empty());
  EXPECT_EQ(health_.counter("link_connects"), 0.0);
}

}  // namespace
}  // namespace sss::edgetech
