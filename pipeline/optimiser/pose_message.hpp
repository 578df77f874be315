// Translation of a corrected navigation sample into SSS_POSE (LCM) and the DDS correction topic
// of the navigation computer. The only optimiser files that know the LCM and DDS types.
#pragma once

#include <cstdint>

#include "navigation_correction.h"
#include "pipeline/core/geodesy.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/optimiser/pose_graph.hpp"
#include "sss_msgs/pose_t.hpp"

namespace sss::optimiser {

// corrected = correction.T_corrected_dr * T_world_body_dr, for the nav sample at utime_us.
sss_msgs::pose_t toPoseMessage(int64_t utime_us, const sss::core::Pose& T_world_body_dr, const Correction& correction,
                               const sss::core::LocalTangentPlane& plane);

// The same corrected pose for the navigation computer. quality: 1 / (1 + horizontal sigma in m),
// 0 without any closure.
sss_dds_NavigationCorrection toDdsCorrection(const sss_msgs::pose_t& pose, uint32_t vehicle_id, int accepted_closures);

}  // namespace sss::optimiser
