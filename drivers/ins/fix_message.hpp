// Translation of an aligned position fix into the SSS_FIX LCM message (INS bridge node). The
// optimiser reads it back with pipeline/optimiser/fix_message.hpp.
#pragma once

#include "drivers/ins/fix_aligner.hpp"
#include "sss_msgs/fix_t.hpp"

namespace sss::ins {

sss_msgs::fix_t toFixMessage(const AlignedFix& fix, const sss::core::MissionOrigin& origin);

}  // namespace sss::ins
