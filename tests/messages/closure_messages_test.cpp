// SSS_LOOP and SSS_TRAJECTORY translation: round trip through the LCM encoding, and malformed
// messages rejected with a reason.
// lcm-gen's decode() reads its hash through an out-parameter GCC 12 cannot follow when inlined
// into a test body at -O3: a false positive in generated code.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include "pipeline/messages/closure_messages.hpp"

#include "tests/support/status_assertions.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace sss::messages {
namespace {

LoopClosure sampleClosure() {
  LoopClosure c;
  c.subframe_id_a = 3;
  c.subframe_id_b = 17;
  c.centre_utime_a_us = 1780300800000000;
  c.centre_utime_b_us = 1780300950000000;
  c.T_a_b = sss::core::Pose(sss::core::quaternionFromEuler(0.01, -0.02, 3.1), Eigen::Vector3d(1.5, -70.2, 0.3));
  for (int r = 0; r < 6; ++r) {
    for (int k = 0; k < 6; ++k) c.covariance(r, k) = r == k ? 0.01 * (r + 1) : 1e-4;
  }
  c.association_round = 1;
  c.num_matches = 1234;
  c.num_inliers = 987;
  c.range_cost = 0.8;
  c.plane_cost = 0.9;
  c.total_cost = 456.0;
  c.mean_zncc = 0.81f;
  for (int i = 0; i < 5; ++i) {
    ClosureCorrespondence cc;
    cc.ping_index_a = i;
    cc.column_a = 100 + i;
    cc.ping_index_b = 199 - i;
    cc.column_b = 2000 - i;
    cc.slant_range_a_m = 30.0f + i;
    cc.slant_range_b_m = 40.0f - i;
    cc.landmark_a_m = Eigen::Vector3f(i, 20.0f + i, 18.0f);
    c.correspondences.push_back(cc);
  }
  return c;
}

template <typename Message>
std::vector<uint8_t> encode(const Message& message) {
  std::vector<uint8_t> bytes(static_cast<size_t>(message.getEncodedSize()));
  EXPECT_EQ(message.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  return bytes;
}

TEST(LoopClosureMessage, RoundTripsThroughTheWire) {
  const LoopClosure c = sampleClosure();
  const std::vector<uint8_t> bytes = encode(toLoopClosureMessage(c, 42));
  sss_msgs::loop_closure_t message;
  ASSERT_EQ(message.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  EXPECT_EQ(message.utime, 42);
  const Result<LoopClosure> read = fromLoopClosureMessage(message);
  ASSERT_OK(read);
  const LoopClosure& back = read.value();
  EXPECT_EQ(back.subframe_id_a, 3);
  EXPECT_EQ(back.subframe_id_b, 17);
  EXPECT_EQ(back.centre_utime_b_us, c.centre_utime_b_us);
  EXPECT_LT((back.T_a_b.translation - c.T_a_b.translation).norm(), 1e-12);
  EXPECT_LT(back.T_a_b.rotation.angularDistance(c.T_a_b.rotation), 1e-12);
  EXPECT_LT((back.covariance - c.covariance).norm(), 1e-15);
  EXPECT_EQ(back.num_inliers, 987);
  EXPECT_FLOAT_EQ(back.mean_zncc, 0.81f);
  ASSERT_EQ(back.correspondences.size(), 5u);
  EXPECT_EQ(back.correspondences[4].column_b, 1996);
  EXPECT_FLOAT_EQ(back.correspondences[2].landmark_a_m.y(), 22.0f);
}

TEST(LoopClosureMessage, RejectsInconsistentArraysAndNonFinitePoses) {
  auto message = toLoopClosureMessage(sampleClosure(), 1);
  auto short_arrays = message;
  short_arrays.column_b.pop_back();
  const Result<LoopClosure> short_read = fromLoopClosureMessage(short_arrays);
  EXPECT_FALSE(short_read.ok());
  EXPECT_NE(short_read.message().find("num_correspondences"), std::string::npos);
  auto zero_quaternion = message;
  for (double& v : zero_quaternion.rotation_ab_wxyz) v = 0.0;
  EXPECT_FALSE(fromLoopClosureMessage(zero_quaternion).ok());
  auto nan_covariance = message;
  nan_covariance.covariance[2][3] = std::nan("");
  const Result<LoopClosure> nan_read = fromLoopClosureMessage(nan_covariance);
  EXPECT_FALSE(nan_read.ok());
  EXPECT_NE(nan_read.message().find("covariance"), std::string::npos);
}

TEST(TrajectoryMessage, RoundTripsAndRejectsBadNodes) {
  std::vector<TrajectoryNode> nodes(3);
  for (int i = 0; i < 3; ++i) {
    nodes[i].subframe_id = 10 + i;
    nodes[i].utime_us = 1000000 * i;
    nodes[i].T_world_body = sss::core::Pose(sss::core::quaternionFromEuler(0, 0, 0.5 * i), Eigen::Vector3d(i, 2.0 * i, 30));
  }
  const std::vector<uint8_t> bytes = encode(toTrajectoryMessage(nodes, 7));
  sss_msgs::trajectory_t message;
  ASSERT_EQ(message.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  const Result<std::vector<TrajectoryNode>> read = fromTrajectoryMessage(message);
  ASSERT_OK(read);
  const std::vector<TrajectoryNode>& back = read.value();
  ASSERT_EQ(back.size(), 3u);
  EXPECT_EQ(back[2].subframe_id, 12);
  EXPECT_LT((back[2].T_world_body.translation - nodes[2].T_world_body.translation).norm(), 1e-12);
  EXPECT_LT(back[1].T_world_body.rotation.angularDistance(nodes[1].T_world_body.rotation), 1e-12);
  auto bad = message;
  bad.position_ned_m[1][0] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(fromTrajectoryMessage(bad).ok());
  auto short_message = message;
  short_message.node_utime.pop_back();
  EXPECT_FALSE(fromTrajectoryMessage(short_message).ok());
}

}  // namespace
}  // namespace sss::messages
