// The process skeleton every sss-slam service runs: one thread polls the LCM socket, extra file
// descriptors (TCP, UDP, serial) and timers; SIGINT/SIGTERM stop it gracefully; under systemd it
// sends READY, STATUS and WATCHDOG (from this loop, so a stuck handler makes systemd restart
// the process); every status period it publishes SSS_STATUS from the HealthMonitor.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/core/health.hpp"
#include "pipeline/transport/lcm_bus.hpp"
#include "pipeline/transport/process_options.hpp"
#include "pipeline/transport/systemd_notifier.hpp"
#include "sss_msgs/status_t.hpp"

namespace sss::transport {

class ProcessLoop {
 public:
  // Installs the SIGINT/SIGTERM handlers and opens the LCM URL.
  explicit ProcessLoop(ProcessOptions options);
  ~ProcessLoop();
  ProcessLoop(const ProcessLoop&) = delete;
  ProcessLoop& operator=(const ProcessLoop&) = delete;

  LcmBus& bus() { return bus_; }
  sss::core::HealthMonitor& health() { return health_; }
  const ProcessOptions& options() const { return options_; }

  // Calls callback every period_s (first call one period after run() starts).
  void addTimer(double period_s, std::function<void()> callback);
  // Calls on_readable when fd has data (or is closed/in error: POLLIN|POLLHUP|POLLERR).
  void addFileDescriptor(int fd, std::function<void()> on_readable);
  void removeFileDescriptor(int fd);
  // For a worker thread that hands results to the loop: returns a thread-safe notify(); after one
  // or more notify() calls the loop calls on_wake once, on its own thread. Empty when the kernel
  // refuses an eventfd (the caller says so and exits).
  std::function<void()> addWakeup(std::function<void()> on_wake);

  // Runs until stop() or a termination signal. Sends READY=1 first. Returns the exit code:
  // 0 after a graceful stop, 1 when the LCM URL could not be opened.
  int run();
  // Thread- and signal-safe request to leave run().
  void stop();
  bool stopRequested() const;

  // Faults a library reports once per kind (its takeNewFaultMessages()): each is counted as an
  // error of `kind` in SSS_STATUS and logged as a warning, so a bad input stream is visible
  // without flooding the log.
  void reportFaults(const std::string& kind, const std::vector<std::string>& faults);

  // Builds the status message of this process now (also used by tests).
  sss_msgs::status_t buildStatus();

 private:
  struct Timer {
    int64_t period_us;
    int64_t next_due_us;
    std::function<void()> callback;
  };
  struct WatchedFd {
    int fd;
    std::function<void()> on_readable;
  };

  void publishStatus();
  int64_t nextDeadlineUs() const;
  void runDueTimers(int64_t now_us);

  ProcessOptions options_;
  int64_t start_monotonic_us_;
  sss::core::HealthMonitor health_;
  LcmBus bus_;
  SystemdNotifier notifier_;
  std::vector<Timer> timers_;
  std::vector<WatchedFd> watched_fds_;
  int wake_fd_ = -1;  // eventfd written by stop() and the signal handler
  std::vector<int> wakeup_fds_;  // addWakeup()'s eventfds, closed with the loop
};

}  // namespace sss::transport
