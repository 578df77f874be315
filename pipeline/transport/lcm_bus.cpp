// LCM adapter, see lcm_bus.hpp.
#include "pipeline/transport/lcm_bus.hpp"

#include <poll.h>
#include <spdlog/spdlog.h>

namespace sss::transport {

LcmBus::LcmBus(const std::string& url, sss::core::HealthMonitor& health)
    : health_(health), lcm_(std::make_unique<lcm::LCM>(url)) {
  if (!lcm_->good()) spdlog::error("LCM: cannot open '{}' (check the URL and the multicast route)", url);
}

int LcmBus::handleAvailable() {
  int handled = 0;
  pollfd fd{lcm_->getFileno(), POLLIN, 0};
  while (::poll(&fd, 1, 0) > 0 && (fd.revents & POLLIN)) {
    if (lcm_->handle() != 0) break;
    ++handled;
  }
  return handled;
}

void LcmBus::reportDecodeFailure(sss::core::HealthMonitor& health, const std::string& channel, uint32_t size) {
  health.recordDrop(channel, false);
  const std::string message = "LCM message on '" + channel + "' (" + std::to_string(size) +
                              " bytes) does not decode as the expected type; skipped";
  if (health.recordError("lcm_decode", message, sss::core::nowUtime())) {
    spdlog::warn("{} (further decode failures are counted in SSS_STATUS, not logged)", message);
  }
}

void LcmBus::reportPublishFailure(const std::string& channel) {
  const std::string message = "LCM publish on '" + channel + "' failed (message too large or socket error)";
  if (health_.recordError("lcm_publish", message, sss::core::nowUtime())) spdlog::error("{}", message);
}

}  // namespace sss::transport
