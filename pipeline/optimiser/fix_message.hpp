// SSS_FIX (an absolute fix placed in the mission frame by the INS bridge) into the pose graph's
// AbsoluteFix. The only optimiser file that reads the LCM type.
#pragma once

#include <optional>
#include <string>

#include "pipeline/core/mission_origin.hpp"
#include "pipeline/optimiser/pose_graph.hpp"
#include "sss_msgs/fix_t.hpp"

namespace sss::optimiser {

// nullopt with the reason in error when the message is not usable: an unknown source, a non-finite
// field, a covariance that is not symmetric positive definite.
sss::core::Result<AbsoluteFix> fromFixMessage(const sss_msgs::fix_t& message);
// The mission origin the message's positions are in.
sss::core::MissionOrigin fixMessageOrigin(const sss_msgs::fix_t& message);

}  // namespace sss::optimiser
