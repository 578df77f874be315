// sd_notify integration: READY=1 after initialisation, STATUS= lines, WATCHDOG=1 pings. Silent
// no-ops when the process does not run under systemd (NOTIFY_SOCKET unset).
#pragma once

#include <cstdint>
#include <string>

namespace sss::transport {

class SystemdNotifier {
 public:
  SystemdNotifier();

  bool underSystemd() const { return under_systemd_; }
  // Watchdog interval requested by the unit (WatchdogSec), 0 when none.
  int64_t watchdogIntervalUs() const { return watchdog_interval_us_; }

  void ready(const std::string& status_text);
  void status(const std::string& status_text);
  void watchdog();
  void stopping();

 private:
  bool under_systemd_ = false;
  int64_t watchdog_interval_us_ = 0;
};

}  // namespace sss::transport
