// Translation between the subframe library's types and the LCM messages SSS_PING, SSS_NAV and
// SSS_SUBFRAME. The only subframe file that knows the LCM types.
#pragma once

#include "pipeline/subframe/ping_nav_fusion.hpp"
#include "pipeline/subframe/subframe_builder.hpp"
#include "sss_msgs/nav_t.hpp"
#include "sss_msgs/ping_t.hpp"
#include "sss_msgs/subframe_t.hpp"

namespace sss::subframe {

PingInput fromPingMessage(const sss_msgs::ping_t& message, int64_t arrival_monotonic_us = 0);
// Altitude is valid when VALID_ALTITUDE is set and STALE_ALTITUDE is not.
NavInput fromNavMessage(const sss_msgs::nav_t& message);

// Quantises the image: code = round(value / scale), scale = max_intensity / (2^bits - 1),
// little-endian for 16 bits. Angles of the mounting come from geometry.T_body_sonar.
sss_msgs::subframe_t toSubframeMessage(const Subframe& subframe, int intensity_bits, double max_intensity,
                                       float horizontal_beam_width_rad = 0.0f, float vertical_beam_width_rad = 0.0f);
// The inverse (matcher side); false with a reason when the message is inconsistent.
bool fromSubframeMessage(const sss_msgs::subframe_t& message, Subframe& subframe, std::string& error);

}  // namespace sss::subframe
