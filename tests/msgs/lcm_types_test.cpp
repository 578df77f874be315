// Every LCM type round-trips through memq://, and a message that does not decode is counted.
#include <gtest/gtest.h>

#include "message_fixtures.hpp"
#include "pipeline/core/health.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/transport/lcm_bus.hpp"

namespace sss::test {
namespace {

template <typename Message>
void expectRoundTrip(const Message& sent, const std::string& channel) {
  sss::core::HealthMonitor health(sss::core::monotonicUtime());
  sss::transport::LcmBus bus("memq://", health);
  ASSERT_TRUE(bus.good());
  std::vector<uint8_t> received_bytes;
  int received = 0;
  bus.subscribe<Message>(channel, [&](const Message& message) {
    received_bytes = encode(message);
    ++received;
  });
  ASSERT_TRUE(bus.publish(channel, sent));
  EXPECT_EQ(bus.handleAvailable(), 1);
  ASSERT_EQ(received, 1);
  // Byte equality of the re-encoded message covers every field and array.
  EXPECT_EQ(received_bytes, encode(sent));
  const sss::core::HealthSnapshot snap = health.snapshot(sss::core::monotonicUtime());
  ASSERT_EQ(snap.channels.size(), 2u);  // the channel in, then out
  EXPECT_EQ(snap.channels[0].messages, 1);
  EXPECT_EQ(snap.channels[1].messages, 1);
}

TEST(LcmTypes, PingRoundTrips) { expectRoundTrip(makePing(2000), "SSS_PING"); }
TEST(LcmTypes, NavRoundTrips) { expectRoundTrip(makeNav(), "SSS_NAV"); }
TEST(LcmTypes, SubframeRoundTrips) { expectRoundTrip(makeSubframe(20, 300), "SSS_SUBFRAME"); }
TEST(LcmTypes, LoopClosureRoundTrips) { expectRoundTrip(makeLoopClosure(), "SSS_LOOP"); }
TEST(LcmTypes, PoseRoundTrips) { expectRoundTrip(makePose(), "SSS_POSE"); }
TEST(LcmTypes, TrajectoryRoundTrips) { expectRoundTrip(makeTrajectory(), "SSS_TRAJECTORY"); }
TEST(LcmTypes, StatusRoundTrips) { expectRoundTrip(makeStatus(), "SSS_STATUS"); }

TEST(LcmTypes, FieldsSurviveDecode) {
  const sss_msgs::loop_closure_t sent = makeLoopClosure();
  const std::vector<uint8_t> bytes = encode(sent);
  sss_msgs::loop_closure_t decoded;
  ASSERT_EQ(decoded.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  EXPECT_EQ(decoded.subframe_id_b, 11);
  EXPECT_DOUBLE_EQ(decoded.covariance[5][5], 0.06);
  EXPECT_EQ(decoded.column_b[2], 1998);
  EXPECT_FLOAT_EQ(decoded.landmark_a_m[1][0], 1.0f);
}

TEST(LcmBus, WrongTypeOnAChannelIsCountedAndSkipped) {
  sss::core::HealthMonitor health(sss::core::monotonicUtime());
  sss::transport::LcmBus bus("memq://", health);
  int handled = 0;
  bus.subscribe<sss_msgs::nav_t>("SSS_NAV", [&](const sss_msgs::nav_t&) { ++handled; });
  bus.publish("SSS_NAV", makePose());  // another type: fingerprint mismatch
  const std::vector<uint8_t> garbage = {1, 2, 3};
  bus.lcm().publish("SSS_NAV", garbage.data(), static_cast<unsigned>(garbage.size()));  // truncated
  bus.publish("SSS_NAV", makeNav());
  bus.handleAvailable();
  EXPECT_EQ(handled, 1);
  const sss::core::HealthSnapshot snap = health.snapshot(sss::core::monotonicUtime());
  EXPECT_EQ(snap.errors_total, 2);
  EXPECT_NE(snap.last_error.find("does not decode"), std::string::npos);
  EXPECT_EQ(snap.channels[0].drops, 2);  // the incoming side
  EXPECT_FALSE(snap.channels[0].outgoing);
}

}  // namespace
}  // namespace sss::test
