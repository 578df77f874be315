// The canonical swath follows the sonar's recorded range: the first ping with a pose widens the
// configured ground-range axis to the ground range of its last sample, and every subframe of the
// mission keeps that axis.
#include <gtest/gtest.h>

#include <cmath>

#include "pipeline/subframe/subframe_buffer.hpp"

namespace sss::subframe {
namespace {

constexpr int64_t kT0 = 1'780'300'800'000'000;

// A straight line at 2 m/s, 4 Hz pings whose last sample lies at range_m of slant range, 18 m
// above the seabed (nav altitude); returns the buffer after `pings` pings.
SubframeGeometry swathFor(double range_m, bool swath_from_range, int pings, size_t* subframes = nullptr) {
  SubframeBufferOptions options;
  options.canonical.swath_from_range = swath_from_range;
  options.fusion.heading_rate_window_s = 0.0;
  SubframeBuffer buffer(options);
  std::vector<Subframe> out;
  const double spacing_m = 0.05;
  const size_t samples = static_cast<size_t>(std::lround(range_m / spacing_m));
  for (int i = 0; i <= pings; ++i) {
    NavInput nav;
    nav.utime_us = kT0 + i * 250'000;
    nav.position_ned_m = Eigen::Vector3d(0.5 * i, 0.0, 30.0);
    nav.altitude_m = 18.0;
    nav.altitude_valid = true;
    nav.distance_travelled_m = 0.5 * i;
    buffer.addNav(nav, out);
    if (i == pings) break;
    PingInput ping;
    ping.utime_us = nav.utime_us + 100'000;
    ping.ping_number = i;
    ping.sample_interval_s = 2.0 * spacing_m / 1500.0;
    ping.port.assign(samples, 1.0f);
    ping.starboard.assign(samples, 1.0f);
    buffer.addPing(std::move(ping), out);
  }
  buffer.finish(out);
  for (const Subframe& s : out) {
    EXPECT_EQ(s.geometry.bins_per_side, buffer.geometry().bins_per_side);
    EXPECT_EQ(s.image.size(), static_cast<size_t>(s.rows()) * s.cols());
  }
  if (subframes) *subframes = out.size();
  return buffer.geometry();
}

TEST(SwathFromRange, AWiderRangeWidensTheSwathOnceAndForAll) {
  size_t subframes = 0;
  // 120 m of slant range at 18 m altitude: 118.64 m of ground range, 1978 bins of 6 cm.
  const SubframeGeometry wide = swathFor(120.0, true, 450, &subframes);
  EXPECT_EQ(wide.bins_per_side, static_cast<int>(std::ceil(std::sqrt(120.0 * 120.0 - 18.0 * 18.0) / 0.06)));
  EXPECT_GE(subframes, 2u);
  // Off: the configured 75 m.
  EXPECT_EQ(swathFor(120.0, false, 10).bins_per_side, 1250);
  // A shorter range never narrows the configured axis.
  EXPECT_EQ(swathFor(50.0, true, 10).bins_per_side, 1250);
}

}  // namespace
}  // namespace sss::subframe
