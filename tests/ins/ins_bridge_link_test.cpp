// sss-ins-bridge as a process, fed by the INS emulator over UDP with corrupted sentences and a
// pause: it publishes a nav sample per INS epoch, flags itself stale during the pause, recovers
// by itself when data returns, and stops cleanly on SIGTERM.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include "pipeline/core/mission_origin.hpp"

#include "ins_test_states.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/transport/lcm_bus.hpp"
#include "sss_msgs/nav_t.hpp"
#include "sss_msgs/status_t.hpp"
#include "tools/emulators/recorded_streams.hpp"
#include "tests/support/status_assertions.hpp"

extern char** environ;

namespace sss::ins {
namespace {

TEST(InsBridgeLink, PublishesEveryEpochGoesStaleInAPauseAndRecovers) {
  const std::string dir = ::testing::TempDir();
  const std::string ins_path = dir + "/ins_link_test.nmea";
  constexpr int kEpochs = 200;  // 20 s at 10 Hz
  {
    std::ofstream file(ins_path, std::ios::binary);
    file << test::eastboundStream(kEpochs);
  }
  const sss::core::Result<std::vector<emulators::TimedChunk>> loaded = emulators::loadInsChunks(ins_path);
  ASSERT_OK(loaded);
  const std::vector<emulators::TimedChunk>& chunks = *loaded;
  ASSERT_EQ(chunks.size(), static_cast<size_t>(kEpochs));

  const int udp_port = 21000 + static_cast<int>(getpid() % 2000);
  const int lcm_port = 23000 + static_cast<int>(getpid() % 2000);
  const std::string lcm_url = "udpm://239.255.76.67:" + std::to_string(lcm_port) + "?ttl=0";
  const std::string config_path = dir + "/ins_link_test.yaml";
  {
    std::ofstream config(config_path);
    config << "mission:\n  origin_latitude_deg: " << test::kOriginLatitudeDeg
           << "\n  origin_longitude_deg: " << test::kOriginLongitudeDeg << "\nins_bridge:\n  source: udp\n"
           << "  bind_address: 127.0.0.1\n  udp_port: " << udp_port << "\n  lcm_url: \"" << lcm_url
           << "\"\n  status_period_s: 0.1\n  log_level: warn\n";
  }
  sss::core::HealthMonitor health(sss::core::monotonicUtime());
  sss::transport::LcmBus bus(lcm_url, health);
  ASSERT_TRUE(bus.good());
  std::vector<int64_t> nav_times;
  std::vector<std::pair<int64_t, sss_msgs::status_t>> statuses;  // (monotonic receive time, status)
  bus.subscribe<sss_msgs::nav_t>("SSS_NAV", [&](const sss_msgs::nav_t& nav) { nav_times.push_back(nav.utime); });
  bus.subscribe<sss_msgs::status_t>("SSS_STATUS", [&](const sss_msgs::status_t& s) {
    if (s.process == "sss-ins-bridge") statuses.emplace_back(sss::core::monotonicUtime(), s);
  });

  pid_t bridge = 0;
  char* argv[] = {const_cast<char*>(INS_BRIDGE_PATH), const_cast<char*>("--config"),
                  const_cast<char*>(config_path.c_str()), nullptr};
  ASSERT_EQ(posix_spawn(&bridge, INS_BRIDGE_PATH, nullptr, nullptr, argv, environ), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the bridge binds its port

  emulators::StreamServerOptions sender_options;
  sender_options.bind_address = "127.0.0.1";
  sender_options.port = udp_port;
  sender_options.speed = 10.0;            // 20 s of INS in 2 s (plus the pause)
  sender_options.faults.flip_every = 9;   // a damaged sentence in every 9th burst
  sender_options.faults.pause_every = 100;
  sender_options.faults.pause_s = 2.0;    // the INS goes silent for 2 s after epoch 100
  emulators::UdpStreamSender sender(sender_options, chunks);
  std::atomic<bool> stop{false};
  int64_t pause_start_us = 0;
  std::thread send_thread([&] { EXPECT_OK(sender.run(stop)); });
  const int64_t deadline = sss::core::monotonicUtime() + 15'000'000;
  while (sss::core::monotonicUtime() < deadline && sender.stats().chunks_sent + sender.stats().chunks_faulted < chunks.size()) {
    bus.handleTimeout(20);
    if (pause_start_us == 0 && nav_times.size() >= 100) pause_start_us = sss::core::monotonicUtime();
  }
  send_thread.join();
  const int64_t end = sss::core::monotonicUtime() + 500'000;
  while (sss::core::monotonicUtime() < end) bus.handleTimeout(20);
  ::kill(bridge, SIGTERM);
  int status = 0;
  ::waitpid(bridge, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);

  // A flipped byte costs one sentence, not the epoch: one nav per INS epoch, in order.
  EXPECT_EQ(nav_times.size(), static_cast<size_t>(kEpochs));
  EXPECT_TRUE(std::is_sorted(nav_times.begin(), nav_times.end()));
  // During the pause the bridge says it is stale; after it, it is OK again by itself.
  bool stale_seen = false, recovered = false;
  for (const auto& [when, s] : statuses) {
    if (pause_start_us == 0 || when < pause_start_us) continue;
    if (s.state == sss_msgs::status_t::STATE_WARNING && s.state_text.find("heading") != std::string::npos) stale_seen = true;
    if (stale_seen && s.state == sss_msgs::status_t::STATE_OK) recovered = true;
  }
  EXPECT_TRUE(stale_seen);
  EXPECT_TRUE(recovered);
  ASSERT_FALSE(statuses.empty());
  const sss_msgs::status_t& last = statuses.back().second;
  double accepted_sentences = -1;
  for (int i = 0; i < last.num_counters; ++i) {
    if (last.counter_name[i] == "nmea_sentences") accepted_sentences = last.counter_value[i];
  }
  // 12 sentences per burst; a flipped byte costs at most the sentence it lands in (a bad
  // checksum, a missing '*HH', a bad character, garbage when it hits the '$'; nothing when it
  // hits the LF of a CRLF, which the CR still terminates).
  const double faulted = static_cast<double>(sender.stats().chunks_faulted);
  EXPECT_GE(faulted, 20.0);
  EXPECT_GE(accepted_sentences, 12.0 * kEpochs - faulted);
  EXPECT_LE(accepted_sentences, 12.0 * kEpochs - faulted / 2);  // most flips hit a sentence body
}

// No origin in the configuration: the bridge takes the first fix, saves it in its state directory
// and, restarted mid-mission, keeps it (the frame must not jump to wherever the vehicle is then).
TEST(InsBridgeLink, WithoutConfiguredOriginTheFirstFixIsKeptAcrossARestart) {
  const std::string dir = ::testing::TempDir() + "/ins_origin_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const int udp_port = 25000 + static_cast<int>(getpid() % 2000);
  const int lcm_port = 27000 + static_cast<int>(getpid() % 2000);
  const std::string lcm_url = "udpm://239.255.76.67:" + std::to_string(lcm_port) + "?ttl=0";
  const std::string config_path = dir + "/config.yaml";
  {
    std::ofstream config(config_path);
    config << "ins_bridge:\n  source: udp\n  bind_address: 127.0.0.1\n  udp_port: " << udp_port
           << "\n  lcm_url: \"" << lcm_url << "\"\n  state_directory: " << dir
           << "\n  status_period_s: 0.1\n  log_level: warn\n";
  }
  sss::core::HealthMonitor health(sss::core::monotonicUtime());
  sss::transport::LcmBus bus(lcm_url, health);
  ASSERT_TRUE(bus.good());
  std::vector<sss_msgs::nav_t> navs;
  bus.subscribe<sss_msgs::nav_t>("SSS_NAV", [&](const sss_msgs::nav_t& nav) { navs.push_back(nav); });
  double status_origin_latitude_deg = 0.0;
  bus.subscribe<sss_msgs::status_t>("SSS_STATUS", [&](const sss_msgs::status_t& status) {
    for (int i = 0; i < status.num_counters; ++i) {
      if (status.counter_name[i] == "origin_latitude_deg") status_origin_latitude_deg = status.counter_value[i];
    }
  });
  const int socket_fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(socket_fd, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<uint16_t>(udp_port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  // One bridge run: epochs [first, first + 20) as one datagram each, then SIGTERM.
  auto run = [&](int first) {
    navs.clear();
    pid_t bridge = 0;
    char* argv[] = {const_cast<char*>(INS_BRIDGE_PATH), const_cast<char*>("--config"),
                    const_cast<char*>(config_path.c_str()), nullptr};
    ASSERT_EQ(posix_spawn(&bridge, INS_BRIDGE_PATH, nullptr, nullptr, argv, environ), 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the bridge binds its port
    for (int e = first; e < first + 20; ++e) {
      const std::string burst = encodeInsState(test::eastboundState(e));
      ::sendto(socket_fd, burst.data(), burst.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
      bus.handleTimeout(10);
    }
    const int64_t end = sss::core::monotonicUtime() + 1'500'000;
    while (sss::core::monotonicUtime() < end && (navs.size() < 20 || status_origin_latitude_deg == 0.0)) {
      bus.handleTimeout(20);
    }
    ::kill(bridge, SIGTERM);
    int status = 0;
    ::waitpid(bridge, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  };
  run(0);
  ASSERT_GE(navs.size(), 18u) << "UDP on the loopback should lose nothing";
  const ins::InsState first_fix = test::eastboundState(0);
  EXPECT_NEAR(navs.front().origin_latitude_deg, first_fix.latitude_deg, 1e-8);
  EXPECT_NEAR(navs.front().origin_longitude_deg, first_fix.longitude_deg, 1e-8);
  EXPECT_NEAR(navs.front().position_ned_m[1], 0.0, 0.01);
  const auto saved = sss::core::readOriginState(dir + "/origin");
  ASSERT_TRUE(saved) << saved.message();
  EXPECT_DOUBLE_EQ(saved->latitude_deg, navs.front().origin_latitude_deg);
  EXPECT_DOUBLE_EQ(status_origin_latitude_deg, saved->latitude_deg) << "SSS_STATUS names the origin";

  run(50);  // restarted 5 s later, 10 m further east
  ASSERT_GE(navs.size(), 18u);
  EXPECT_DOUBLE_EQ(navs.front().origin_latitude_deg, saved->latitude_deg);
  EXPECT_DOUBLE_EQ(navs.front().origin_longitude_deg, saved->longitude_deg);
  EXPECT_NEAR(navs.front().position_ned_m[1], 10.0, 0.01) << "in the first run's frame";
  ::close(socket_fd);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sss::ins
