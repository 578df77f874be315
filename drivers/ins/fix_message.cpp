// SSS_FIX translation, see fix_message.hpp.
#include "drivers/ins/fix_message.hpp"

namespace sss::ins {

sss_msgs::fix_t toFixMessage(const AlignedFix& fix, const sss::core::MissionOrigin& origin) {
  sss_msgs::fix_t m{};
  m.utime = fix.fix.utime_us;
  m.source = fixSourceName(fix.fix.source);
  m.latitude_deg = fix.fix.latitude_deg;
  m.longitude_deg = fix.fix.longitude_deg;
  m.position_ne_m[0] = fix.position_ne_m.x();
  m.position_ne_m[1] = fix.position_ne_m.y();
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 2; ++c) m.covariance_ne_m2[2 * r + c] = fix.covariance_m2(r, c);
  m.origin_latitude_deg = origin.latitude_deg;
  m.origin_longitude_deg = origin.longitude_deg;
  for (int i = 0; i < 3; ++i) m.dr_position_ned_m[i] = fix.dr_position_m(i);
  m.dr_distance_travelled_m = fix.dr_distance_m;
  m.quality = fix.fix.quality;
  m.satellites = fix.fix.satellites;
  m.hdop = fix.fix.hdop;
  return m;
}

}  // namespace sss::ins
