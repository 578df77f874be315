// Helpers the pose graph's translation units share (pose_graph.cpp, pose_graph_solve.cpp,
// pose_graph_closures.cpp); not part of the public interface.
#pragma once

#include <cmath>

#include "pipeline/optimiser/pose_graph.hpp"

namespace sss::optimiser {

// The names every pose-graph file uses (these files only include this header).
using sss::core::Matrix6d;
using sss::core::Pose;
using sss::core::Vector6d;

namespace internal {

// Whitening of the first node's anchor: its horizontal sigma north and east as the graph holds it
// (SlidingWindowPoseGraph::firstNodeHorizontalSigma), first_node_sigma_m in depth.
inline Matrix6d firstNodeSqrtInformation(const PoseGraphOptions& o, const Eigen::Vector2d& horizontal_sigma_ne_m) {
  Vector6d inverse_sigma;
  const double m = 1.0 / o.first_node_sigma_m, r = 1.0 / o.first_node_sigma_rad;
  inverse_sigma << 1.0 / horizontal_sigma_ne_m(0), 1.0 / horizontal_sigma_ne_m(1), m, r, r, r;
  return inverse_sigma.asDiagonal();
}

// 1 / sigma of the INS absolute factor's depth, roll, pitch and heading (0: not used).
inline Eigen::Vector4d insAbsoluteWeights(const PoseGraphOptions& o) {
  auto weight = [](double sigma) { return sigma > 0.0 ? 1.0 / sigma : 0.0; };
  return Eigen::Vector4d(weight(o.absolute_depth_sigma_m), weight(o.absolute_roll_pitch_sigma_rad),
                         weight(o.absolute_roll_pitch_sigma_rad), weight(o.absolute_heading_sigma_rad));
}

inline bool finitePose(const Pose& pose) {
  return pose.translation.allFinite() && pose.rotation.coeffs().allFinite() &&
         std::abs(pose.rotation.norm() - 1.0) < 1e-3;
}

inline Pose normalisedPose(const Pose& pose) {
  Pose out = pose;
  out.rotation.normalize();
  return out;
}

}  // namespace internal

using internal::finitePose;
using internal::firstNodeSqrtInformation;
using internal::insAbsoluteWeights;
using internal::normalisedPose;

}  // namespace sss::optimiser
