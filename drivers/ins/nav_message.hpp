// Translation of a navigation sample into the SSS_NAV LCM message (INS bridge node and the
// offline runner). The only ins file that knows the LCM type.
#pragma once

#include "drivers/ins/ins_bridge.hpp"
#include "sss_msgs/nav_t.hpp"

namespace sss::ins {

// extra_stale: staleness flags to add (from the bridge's silence check).
sss_msgs::nav_t toNavMessage(const NavSample& sample, uint32_t extra_stale = 0);

}  // namespace sss::ins
