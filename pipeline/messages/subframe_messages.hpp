// Translation between the shared subframe type (pipeline/core/subframe_types.hpp) and the LCM
// message SSS_SUBFRAME: the subframe buffer publishes it, the matcher and the optimiser read it.
#pragma once

#include <string>

#include "pipeline/core/status.hpp"
#include "pipeline/core/subframe_types.hpp"
#include "sss_msgs/subframe_t.hpp"

namespace sss::messages {

using sss::core::Subframe;
using sss::core::SubframePing;
using sss::core::Result;
using sss::core::Status;

// Quantises the image: code = round(value / scale), scale = max_intensity / (2^bits - 1),
// little-endian for 16 bits. Angles of the mounting come from geometry.T_body_sonar.
sss_msgs::subframe_t toSubframeMessage(const Subframe& subframe, int intensity_bits, double max_intensity,
                                       float horizontal_beam_width_rad = 0.0f, float vertical_beam_width_rad = 0.0f);
// The inverse (matcher side); an error with the reason when the message is inconsistent.
Result<Subframe> fromSubframeMessage(const sss_msgs::subframe_t& message);

}  // namespace sss::messages
