// Translation of the LCM messages SSS_PING and SSS_NAV into the subframe stage's inputs. SSS_SUBFRAME,
// read by the matcher and the optimiser too, is in pipeline/messages/subframe_messages.hpp.
#pragma once

#include "pipeline/subframe/ping_nav_fusion.hpp"
#include "sss_msgs/nav_t.hpp"
#include "sss_msgs/ping_t.hpp"

namespace sss::subframe {

PingInput fromPingMessage(const sss_msgs::ping_t& message, int64_t arrival_monotonic_us = 0);
// Altitude is valid when VALID_ALTITUDE is set and STALE_ALTITUDE is not.
NavInput fromNavMessage(const sss_msgs::nav_t& message);

}  // namespace sss::subframe
