// LCM adapter: typed publish/subscribe over one lcm::LCM instance. Every message in or out is
// recorded in the process's HealthMonitor (count, handler latency); a message that does not
// decode is counted, logged once and skipped, never passed on.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <functional>
#include <memory>
#include <string>

#include "pipeline/core/health.hpp"
#include "pipeline/core/time.hpp"

namespace sss::transport {

class LcmBus {
 public:
  LcmBus(const std::string& url, sss::core::HealthMonitor& health);
  LcmBus(const LcmBus&) = delete;
  LcmBus& operator=(const LcmBus&) = delete;

  // False when the URL could not be opened (bad URL, no multicast route, ...).
  bool good() const { return lcm_->good(); }
  int fileno() { return lcm_->getFileno(); }
  lcm::LCM& lcm() { return *lcm_; }

  template <typename Message>
  void subscribe(const std::string& channel, std::function<void(const Message&)> handler) {
    handlers_.push_back(std::make_unique<Handler<Message>>(channel, std::move(handler), health_));
    // The C API directly: lcm-cpp 1.3.1's member-function subscription trips UBSan's vptr check.
    lcm_subscribe(lcm_->getUnderlyingLCM(), channel.c_str(), &HandlerBase::onMessage, handlers_.back().get());
  }

  // The latency recorded for the channel is the time from since_monotonic_us (e.g. the arrival
  // of the data the message was made from) to the end of the publish; by default the publish.
  template <typename Message>
  bool publish(const std::string& channel, const Message& message, int64_t since_monotonic_us = -1) {
    const int64_t start_us = since_monotonic_us >= 0 ? since_monotonic_us : sss::core::monotonicUtime();
    const int result = lcm_->publish(channel, &message);
    health_.recordMessage(channel, true, sss::core::monotonicUtime() - start_us);
    if (result != 0) {
      health_.recordDrop(channel, true);
      reportPublishFailure(channel);
      return false;
    }
    return true;
  }

  // Handles every message already waiting, without blocking. Returns the number handled.
  int handleAvailable();
  // Waits up to timeout_ms for one message and handles it; 0 on timeout, < 0 on error.
  int handleTimeout(int timeout_ms) { return lcm_->handleTimeout(timeout_ms); }

 private:
  struct HandlerBase {
    HandlerBase(std::string channel, sss::core::HealthMonitor& health) : channel_(std::move(channel)), health_(health) {}
    virtual ~HandlerBase() = default;
    virtual void dispatch(const lcm_recv_buf_t* buffer) = 0;
    static void onMessage(const lcm_recv_buf_t* buffer, const char* /*channel*/, void* user_data) {
      HandlerBase* self = static_cast<HandlerBase*>(user_data);
      const int64_t start_us = sss::core::monotonicUtime();
      self->dispatch(buffer);
      self->health_.recordMessage(self->channel_, false, sss::core::monotonicUtime() - start_us);
    }
    std::string channel_;
    sss::core::HealthMonitor& health_;
  };

  template <typename Message>
  struct Handler : HandlerBase {
    Handler(std::string channel, std::function<void(const Message&)> handler, sss::core::HealthMonitor& health)
        : HandlerBase(std::move(channel), health), handler_(std::move(handler)) {}
    void dispatch(const lcm_recv_buf_t* buffer) override {
      // decode() checks the type fingerprint and every array length against the buffer size.
      if (message_.decode(buffer->data, 0, static_cast<int>(buffer->data_size)) < 0) {
        reportDecodeFailure(health_, channel_, buffer->data_size);
        return;
      }
      handler_(message_);
    }
    std::function<void(const Message&)> handler_;
    Message message_;  // reused: no allocation per message once arrays have grown
  };

  static void reportDecodeFailure(sss::core::HealthMonitor& health, const std::string& channel, uint32_t size);
  void reportPublishFailure(const std::string& channel);

  sss::core::HealthMonitor& health_;
  std::unique_ptr<lcm::LCM> lcm_;
  std::vector<std::unique_ptr<HandlerBase>> handlers_;
};

}  // namespace sss::transport
