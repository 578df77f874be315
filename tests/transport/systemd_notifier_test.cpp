// sd_notify: a datagram socket bound as NOTIFY_SOCKET sees READY=1, STATUS= and WATCHDOG=1 from
// a running process loop, as systemd would.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <thread>
#include <string>
#include <vector>

#include "pipeline/transport/process_loop.hpp"

namespace sss::transport {
namespace {

class NotifySocket {
 public:
  NotifySocket() {
    path_ = "/tmp/sss-notify-" + std::to_string(getpid()) + ".sock";
    ::unlink(path_.c_str());
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_NONBLOCK, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::snprintf(address.sun_path, sizeof(address.sun_path), "%s", path_.c_str());
    bound_ = ::bind(fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0;
  }
  ~NotifySocket() {
    ::close(fd_);
    ::unlink(path_.c_str());
  }
  bool bound() const { return bound_; }
  const std::string& path() const { return path_; }
  // Reads datagrams until stop: like systemd, drains continuously (a unix datagram queue holds
  // only ~10, and sd_notify blocks when it is full).
  void receiveUntil(const std::atomic<bool>& stop) {
    char buffer[4096];
    while (!stop) {
      const ssize_t n = ::recv(fd_, buffer, sizeof(buffer), 0);
      if (n > 0) {
        datagrams_.emplace_back(buffer, static_cast<size_t>(n));
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
    }
  }
  std::vector<std::string> datagrams() {
    char buffer[4096];
    ssize_t n;
    while ((n = ::recv(fd_, buffer, sizeof(buffer), 0)) > 0) datagrams_.emplace_back(buffer, static_cast<size_t>(n));
    return datagrams_;
  }

 private:
  std::string path_;
  std::vector<std::string> datagrams_;
  int fd_ = -1;
  bool bound_ = false;
};

bool containsLine(const std::vector<std::string>& datagrams, const std::string& line) {
  for (const std::string& d : datagrams) {
    if (("\n" + d + "\n").find("\n" + line + "\n") != std::string::npos) return true;
  }
  return false;
}

TEST(SystemdNotifier, ProcessLoopSendsReadyStatusAndWatchdog) {
  NotifySocket socket;
  ASSERT_TRUE(socket.bound());
  ::setenv("NOTIFY_SOCKET", socket.path().c_str(), 1);
  ::setenv("WATCHDOG_USEC", "100000", 1);  // 100 ms: pings every 50 ms
  ::setenv("WATCHDOG_PID", std::to_string(getpid()).c_str(), 1);

  ProcessOptions options;
  options.process_name = "notify-test";
  options.lcm_url = "memq://";
  options.status_period_s = 0.1;
  std::atomic<bool> stop_receiving{false};
  std::thread receiver([&] { socket.receiveUntil(stop_receiving); });
  {
    ProcessLoop loop(options);
    loop.addTimer(0.35, [&] { loop.stop(); });
    EXPECT_EQ(loop.run(), 0);
  }
  stop_receiving = true;
  receiver.join();
  ::unsetenv("NOTIFY_SOCKET");
  ::unsetenv("WATCHDOG_USEC");
  ::unsetenv("WATCHDOG_PID");

  const std::vector<std::string> datagrams = socket.datagrams();
  ASSERT_FALSE(datagrams.empty());
  EXPECT_TRUE(containsLine(datagrams, "READY=1"));
  EXPECT_TRUE(containsLine(datagrams, "WATCHDOG=1"));
  EXPECT_TRUE(containsLine(datagrams, "STOPPING=1"));
  int watchdogs = 0;
  for (const std::string& d : datagrams) watchdogs += d == "WATCHDOG=1";
  EXPECT_GE(watchdogs, 4);  // 350 ms at one ping per 50 ms, with slack for a loaded host
  // READY comes first, with a status line naming the process.
  EXPECT_NE(datagrams.front().find("READY=1"), std::string::npos);
  EXPECT_NE(datagrams.front().find("STATUS=notify-test running"), std::string::npos);
}

TEST(SystemdNotifier, SilentWithoutSystemd) {
  ::unsetenv("NOTIFY_SOCKET");
  SystemdNotifier notifier;
  EXPECT_FALSE(notifier.underSystemd());
  EXPECT_EQ(notifier.watchdogIntervalUs(), 0);
  notifier.ready("x");  // must not crash or block
  notifier.watchdog();
}

}  // namespace
}  // namespace sss::transport
