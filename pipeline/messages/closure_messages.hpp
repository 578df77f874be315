// Translation between the shared closure types (pipeline/core/closure_types.hpp) and the LCM
// messages SSS_LOOP and SSS_TRAJECTORY, for the matcher and optimiser processes alike.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/closure_types.hpp"
#include "pipeline/core/status.hpp"
#include "sss_msgs/loop_closure_t.hpp"
#include "sss_msgs/trajectory_t.hpp"

namespace sss::messages {

using sss::core::ClosureCorrespondence;
using sss::core::LoopClosure;
using sss::core::Result;
using sss::core::Status;
using sss::core::TrajectoryNode;

sss_msgs::loop_closure_t toLoopClosureMessage(const LoopClosure& closure, int64_t utime_us);
// An error with the reason when the message is inconsistent (sizes, non-finite numbers, a zero quaternion).
Result<LoopClosure> fromLoopClosureMessage(const sss_msgs::loop_closure_t& message);

sss_msgs::trajectory_t toTrajectoryMessage(const std::vector<TrajectoryNode>& nodes, int64_t utime_us);
Result<std::vector<TrajectoryNode>> fromTrajectoryMessage(const sss_msgs::trajectory_t& message);

}  // namespace sss::messages
