// The process skeleton, see process_loop.hpp.
#include "pipeline/transport/process_loop.hpp"

#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>

#include "pipeline/core/time.hpp"

namespace sss::transport {

namespace {
// The signal handler may only touch async-signal-safe state: an atomic flag and a write().
std::atomic<int> g_wake_fd{-1};
std::atomic<bool> g_stop_requested{false};

void onTerminationSignal(int /*signal*/) {
  g_stop_requested.store(true);
  const int fd = g_wake_fd.load();
  if (fd >= 0) {
    const uint64_t one = 1;
    [[maybe_unused]] ssize_t written = ::write(fd, &one, sizeof(one));
  }
}

void installSignalHandlers() {
  struct sigaction action {};
  action.sa_handler = onTerminationSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  // A peer closing a TCP socket must be an error return, not a process kill.
  signal(SIGPIPE, SIG_IGN);
}
}  // namespace

ProcessLoop::ProcessLoop(ProcessOptions options)
    : options_(std::move(options)),
      start_monotonic_us_(sss::core::monotonicUtime()),
      health_(start_monotonic_us_),
      bus_(options_.lcm_url, health_) {
  wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  g_stop_requested.store(false);
  g_wake_fd.store(wake_fd_);
  installSignalHandlers();
  addTimer(options_.status_period_s, [this] { publishStatus(); });
  if (notifier_.watchdogIntervalUs() > 0) {
    // Ping at half the interval, as sd_watchdog_enabled(3) recommends.
    addTimer(static_cast<double>(notifier_.watchdogIntervalUs()) * 0.5e-6, [this] { notifier_.watchdog(); });
  }
}

ProcessLoop::~ProcessLoop() {
  g_wake_fd.store(-1);
  if (wake_fd_ >= 0) ::close(wake_fd_);
  for (const int fd : wakeup_fds_) ::close(fd);
}

void ProcessLoop::addTimer(double period_s, std::function<void()> callback) {
  const int64_t period_us = std::max<int64_t>(1000, sss::core::secondsToUtime(period_s));
  timers_.push_back({period_us, sss::core::monotonicUtime() + period_us, std::move(callback)});
}

void ProcessLoop::addFileDescriptor(int fd, std::function<void()> on_readable) {
  watched_fds_.push_back({fd, std::move(on_readable)});
}

std::function<void()> ProcessLoop::addWakeup(std::function<void()> on_wake) {
  const int fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (fd < 0) return {};
  wakeup_fds_.push_back(fd);
  addFileDescriptor(fd, [fd, on_wake = std::move(on_wake)] {
    uint64_t count = 0;
    if (::read(fd, &count, sizeof count) < 0) return;  // EAGAIN: another wake-up took it
    on_wake();
  });
  return [fd] {
    const uint64_t one = 1;
    if (::write(fd, &one, sizeof one) < 0) {
      // Saturated counter: the loop is already due to wake.
    }
  };
}

void ProcessLoop::removeFileDescriptor(int fd) {
  watched_fds_.erase(std::remove_if(watched_fds_.begin(), watched_fds_.end(),
                                    [fd](const WatchedFd& w) { return w.fd == fd; }),
                     watched_fds_.end());
}

void ProcessLoop::stop() {
  g_stop_requested.store(true);
  const uint64_t one = 1;
  [[maybe_unused]] ssize_t written = ::write(wake_fd_, &one, sizeof(one));
}

bool ProcessLoop::stopRequested() const { return g_stop_requested.load(); }

int64_t ProcessLoop::nextDeadlineUs() const {
  int64_t deadline = INT64_MAX;
  for (const Timer& timer : timers_) deadline = std::min(deadline, timer.next_due_us);
  return deadline;
}

void ProcessLoop::runDueTimers(int64_t now_us) {
  // Index loop: a callback may add timers.
  for (size_t i = 0; i < timers_.size(); ++i) {
    if (timers_[i].next_due_us > now_us) continue;
    // Skip missed periods instead of firing a burst after a stall.
    while (timers_[i].next_due_us <= now_us) timers_[i].next_due_us += timers_[i].period_us;
    timers_[i].callback();
  }
}

int ProcessLoop::run() {
  if (!bus_.good()) {
    spdlog::critical("{}: LCM URL '{}' could not be opened; exiting", options_.process_name, options_.lcm_url);
    return 1;
  }
  notifier_.ready(options_.process_name + " running");
  spdlog::info("{} running on {}", options_.process_name, options_.lcm_url);

  std::vector<pollfd> fds;
  while (!stopRequested()) {
    fds.clear();
    fds.push_back({wake_fd_, POLLIN, 0});
    fds.push_back({bus_.fileno(), POLLIN, 0});
    for (const WatchedFd& w : watched_fds_) fds.push_back({w.fd, POLLIN, 0});

    const int64_t now_us = sss::core::monotonicUtime();
    const int64_t wait_us = std::max<int64_t>(0, nextDeadlineUs() - now_us);
    const int timeout_ms = static_cast<int>(std::min<int64_t>((wait_us + 999) / 1000, 1000));
    const int ready = ::poll(fds.data(), fds.size(), timeout_ms);
    if (ready < 0 && errno != EINTR) {
      spdlog::critical("poll failed: {}", std::strerror(errno));
      return 1;
    }
    if (ready > 0) {
      if (fds[0].revents & POLLIN) {
        uint64_t value = 0;
        [[maybe_unused]] ssize_t n = ::read(wake_fd_, &value, sizeof(value));
      }
      if (fds[1].revents & POLLIN) bus_.handleAvailable();
      // Copy: a callback may add or remove descriptors.
      const std::vector<WatchedFd> watched = watched_fds_;
      for (size_t i = 0; i < watched.size() && i + 2 < fds.size(); ++i) {
        if (fds[i + 2].revents & (POLLIN | POLLHUP | POLLERR)) watched[i].on_readable();
      }
    }
    runDueTimers(sss::core::monotonicUtime());
  }
  notifier_.stopping();
  publishStatus();  // a last status so monitors see the stop
  spdlog::info("{} stopped", options_.process_name);
  return 0;
}

void ProcessLoop::reportFaults(const std::string& kind, const std::vector<std::string>& faults) {
  for (const std::string& fault : faults) {
    health_.recordError(kind, fault, sss::core::nowUtime());
    spdlog::warn("{} (further faults of this kind are counted in SSS_STATUS)", fault);
  }
}

sss_msgs::status_t ProcessLoop::buildStatus() {
  const sss::core::HealthSnapshot snap = health_.snapshot(sss::core::monotonicUtime());
  sss_msgs::status_t status;
  status.utime = sss::core::nowUtime();
  status.process = options_.process_name;
  status.pid = static_cast<int32_t>(::getpid());
  status.uptime_s = snap.uptime_s;
  status.state = static_cast<int8_t>(snap.state);
  status.state_text = snap.state_text;
  for (const sss::core::ChannelHealth& ch : snap.channels) {
    sss_msgs::channel_stats_t stats;
    stats.channel = ch.channel;
    stats.outgoing = ch.outgoing;
    stats.messages = ch.messages;
    stats.rate_hz = ch.rate_hz;
    stats.latency_p50_ms = ch.latency_p50_ms;
    stats.latency_p99_ms = ch.latency_p99_ms;
    stats.latency_max_ms = ch.latency_max_ms;
    stats.queue_depth = ch.queue_depth;
    stats.drops = ch.drops;
    status.channels.push_back(stats);
  }
  status.num_channels = static_cast<int32_t>(status.channels.size());
  for (const auto& [name, value] : snap.counters) {
    status.counter_name.push_back(name);
    status.counter_value.push_back(value);
  }
  status.num_counters = static_cast<int32_t>(status.counter_name.size());
  status.errors_total = snap.errors_total;
  status.last_error = snap.last_error;
  status.last_error_utime = snap.last_error_utime;
  return status;
}

void ProcessLoop::publishStatus() {
  const sss_msgs::status_t status = buildStatus();
  bus_.publish(options_.status_channel, status);
  notifier_.status(status.state_text + ", " + std::to_string(status.errors_total) + " errors");
}

}  // namespace sss::transport
