// sss-sonar-driver --file on the real XTF in ../shared/data/real (an Iver2 AUV's Marine Sonic
// record, see its README): every ping reaches SSS_PING with its samples, time, position inside the
// file's lat/lon box and a plausible altitude, and the process ends by itself. Skipped when the
// file is absent.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/core/health.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/transport/lcm_bus.hpp"
#include "sss_msgs/ping_t.hpp"

extern char** environ;

namespace {

TEST(RealFileDriver, ReplaysEveryPingOfTheRealXtfOnLcm) {
  const std::string path = std::string(SSS_REAL_DATA_DIR) + "/scotsman-iver2.xtf";
  if (!std::filesystem::is_regular_file(path)) {
    GTEST_SKIP() << path << " is absent: the real-data tests need ../shared/data/real beside the repository";
  }
  const int lcm_port = 29000 + static_cast<int>(getpid() % 2000);
  const std::string lcm_url = "udpm://239.255.76.67:" + std::to_string(lcm_port) + "?ttl=0&recv_buf_size=16777216";
  sss::core::HealthMonitor health(sss::core::monotonicUtime());
  sss::transport::LcmBus bus(lcm_url, health);
  ASSERT_TRUE(bus.good());
  std::vector<sss_msgs::ping_t> pings;
  bus.subscribe<sss_msgs::ping_t>("SSS_PING", [&](const sss_msgs::ping_t& ping) { pings.push_back(ping); });

  pid_t driver = 0;
  // 52 s of record at 20x: ~2.6 s, ~180 pings/s on the loopback.
  char* argv[] = {const_cast<char*>(SONAR_DRIVER_PATH), const_cast<char*>("--file"), const_cast<char*>(path.c_str()),
                  const_cast<char*>("--speed"), const_cast<char*>("20"), const_cast<char*>("--lcm-url"),
                  const_cast<char*>(lcm_url.c_str()), nullptr};
  ASSERT_EQ(posix_spawn(&driver, SONAR_DRIVER_PATH, nullptr, nullptr, argv, environ), 0);
  int status = 0;
  bool exited = false;
  const int64_t deadline = sss::core::monotonicUtime() + 30'000'000;
  while (sss::core::monotonicUtime() < deadline) {
    bus.handleTimeout(20);
    if (!exited && ::waitpid(driver, &status, WNOHANG) == driver) {
      exited = true;
      const int64_t drain = sss::core::monotonicUtime() + 300'000;
      while (sss::core::monotonicUtime() < drain) bus.handleTimeout(20);
      break;
    }
  }
  if (!exited) {
    ::kill(driver, SIGKILL);
    ::waitpid(driver, &status, 0);
  }
  ASSERT_TRUE(exited) << "the driver should end by itself at the end of the file";
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  std::printf("real XTF replayed: %zu pings on SSS_PING\n", pings.size());
  ASSERT_GE(pings.size(), 455u) << "461 pings in the file; the loopback may drop a few under load";
  // The file's box (from its README: one 55 m line at 48.445 N 68.828 W) and its altitudes.
  int64_t previous_us = 0;
  for (const auto& ping : pings) {
    EXPECT_EQ(ping.num_port_samples, 1024);
    EXPECT_EQ(ping.num_starboard_samples, 1024);
    EXPECT_GT(ping.utime, previous_us);
    previous_us = ping.utime;
    if (ping.latitude_deg == 0.0) continue;  // the first ping has no position
    EXPECT_NEAR(ping.latitude_deg, 48.4455, 0.002);
    EXPECT_NEAR(ping.longitude_deg, -68.8280, 0.003);
    EXPECT_GT(ping.altitude_m, 2.0);
    EXPECT_LT(ping.altitude_m, 12.0);
  }
  // 0.04 s pings: 52 s of record.
  EXPECT_NEAR(1e-6 * static_cast<double>(pings.back().utime - pings.front().utime), 52.0, 2.0);
}

}  // namespace
