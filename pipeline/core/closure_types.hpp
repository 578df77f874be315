// Domain types the matcher hands on to the optimiser (and the optimiser back to the matcher):
// a loop closure with its inlier correspondences, and an optimised subframe-centre pose. They sit
// below the stages so that no stage includes another's headers; the LCM messages SSS_LOOP and
// SSS_TRAJECTORY carry them between processes.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "pipeline/core/pose.hpp"

namespace sss::core {

// An optimised subframe-centre pose (SSS_TRAJECTORY).
struct TrajectoryNode {
  int64_t subframe_id = 0;
  int64_t utime_us = 0;
  Pose T_world_body;
};

// An inlier correspondence of a closure (for the bathymetric point cloud).
struct ClosureCorrespondence {
  int ping_index_a = 0;
  int column_a = 0;
  int ping_index_b = 0;
  int column_b = 0;
  float slant_range_a_m = 0.0f;
  float slant_range_b_m = 0.0f;
  Eigen::Vector3f landmark_a_m = Eigen::Vector3f::Zero();  // in A's centre-ping body frame
};

// The relative pose of two subframes from their side-scan images (SSS_LOOP).
struct LoopClosure {
  int64_t subframe_id_a = 0;  // the older subframe
  int64_t subframe_id_b = 0;
  int64_t centre_utime_a_us = 0;
  int64_t centre_utime_b_us = 0;
  Pose T_a_b;                                  // B's centre body frame in A's
  Matrix6d covariance = Matrix6d::Zero();      // [dt, dr] at T_a_b
  int association_round = 0;                   // 0 = DR poses
  int num_matches = 0;
  int num_inliers = 0;
  double range_cost = 0.0;
  double plane_cost = 0.0;
  double total_cost = 0.0;
  float mean_zncc = 0.0f;
  std::vector<ClosureCorrespondence> correspondences;
};

}  // namespace sss::core
