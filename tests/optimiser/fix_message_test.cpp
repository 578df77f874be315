// SSS_FIX end to end: the INS bridge's translation (drivers/ins/fix_message) over an LCM bus into
// the optimiser's (pipeline/optimiser/fix_message), and what the optimiser refuses.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "drivers/ins/fix_message.hpp"
#include "pipeline/core/health.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/optimiser/fix_message.hpp"
#include "pipeline/transport/lcm_bus.hpp"

namespace sss::optimiser {
namespace {

// Published and received on an in-process LCM bus, as between the two nodes.
std::optional<sss_msgs::fix_t> overTheBus(const sss_msgs::fix_t& message) {
  sss::core::HealthMonitor health(sss::core::monotonicUtime());
  sss::transport::LcmBus bus("memq://", health);
  std::optional<sss_msgs::fix_t> received;
  bus.subscribe<sss_msgs::fix_t>("SSS_FIX", [&](const sss_msgs::fix_t& m) { received = m; });
  bus.publish("SSS_FIX", message);
  bus.handleTimeout(100);
  return received;
}

sss::ins::AlignedFix usblFix() {
  sss::ins::AlignedFix fix;
  fix.fix.utime_us = 1780300860123456;
  fix.fix.source = sss::ins::FixSource::kUsbl;
  fix.fix.latitude_deg = 59.351;
  fix.fix.longitude_deg = 18.071;
  fix.fix.quality = 1;
  fix.position_ne_m = Eigen::Vector2d(111.25, 57.5);
  fix.covariance_m2 << 0.81, 0.02, 0.02, 1.21;
  fix.dr_position_m = Eigen::Vector3d(110.0, 58.0, 24.5);
  fix.dr_distance_m = 612.5;
  return fix;
}

TEST(FixMessage, BridgeToOptimiserOverLcm) {
  const sss::core::MissionOrigin origin{59.35, 18.07};
  const std::optional<sss_msgs::fix_t> received = overTheBus(sss::ins::toFixMessage(usblFix(), origin));
  ASSERT_TRUE(received);
  const sss_msgs::fix_t& message = *received;
  const sss::core::Result<AbsoluteFix> fix = fromFixMessage(message);
  ASSERT_TRUE(fix) << fix.message();
  EXPECT_EQ(fix->utime_us, 1780300860123456);
  EXPECT_EQ(fix->source, "usbl");
  EXPECT_EQ(fix->position_ne_m, Eigen::Vector2d(111.25, 57.5));
  EXPECT_EQ(fix->covariance_m2(0, 1), 0.02);
  EXPECT_EQ(fix->covariance_m2(1, 1), 1.21);
  EXPECT_EQ(fix->dr_position_m, Eigen::Vector3d(110.0, 58.0, 24.5));
  EXPECT_EQ(fix->dr_distance_m, 612.5);
  EXPECT_EQ(fixMessageOrigin(message).latitude_deg, 59.35);
  EXPECT_EQ(fixMessageOrigin(message).longitude_deg, 18.07);
}

TEST(FixMessage, UnusableMessagesAreRefusedWithTheReason) {
  const sss_msgs::fix_t good = sss::ins::toFixMessage(usblFix(), {59.35, 18.07});
  sss_msgs::fix_t m = good;
  m.source = "radio";
  sss::core::Result<AbsoluteFix> fix = fromFixMessage(m);
  EXPECT_FALSE(fix);
  EXPECT_NE(fix.message().find("neither gnss nor usbl"), std::string::npos) << fix.message();
  m = good;
  m.position_ne_m[0] = std::nan("");
  fix = fromFixMessage(m);
  EXPECT_FALSE(fix);
  EXPECT_NE(fix.message().find("not finite"), std::string::npos) << fix.message();
  m = good;
  m.covariance_ne_m2[1] = 5.0;  // not symmetric
  fix = fromFixMessage(m);
  EXPECT_FALSE(fix);
  EXPECT_NE(fix.message().find("positive definite"), std::string::npos) << fix.message();
  m = good;
  m.covariance_ne_m2[0] = -1.0;
  EXPECT_FALSE(fromFixMessage(m));
}

}  // namespace
}  // namespace sss::optimiser
