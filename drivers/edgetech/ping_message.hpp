// Translation of a joined ping into the SSS_PING LCM message (used by the driver node and the
// offline runner). The only edgetech file that knows the LCM type.
#pragma once

#include "drivers/edgetech/sonar_driver.hpp"
#include "sss_msgs/ping_t.hpp"

namespace sss::edgetech {

sss_msgs::ping_t toPingMessage(const DriverPing& driver_ping);

}  // namespace sss::edgetech
