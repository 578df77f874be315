// A multi-megabyte subframe arrives intact over LCM udpm on the local host (ttl=0), with the
// receive buffer the default URL asks for. A separate port keeps parallel tests apart.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <thread>

#include "message_fixtures.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/transport/lcm_bus.hpp"

namespace sss::test {
namespace {

TEST(LcmUdpm, MultiMegabyteSubframeArrivesIntact) {
  const int port = 17000 + static_cast<int>(getpid() % 2000);
  const std::string url = "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=16777216";
  sss::core::HealthMonitor health(sss::core::monotonicUtime());
  sss::transport::LcmBus receiver(url, health);
  sss::transport::LcmBus sender(url, health);
  ASSERT_TRUE(receiver.good() && sender.good()) << "no multicast route on this host";

  const sss_msgs::subframe_t sent = makeSubframe(200, 3000);
  const std::vector<uint8_t> sent_bytes = encode(sent);
  ASSERT_GT(sent_bytes.size(), 3u * 1024 * 1024);

  std::atomic<bool> done{false};
  std::vector<uint8_t> received_bytes;
  receiver.subscribe<sss_msgs::subframe_t>("SSS_SUBFRAME", [&](const sss_msgs::subframe_t& message) {
    received_bytes = encode(message);
    done = true;
  });
  std::thread receive_thread([&] {
    const int64_t deadline = sss::core::monotonicUtime() + 5'000'000;
    while (!done && sss::core::monotonicUtime() < deadline) receiver.handleTimeout(100);
  });
  ASSERT_TRUE(sender.publish("SSS_SUBFRAME", sent));
  receive_thread.join();
  ASSERT_TRUE(done) << "subframe never arrived: is net.core.rmem_max large enough? (tools/setup-deps.sh raises it)";
  EXPECT_EQ(received_bytes, sent_bytes);
}

}  // namespace
}  // namespace sss::test
