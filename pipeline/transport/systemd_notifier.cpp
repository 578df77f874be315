// sd_notify integration, see systemd_notifier.hpp.
#include "pipeline/transport/systemd_notifier.hpp"

#include <spdlog/spdlog.h>
#include <systemd/sd-daemon.h>

#include <cstdlib>

namespace sss::transport {

SystemdNotifier::SystemdNotifier() {
  under_systemd_ = std::getenv("NOTIFY_SOCKET") != nullptr;
  uint64_t interval_us = 0;
  // unset_environment = 0: a child process started by us must not inherit it, but we start none.
  if (sd_watchdog_enabled(0, &interval_us) > 0) watchdog_interval_us_ = static_cast<int64_t>(interval_us);
}

void SystemdNotifier::ready(const std::string& status_text) {
  if (!under_systemd_) return;
  if (sd_notifyf(0, "READY=1\nSTATUS=%s", status_text.c_str()) < 0) spdlog::warn("sd_notify READY failed");
}

void SystemdNotifier::status(const std::string& status_text) {
  if (under_systemd_) sd_notifyf(0, "STATUS=%s", status_text.c_str());
}

void SystemdNotifier::watchdog() {
  if (under_systemd_) sd_notify(0, "WATCHDOG=1");
}

void SystemdNotifier::stopping() {
  if (under_systemd_) sd_notify(0, "STOPPING=1");
}

}  // namespace sss::transport
