// sss-sonar-driver as a process, fed by the sonar emulator over TCP with corrupt bytes,
// truncated messages, dropped connections and pauses: it keeps running, publishes every good
// ping on LCM (counted against the file), says what was dropped, and stops cleanly on SIGTERM.
// The config names no record directory: the raw bytes go to $LOGS_DIRECTORY, as under systemd.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "jsf_test_data.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/transport/lcm_bus.hpp"
#include "sss_msgs/ping_t.hpp"
#include "sss_msgs/status_t.hpp"
#include "tools/emulators/recorded_streams.hpp"
#include "tests/support/status_assertions.hpp"

extern char** environ;

namespace sss::edgetech {
namespace {

TEST(SonarDriverLink, EveryGoodPingSurvivesALinkWithFaults) {
  const std::string dir = ::testing::TempDir();
  const std::string jsf_path = dir + "/link_test.jsf";
  constexpr int kPings = 240;
  {
    std::ofstream file(jsf_path, std::ios::binary);
    const auto bytes = test::concatenate(test::makeMessages(kPings, 800));
    file.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  const sss::core::Result<std::vector<emulators::TimedChunk>> loaded = emulators::loadJsfChunks(jsf_path);
  ASSERT_OK(loaded);
  const std::vector<emulators::TimedChunk>& chunks = *loaded;
  ASSERT_EQ(chunks.size(), 2u * kPings);

  emulators::StreamServerOptions server_options;
  server_options.port = 0;
  server_options.speed = 60.0;  // 60 s of pings in ~1 s
  server_options.faults.corrupt_every = 17;
  server_options.faults.truncate_every = 23;
  server_options.faults.drop_connection_every = 101;
  server_options.faults.pause_every = 150;
  server_options.faults.pause_s = 0.3;
  emulators::TcpStreamServer server(server_options, chunks);
  ASSERT_OK(server.listen());

  const int lcm_port = 19000 + static_cast<int>(getpid() % 2000);
  const std::string lcm_url = "udpm://239.255.76.67:" + std::to_string(lcm_port) + "?ttl=0&recv_buf_size=16777216";
  const std::string config_path = dir + "/link_test.yaml";
  {
    std::ofstream config(config_path);
    config << "sonar_driver:\n  host: 127.0.0.1\n  port: " << server.port()
           << "\n  lcm_url: \"" << lcm_url << "\"\n  time_source: sonar\n  reconnect_min_s: 0.05\n"
           << "  status_period_s: 0.2\n  log_level: warn\n";
  }

  sss::core::HealthMonitor health(sss::core::monotonicUtime());
  sss::transport::LcmBus bus(lcm_url, health);
  ASSERT_TRUE(bus.good());
  std::map<int64_t, int32_t> flags_by_ping;
  sss_msgs::status_t last_status;
  bus.subscribe<sss_msgs::ping_t>("SSS_PING", [&](const sss_msgs::ping_t& ping) { flags_by_ping[ping.ping_number] = ping.flags; });
  bus.subscribe<sss_msgs::status_t>("SSS_STATUS", [&](const sss_msgs::status_t& s) {
    if (s.process == "sss-sonar-driver") last_status = s;
  });

  // systemd's LogsDirectory= (sss-sonar-driver.service) arrives as $LOGS_DIRECTORY.
  const std::string logs_directory = dir + "/link_test_logs";
  std::filesystem::remove_all(logs_directory);
  std::vector<std::string> environment = {"LOGS_DIRECTORY=" + logs_directory};
  for (char** e = environ; *e != nullptr; ++e) {
    if (std::string(*e).rfind("LOGS_DIRECTORY=", 0) != 0) environment.emplace_back(*e);
  }
  std::vector<char*> envp;
  for (std::string& e : environment) envp.push_back(e.data());
  envp.push_back(nullptr);
  pid_t driver = 0;
  char* argv[] = {const_cast<char*>(SONAR_DRIVER_PATH), const_cast<char*>("--config"),
                  const_cast<char*>(config_path.c_str()), nullptr};
  ASSERT_EQ(posix_spawn(&driver, SONAR_DRIVER_PATH, nullptr, nullptr, argv, envp.data()), 0);

  std::atomic<bool> stop_server{false};
  std::thread server_thread([&] { server.run(stop_server); });
  std::atomic<bool> serving{true};
  std::thread watchdog([&] {
    const int64_t deadline = sss::core::monotonicUtime() + 30'000'000;
    while (serving && sss::core::monotonicUtime() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    stop_server = true;
  });
  // Receive while the server streams, then 1.5 s more for the last lone sides to time out.
  while (!stop_server && server_thread.joinable() && server.stats().chunks_sent + server.stats().chunks_faulted < chunks.size()) {
    bus.handleTimeout(50);
  }
  serving = false;
  server_thread.join();
  watchdog.join();
  const int64_t grace_end = sss::core::monotonicUtime() + 1'500'000;
  while (sss::core::monotonicUtime() < grace_end) bus.handleTimeout(50);

  ASSERT_EQ(::kill(driver, SIGTERM), 0);
  int status = 0;
  ::waitpid(driver, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "driver did not stop cleanly";

  // Which sides the emulator damaged: chunk i is ping i/2, side i%2.
  std::map<int64_t, int> damaged_sides;
  for (size_t i = 0; i < chunks.size(); ++i) {
    if ((i + 1) % 23 == 0) damaged_sides[1000 + static_cast<int64_t>(i / 2)] += 1;
  }
  const emulators::StreamStats& sent = server.stats();
  EXPECT_EQ(sent.chunks_faulted, damaged_sides.size());
  EXPECT_GE(sent.drops, 4u);
  EXPECT_GE(sent.connections, 5u);

  // Every ping had at least one good side: every ping is published; a damaged side is flagged.
  EXPECT_EQ(flags_by_ping.size(), static_cast<size_t>(kPings));
  for (int p = 0; p < kPings; ++p) {
    const int64_t number = 1000 + p;
    ASSERT_TRUE(flags_by_ping.count(number)) << "ping " << number << " lost";
    const bool one_side = damaged_sides.count(number) > 0;
    EXPECT_EQ(flags_by_ping[number] != 0, one_side) << "ping " << number;
  }
  // The status says what was dropped.
  std::map<std::string, double> counters;
  for (int i = 0; i < last_status.num_counters; ++i) counters[last_status.counter_name[i]] = last_status.counter_value[i];
  EXPECT_EQ(counters["jsf_truncated_messages"], static_cast<double>(damaged_sides.size()));
  EXPECT_EQ(counters["pings_one_side_missing"], static_cast<double>(damaged_sides.size()));
  EXPECT_GE(counters["jsf_bytes_skipped"], 64.0 * (sent.garbage_runs - 1));
  // After the emulator's last close the driver reconnects once more: the kernel completes the
  // connection into the listen backlog although the finished emulator accepts no more.
  EXPECT_GE(counters["link_connects"], static_cast<double>(sent.connections));
  EXPECT_LE(counters["link_connects"], static_cast<double>(sent.connections + 1));

  // Every byte received was recorded under $LOGS_DIRECTORY: the file's size, give or take the
  // garbage added and the halves cut by the emulator.
  uint64_t recorded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(logs_directory)) recorded += entry.file_size();
  EXPECT_EQ(static_cast<double>(recorded), counters["recorded_bytes"]);
  EXPECT_GT(recorded, std::filesystem::file_size(jsf_path) * 9 / 10);
  EXPECT_EQ(counters["record_errors"], 0.0);
}

}  // namespace
}  // namespace sss::edgetech
