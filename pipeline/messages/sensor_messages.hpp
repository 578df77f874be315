// LCM translation of the sensor samples (pipeline/core/sensor_types.hpp): SSS_PING and SSS_NAV.
#pragma once

#include <cstdint>

#include "pipeline/core/sensor_types.hpp"
#include "sss_msgs/nav_t.hpp"
#include "sss_msgs/ping_t.hpp"

namespace sss::messages {

sss::core::PingSample fromPingMessage(const sss_msgs::ping_t& message, int64_t arrival_monotonic_us = 0);
// Altitude is valid when VALID_ALTITUDE is set and STALE_ALTITUDE is not. Before the INS's first fix
// (no VALID_POSITION, or the origin NaN) the sample has no position and no origin.
sss::core::NavSample fromNavMessage(const sss_msgs::nav_t& message);

}  // namespace sss::messages
