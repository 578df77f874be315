// The process skeleton: timers, file descriptors, graceful stop on SIGTERM, 1 Hz status.
#include "pipeline/transport/process_loop.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <functional>
#include <thread>

#include "pipeline/core/time.hpp"
#include "sss_msgs/nav_t.hpp"

namespace sss::transport {
namespace {

ProcessOptions testOptions(double status_period_s = 0.05) {
  ProcessOptions options;
  options.process_name = "test-process";
  options.lcm_url = "memq://";
  options.status_period_s = status_period_s;
  return options;
}

TEST(ProcessLoop, TimersFireAtTheirPeriodAndStopEndsRun) {
  ProcessLoop loop(testOptions(10.0));
  int ticks = 0;
  const int64_t start_us = sss::core::monotonicUtime();
  loop.addTimer(0.02, [&] {
    if (++ticks == 10) loop.stop();
  });
  EXPECT_EQ(loop.run(), 0);
  const double elapsed_s = sss::core::utimeToSeconds(sss::core::monotonicUtime() - start_us);
  EXPECT_EQ(ticks, 10);
  EXPECT_GE(elapsed_s, 0.19);  // 10 periods of 20 ms
  EXPECT_LT(elapsed_s, 2.0);
}

TEST(ProcessLoop, SigtermStopsGracefullyWithExitCodeZero) {
  ProcessLoop loop(testOptions());
  loop.addTimer(0.05, [] { ::raise(SIGTERM); });
  EXPECT_EQ(loop.run(), 0);
  EXPECT_TRUE(loop.stopRequested());
}

TEST(ProcessLoop, PublishesStatusWithChannelFigures) {
  ProcessLoop loop(testOptions(0.05));
  std::vector<sss_msgs::status_t> statuses;
  int navs = 0;
  loop.bus().subscribe<sss_msgs::nav_t>("SSS_NAV", [&](const sss_msgs::nav_t&) { ++navs; });
  loop.bus().subscribe<sss_msgs::status_t>("SSS_STATUS", [&](const sss_msgs::status_t& s) {
    statuses.push_back(s);
    if (statuses.size() == 3) loop.stop();
  });
  loop.health().incrementCounter("pings_dropped", 2);
  for (int i = 0; i < 5; ++i) loop.bus().publish("SSS_NAV", sss_msgs::nav_t{});
  EXPECT_EQ(loop.run(), 0);
  ASSERT_GE(statuses.size(), 3u);
  EXPECT_EQ(navs, 5);
  const sss_msgs::status_t& status = statuses[0];
  EXPECT_EQ(status.process, "test-process");
  EXPECT_EQ(status.pid, getpid());
  EXPECT_EQ(status.state, sss_msgs::status_t::STATE_OK);
  bool found_nav = false;
  for (const auto& ch : status.channels) {
    if (ch.channel == "SSS_NAV" && !ch.outgoing) {
      found_nav = true;
      EXPECT_EQ(ch.messages, 5);
    }
  }
  EXPECT_TRUE(found_nav);
  ASSERT_EQ(status.num_counters, 1);
  EXPECT_EQ(status.counter_name[0], "pings_dropped");
  EXPECT_DOUBLE_EQ(status.counter_value[0], 2.0);
}

TEST(ProcessLoop, ReportedFaultsAreCountedInTheStatus) {
  ProcessLoop loop(testOptions(10.0));
  loop.reportFaults("jsf_input", {"JSF message at byte 10: bad header", "JSF stream at byte 99: garbage"});
  loop.reportFaults("jsf_input", {});
  const sss_msgs::status_t status = loop.buildStatus();
  EXPECT_EQ(status.errors_total, 2);
  EXPECT_EQ(status.last_error, "JSF stream at byte 99: garbage");
  ASSERT_EQ(status.num_counters, 1);
  EXPECT_EQ(status.counter_name[0], "error.jsf_input");
  EXPECT_DOUBLE_EQ(status.counter_value[0], 2.0);
}

TEST(ProcessLoop, ReadableFileDescriptorCallsItsHandler) {
  ProcessLoop loop(testOptions(10.0));
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  std::string received;
  loop.addFileDescriptor(fds[0], [&] {
    char buffer[16];
    const ssize_t n = ::read(fds[0], buffer, sizeof(buffer));
    if (n > 0) received.append(buffer, static_cast<size_t>(n));
    loop.stop();
  });
  ASSERT_EQ(::write(fds[1], "ping", 4), 4);
  EXPECT_EQ(loop.run(), 0);
  EXPECT_EQ(received, "ping");
  ::close(fds[0]);
  ::close(fds[1]);
}

// A worker thread's notify() wakes the loop, which then runs on_wake on its own thread; notifies
// that come before the loop gets to them are taken by one call.
TEST(ProcessLoop, WakeupFromAnotherThreadRunsOnTheLoopsThread) {
  ProcessLoop loop(testOptions(10.0));
  const std::thread::id loop_thread = std::this_thread::get_id();
  int wakes = 0;
  bool on_loop_thread = true;
  const std::function<void()> notify = loop.addWakeup([&] {
    ++wakes;
    on_loop_thread = on_loop_thread && std::this_thread::get_id() == loop_thread;
    loop.stop();
  });
  ASSERT_TRUE(notify);
  std::thread worker([&] {
    notify();
    notify();
    notify();
  });
  worker.join();  // three notifies before the loop runs
  EXPECT_EQ(loop.run(), 0);
  EXPECT_EQ(wakes, 1);
  EXPECT_TRUE(on_loop_thread);
}

TEST(ProcessLoop, UnopenableLcmUrlExitsWithAnError) {
  ProcessOptions options = testOptions();
  options.lcm_url = "nosuchprovider://";
  ProcessLoop loop(options);
  EXPECT_EQ(loop.run(), 1);
}

TEST(ProcessOptions, ReadsAndValidatesTheSharedKeys) {
  sss::core::Config config = sss::core::Config::fromString(
      "driver:\n  lcm_url: \"udpm://239.255.76.67:7667?ttl=0\"\n  status_period_s: 0.0\n  log_level: loud\n");
  sss::core::ConfigSection section = config.section("driver");
  ProcessOptions options;
  readProcessOptions(section, options);
  EXPECT_EQ(options.lcm_url, "udpm://239.255.76.67:7667?ttl=0");
  ASSERT_EQ(config.problems().size(), 2u);
  EXPECT_EQ(config.problems()[0].key, "driver.status_period_s");
  EXPECT_EQ(config.problems()[1].message(),
            "config key 'driver.log_level' = loud: not allowed; expected one of {trace, debug, info, warn, error, "
            "critical, off}");
}

}  // namespace
}  // namespace sss::transport
