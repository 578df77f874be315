// Translation between the shared closure types and the LCM messages SSS_LOOP and SSS_TRAJECTORY.
#include "pipeline/messages/closure_messages.hpp"

#include <cmath>

namespace sss::messages {
namespace {

bool finite(const double* values, int count) {
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(values[i])) return false;
  }
  return true;
}

// A quaternion from wxyz, false when it is not finite or has no length.
bool quaternionFrom(const double wxyz[4], Eigen::Quaterniond& q) {
  if (!finite(wxyz, 4)) return false;
  q = Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  if (q.norm() < 1e-6) return false;
  q.normalize();
  return true;
}

}  // namespace

sss_msgs::loop_closure_t toLoopClosureMessage(const LoopClosure& c, int64_t utime_us) {
  sss_msgs::loop_closure_t m;
  m.utime = utime_us;
  m.subframe_id_a = c.subframe_id_a;
  m.subframe_id_b = c.subframe_id_b;
  m.centre_utime_a = c.centre_utime_a_us;
  m.centre_utime_b = c.centre_utime_b_us;
  for (int i = 0; i < 3; ++i) m.translation_ab_m[i] = c.T_a_b.translation[i];
  m.rotation_ab_wxyz[0] = c.T_a_b.rotation.w();
  m.rotation_ab_wxyz[1] = c.T_a_b.rotation.x();
  m.rotation_ab_wxyz[2] = c.T_a_b.rotation.y();
  m.rotation_ab_wxyz[3] = c.T_a_b.rotation.z();
  for (int r = 0; r < 6; ++r) {
    for (int k = 0; k < 6; ++k) m.covariance[r][k] = c.covariance(r, k);
  }
  m.association_round = c.association_round;
  m.num_matches = c.num_matches;
  m.num_inliers = c.num_inliers;
  m.range_cost = c.range_cost;
  m.plane_cost = c.plane_cost;
  m.total_cost = c.total_cost;
  m.mean_zncc = c.mean_zncc;
  const size_t n = c.correspondences.size();
  m.num_correspondences = static_cast<int32_t>(n);
  m.ping_index_a.resize(n);
  m.column_a.resize(n);
  m.ping_index_b.resize(n);
  m.column_b.resize(n);
  m.slant_range_a_m.resize(n);
  m.slant_range_b_m.resize(n);
  m.landmark_a_m.assign(n, std::vector<float>(3, 0.0f));
  for (size_t i = 0; i < n; ++i) {
    const ClosureCorrespondence& cc = c.correspondences[i];
    m.ping_index_a[i] = cc.ping_index_a;
    m.column_a[i] = cc.column_a;
    m.ping_index_b[i] = cc.ping_index_b;
    m.column_b[i] = cc.column_b;
    m.slant_range_a_m[i] = cc.slant_range_a_m;
    m.slant_range_b_m[i] = cc.slant_range_b_m;
    for (int k = 0; k < 3; ++k) m.landmark_a_m[i][k] = cc.landmark_a_m[k];
  }
  return m;
}

