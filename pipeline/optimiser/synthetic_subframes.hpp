// Subframes (per-ping DR poses) and matcher closures with seabed correspondences on a synthetic
// lawnmower (synthetic_mission.hpp), for the optimiser engine's tests and the checkpoint benchmark.
#pragma once

#include <vector>

#include "pipeline/core/closure_types.hpp"
#include "pipeline/optimiser/synthetic_mission.hpp"
#include "pipeline/core/subframe_types.hpp"

namespace sss::optimiser::synthetic {

struct SubframeOptions {
  int pings_per_subframe = 200;
  double ping_spacing_m = 0.5;   // 2 m/s at 4 pings/s: a 100 m subframe of 200 pings
  double altitude_m = 18.0;      // above a flat seabed
  int correspondences_per_closure = 300;
  sss::core::Pose T_body_sonar = sss::core::Pose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1.0, 0.0, 0.3));
};

// One subframe per mission node (same id), pings along the node's heading, centre = middle ping;
// DR pings from the node's DR pose, no image. truth_pings[k][i] is the true pose of ping i of subframe k.
std::vector<sss::core::Subframe> makeSubframes(const Mission& mission, const SubframeOptions& options,
                                                   std::vector<std::vector<sss::core::Pose>>* truth_pings = nullptr);

// The matcher's closure for mission.closures[index]: its relative pose and covariance, and
// correspondences of seabed points between the two lines, seen from both subframes' true pings
// (slant ranges exact, the point in A's fan plane, within half a ping spacing of B's).
sss::core::LoopClosure makeMatcherClosure(const Mission& mission, size_t index,
                                             const std::vector<std::vector<sss::core::Pose>>& truth_pings,
                                             const SubframeOptions& options, int association_round = 0);

}  // namespace sss::optimiser::synthetic
