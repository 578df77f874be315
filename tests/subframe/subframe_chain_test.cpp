// The front of the chain as separate processes over LCM udpm: a simulated 2-line mission is
// replayed by sss-sonar-driver (JSF) and sss-ins-bridge (iXblue NMEA) at 40x, and
// sss-subframe-buffer turns it into subframes that decode, follow each other within each line
// and cover the lines.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include "pipeline/core/time.hpp"
#include "pipeline/messages/subframe_messages.hpp"
#include "pipeline/transport/lcm_bus.hpp"
#include "tools/fixtures/spawn_process.hpp"

namespace sss::subframe {
namespace {

TEST(SubframeChain, SimulatedMissionThroughDriverBridgeAndBufferProcesses) {
  const std::string dir = ::testing::TempDir() + "/subframe_chain_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  // Two 200 m lines: ~100 s = ~400 pings each at 4 Hz, so two full subframes per line.
  ASSERT_EQ(sss::test::waitExitCode(sss::test::spawnProcess({SIM_PATH, "--out", dir, "--lines", "2", "--line-length-m", "200", "--seed", "5"})), 0);

  const std::string lcm_url =
      "udpm://239.255.76.67:" + std::to_string(25000 + getpid() % 2000) + "?ttl=0&recv_buf_size=16777216";
  const std::string config = dir + "/chain.yaml";
  {
    std::ofstream file(config);
    for (const char* section : {"sonar_driver", "ins_bridge", "subframe_buffer"}) {
      file << section << ":\n  lcm_url: \"" << lcm_url << "\"\n  log_level: warn\n";
    }
    file << "  idle_flush_s: 1.0\n";  // the last line's tail comes out 1 s after the last ping
  }
  sss::core::HealthMonitor health(sss::core::monotonicUtime());
  sss::transport::LcmBus bus(lcm_url, health);
  ASSERT_TRUE(bus.good());
  std::vector<sss::core::Subframe> subframes;
  int decode_failures = 0;
  bus.subscribe<sss_msgs::subframe_t>("SSS_SUBFRAME", [&](const sss_msgs::subframe_t& message) {
    sss::core::Result<sss::core::Subframe> subframe = sss::messages::fromSubframeMessage(message);
    if (subframe) {
      subframes.push_back(std::move(subframe).value());
    } else {
      ++decode_failures;
    }
  });

  const pid_t buffer = sss::test::spawnProcess({SUBFRAME_BUFFER_PATH, "--config", config});
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const pid_t bridge = sss::test::spawnProcess({INS_BRIDGE_PATH, "--config", config, "--file", dir + "/ins.nmea", "--speed", "40"});
  const pid_t driver = sss::test::spawnProcess({SONAR_DRIVER_PATH, "--config", config, "--file", dir + "/sonar.jsf", "--speed", "40"});
  ASSERT_GT(buffer, 0);
  ASSERT_GT(bridge, 0);
  ASSERT_GT(driver, 0);
  // The replays end by themselves (~40 s of mission time per second).
  const int64_t deadline = sss::core::monotonicUtime() + 60'000'000;
  int driver_exit = -2, bridge_exit = -2;
  while (sss::core::monotonicUtime() < deadline && (driver_exit == -2 || bridge_exit == -2)) {
    bus.handleTimeout(50);
    int status = 0;
    if (driver_exit == -2 && ::waitpid(driver, &status, WNOHANG) == driver) driver_exit = WEXITSTATUS(status);
    if (bridge_exit == -2 && ::waitpid(bridge, &status, WNOHANG) == bridge) bridge_exit = WEXITSTATUS(status);
  }
  const int64_t grace = sss::core::monotonicUtime() + 2'500'000;
  while (sss::core::monotonicUtime() < grace) bus.handleTimeout(50);
  ::kill(buffer, SIGTERM);
  EXPECT_EQ(sss::test::waitExitCode(buffer), 0);
  EXPECT_EQ(driver_exit, 0);
  EXPECT_EQ(bridge_exit, 0);
  std::filesystem::remove_all(dir);

  EXPECT_EQ(decode_failures, 0);
  ASSERT_GE(subframes.size(), 4u) << "two lines of ~400 pings give two full subframes each";
  std::map<int, std::vector<const sss::core::Subframe*>> by_line;
  for (size_t i = 0; i < subframes.size(); ++i) {
    if (i > 0) {
      EXPECT_GT(subframes[i].id, subframes[i - 1].id);
    }
    by_line[subframes[i].line_id].push_back(&subframes[i]);
  }
  EXPECT_EQ(by_line.size(), 2u);
  for (const auto& [line, of_line] : by_line) {
    EXPECT_EQ(of_line.front()->rows(), 200) << "line " << line;
    // Consecutive subframes of a line follow each other ping by ping.
    for (size_t k = 1; k < of_line.size(); ++k) {
      EXPECT_EQ(of_line[k]->pings.front().ping_number, of_line[k - 1]->pings.back().ping_number + 1) << "line " << line;
    }
  }
}

}  // namespace
}  // namespace sss::subframe
