// The correction sample the DDS tests exchange.
#pragma once

#include "navigation_correction.h"

namespace sss::test {

inline sss_dds_NavigationCorrection makeCorrection(int64_t utime_us) {
  sss_dds_NavigationCorrection c{};
  c.vehicle_id = 7;
  c.utime_us = utime_us;
  c.latitude_deg = 59.35;
  c.longitude_deg = 18.07;
  c.depth_m = 42.5;
  c.heading_rad = 1.25;
  for (int i = 0; i < 6; ++i) c.covariance[i * 6 + i] = 0.1 * (i + 1);
  c.correction_north_m = 1.5;
  c.correction_east_m = -2.25;
  c.correction_heading_rad = 0.004;
  c.status = sss_dds_CORRECTED;
  c.quality = 0.75f;
  c.num_loop_closures = 12;
  c.correction_utime_us = utime_us - 1000;
  return c;
}

}  // namespace sss::test
