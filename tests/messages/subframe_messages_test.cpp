// SSS_SUBFRAME translation: quantisation round trip (8 and 16 bits), geometry, poses and masks.
#include "pipeline/messages/subframe_messages.hpp"

#include "tests/support/status_assertions.hpp"

#include <gtest/gtest.h>

namespace sss::messages {
namespace {

Subframe smallSubframe() {
  Subframe s;
  s.id = 7;
  s.line_id = 2;
  s.geometry = sss::core::SubframeGeometry{3, 0.1, 0.5, sss::core::Pose(sss::core::quaternionFromEuler(0.0, 0.1, 0.0), Eigen::Vector3d(1, 0, 0.5))};
  for (int r = 0; r < 4; ++r) {
    SubframePing p;
    p.utime_us = 1000 + r;
    p.ping_number = 50 + r;
    p.T_world_body = sss::core::Pose(sss::core::quaternionFromEuler(0.01 * r, 0.0, 0.3), Eigen::Vector3d(r, 2, 3));
    p.altitude_m = 18.0 + r;
    s.pings.push_back(p);
  }
  s.centre_ping_index = 2;
  for (int i = 0; i < 24; ++i) {
    s.image.push_back(0.1f * i);
    s.mask.push_back(i % 6 == 0 ? sss::core::kMaskNadir : sss::core::kMaskValid);
  }
  return s;
}

TEST(SubframeMessage, RoundTripsWithinHalfAQuantisationStep) {
  const Subframe s = smallSubframe();
  for (int bits : {8, 16}) {
    const sss_msgs::subframe_t m = toSubframeMessage(s, bits, 4.0);
    EXPECT_EQ(m.num_image_bytes, 24 * bits / 8);
    EXPECT_EQ(m.utime, 1002);
    const Result<Subframe> read = fromSubframeMessage(m);
    ASSERT_OK(read);
    const Subframe& back = read.value();
    for (size_t i = 0; i < s.image.size(); ++i) {
      EXPECT_NEAR(back.image[i], std::min(s.image[i], 4.0f), 0.5 * m.intensity_scale + 1e-6);
    }
    EXPECT_EQ(back.mask, s.mask);
    EXPECT_EQ(back.centre().ping_number, 52);
    EXPECT_NEAR(back.pings[3].T_world_body.translation.x(), 3.0, 1e-12);
    EXPECT_TRUE(back.pings[1].T_world_body.rotation.isApprox(s.pings[1].T_world_body.rotation, 1e-12));
    EXPECT_NEAR(back.geometry.first_bin_range_m, 0.5, 1e-6);
    EXPECT_TRUE(back.geometry.T_body_sonar.rotation.isApprox(s.geometry.T_body_sonar.rotation, 1e-12));
  }
}

TEST(SubframeMessage, RejectsInconsistentSizes) {
  sss_msgs::subframe_t m = toSubframeMessage(smallSubframe(), 16, 4.0);
  m.image.pop_back();
  m.num_image_bytes -= 1;
  const Result<Subframe> read = fromSubframeMessage(m);
  EXPECT_FALSE(read.ok());
  EXPECT_NE(read.message().find("inconsistent"), std::string::npos);
}

}  // namespace
}  // namespace sss::messages