Result<LoopClosure> fromLoopClosureMessage(const sss_msgs::loop_closure_t& m) {
  const size_t n = m.num_correspondences < 0 ? 0 : static_cast<size_t>(m.num_correspondences);
  if (m.num_correspondences < 0 || m.ping_index_a.size() != n || m.column_a.size() != n ||
      m.ping_index_b.size() != n || m.column_b.size() != n || m.slant_range_a_m.size() != n ||
      m.slant_range_b_m.size() != n || m.landmark_a_m.size() != n) {
    return Status::error("loop closure " + std::to_string(m.subframe_id_a) + "-" + std::to_string(m.subframe_id_b) +
                         ": correspondence arrays disagree with num_correspondences");
  }
  LoopClosure c;
  c.subframe_id_a = m.subframe_id_a;
  c.subframe_id_b = m.subframe_id_b;
  c.centre_utime_a_us = m.centre_utime_a;
  c.centre_utime_b_us = m.centre_utime_b;
  if (!finite(m.translation_ab_m, 3) || !quaternionFrom(m.rotation_ab_wxyz, c.T_a_b.rotation)) {
    return Status::error("loop closure " + std::to_string(m.subframe_id_a) + "-" + std::to_string(m.subframe_id_b) +
                         ": relative pose is not finite or its quaternion is zero");
  }
  c.T_a_b.translation = Eigen::Vector3d(m.translation_ab_m[0], m.translation_ab_m[1], m.translation_ab_m[2]);
  for (int r = 0; r < 6; ++r) {
    if (!finite(m.covariance[r], 6)) {
      return Status::error("loop closure " + std::to_string(m.subframe_id_a) + "-" + std::to_string(m.subframe_id_b) +
                           ": covariance is not finite");
    }
    for (int k = 0; k < 6; ++k) c.covariance(r, k) = m.covariance[r][k];
  }
  c.association_round = m.association_round;
  c.num_matches = m.num_matches;
  c.num_inliers = m.num_inliers;
  c.range_cost = m.range_cost;
  c.plane_cost = m.plane_cost;
  c.total_cost = m.total_cost;
  c.mean_zncc = m.mean_zncc;
  c.correspondences.resize(n);
  for (size_t i = 0; i < n; ++i) {
    ClosureCorrespondence& cc = c.correspondences[i];
    cc.ping_index_a = m.ping_index_a[i];
    cc.column_a = m.column_a[i];
    cc.ping_index_b = m.ping_index_b[i];
    cc.column_b = m.column_b[i];
    cc.slant_range_a_m = m.slant_range_a_m[i];
    cc.slant_range_b_m = m.slant_range_b_m[i];
    if (m.landmark_a_m[i].size() != 3) {
      return Status::error("loop closure: a landmark without 3 coordinates");
    }
    cc.landmark_a_m = Eigen::Vector3f(m.landmark_a_m[i][0], m.landmark_a_m[i][1], m.landmark_a_m[i][2]);
  }
  return c;
}

sss_msgs::trajectory_t toTrajectoryMessage(const std::vector<TrajectoryNode>& nodes, int64_t utime_us) {
  sss_msgs::trajectory_t m;
  m.utime = utime_us;
  const size_t n = nodes.size();
  m.num_nodes = static_cast<int32_t>(n);
  m.subframe_id.resize(n);
  m.node_utime.resize(n);
  m.position_ned_m.assign(n, std::vector<double>(3, 0.0));
  m.orientation_wxyz.assign(n, std::vector<double>(4, 0.0));
  for (size_t i = 0; i < n; ++i) {
    m.subframe_id[i] = nodes[i].subframe_id;
    m.node_utime[i] = nodes[i].utime_us;
    for (int k = 0; k < 3; ++k) m.position_ned_m[i][k] = nodes[i].T_world_body.translation[k];
    const Eigen::Quaterniond& q = nodes[i].T_world_body.rotation;
    m.orientation_wxyz[i] = {q.w(), q.x(), q.y(), q.z()};
  }
  return m;
}

Result<std::vector<TrajectoryNode>> fromTrajectoryMessage(const sss_msgs::trajectory_t& m) {
  const size_t n = m.num_nodes < 0 ? 0 : static_cast<size_t>(m.num_nodes);
  if (m.num_nodes < 0 || m.subframe_id.size() != n || m.node_utime.size() != n || m.position_ned_m.size() != n ||
      m.orientation_wxyz.size() != n) {
    return Status::error("trajectory: arrays disagree with num_nodes");
  }
  std::vector<TrajectoryNode> nodes;
  nodes.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    TrajectoryNode node;
    node.subframe_id = m.subframe_id[i];
    node.utime_us = m.node_utime[i];
    if (m.position_ned_m[i].size() != 3 || m.orientation_wxyz[i].size() != 4 || !finite(m.position_ned_m[i].data(), 3) ||
        !quaternionFrom(m.orientation_wxyz[i].data(), node.T_world_body.rotation)) {
      return Status::error("trajectory: node " + std::to_string(node.subframe_id) +
                           " has a non-finite pose or a zero quaternion");
    }
    node.T_world_body.translation = Eigen::Vector3d(m.position_ned_m[i][0], m.position_ned_m[i][1], m.position_ned_m[i][2]);
    nodes.push_back(node);
  }
  return nodes;
}

}  // namespace sss::messages
