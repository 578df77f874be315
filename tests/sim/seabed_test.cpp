// Seabed: determinism per seed, bounded slope, hand-placed objects stand up from the bed.
#include "tools/sim/seabed.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace sss::sim {
namespace {

SeabedOptions smallBed(uint64_t seed) {
  SeabedOptions options;
  options.seed = seed;
  options.north_min_m = 0.0;
  options.east_min_m = 0.0;
  options.size_north_m = 60.0;
  options.size_east_m = 60.0;
  options.resolution_m = 0.15;
  options.boulders_per_hectare = 50.0;
  return options;
}

TEST(Seabed, SameSeedSameGridDifferentSeedDifferentGrid) {
  const Seabed a(smallBed(7));
  const Seabed b(smallBed(7));
  const Seabed c(smallBed(8));
  EXPECT_EQ(a.depthGrid(), b.depthGrid());
  EXPECT_EQ(a.reflectivityGrid(), b.reflectivityGrid());
  EXPECT_NE(a.depthGrid(), c.depthGrid());
  EXPECT_NE(a.reflectivityGrid(), c.reflectivityGrid());
}

TEST(Seabed, LargeScaleSlopeStaysBelowFiveDegrees) {
  SeabedOptions options = smallBed(3);
  options.size_north_m = 400.0;
  options.size_east_m = 400.0;
  options.resolution_m = 1.0;
  options.slope_deg = 4.0;
  const Seabed bed(options);
  // The smooth part (what the vehicle follows) over 20 m baselines: plane + undulation.
  double max_slope = 0.0;
  for (double n = 20.0; n < 380.0; n += 20.0) {
    for (double e = 20.0; e < 380.0; e += 20.0) {
      const double dn = (bed.smoothDepthM(n + 10, e) - bed.smoothDepthM(n - 10, e)) / 20.0;
      const double de = (bed.smoothDepthM(n, e + 10) - bed.smoothDepthM(n, e - 10)) / 20.0;
      max_slope = std::max(max_slope, std::atan(std::hypot(dn, de)) * 180.0 / M_PI);
    }
  }
  EXPECT_GT(max_slope, 2.0);
  EXPECT_LT(max_slope, 6.5);  // 4 deg plane + gentle 1.5 m / 80 m undulation
}

TEST(Seabed, PlacedObjectRisesAboveFlatBed) {
  SeabedOptions options = smallBed(1);
  options.enable_texture = false;
  options.mean_depth_m = 30.0;
  options.objects.push_back({30.0, 30.0, 1.0, 1.5, 1.1});
  const Seabed bed(options);
  EXPECT_NEAR(bed.depthM(10.0, 10.0), 30.0, 1e-6);
  EXPECT_NEAR(bed.depthM(30.0, 30.0), 28.5, 0.02);
  EXPECT_NEAR(bed.reflectivity(30.0, 30.0), 1.1, 1e-6);
  EXPECT_NEAR(bed.normal(10.0, 10.0).z(), -1.0, 1e-9);
}

}  // namespace
}  // namespace sss::sim
