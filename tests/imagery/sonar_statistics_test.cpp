// Image statistics on synthetic pings whose statistics are known in closed form: Rayleigh speckle
// on a constant seabed behind a dark water column.
#include "tools/imagery/sonar_statistics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace sss::imagery {
namespace {

// Rayleigh envelope of mean power `seabed` beyond `first_return` samples, `water` before; the
// starboard side `gain` times brighter in amplitude.
std::vector<StatisticsPing> syntheticPings(size_t count, size_t samples, size_t first_return, double water,
                                           double seabed, bool with_altitude) {
  std::mt19937_64 rng(7);
  std::exponential_distribution<double> exponential(1.0);
  std::vector<StatisticsPing> pings(count);
  for (StatisticsPing& ping : pings) {
    ping.sample_spacing_m = 0.05;
    if (with_altitude) ping.altitude_m = first_return * ping.sample_spacing_m;
    for (std::vector<float>* side : {&ping.port, &ping.starboard}) {
      side->resize(samples);
      for (size_t i = 0; i < samples; ++i) {
        const double power = i < first_return ? water : seabed;
        (*side)[i] = static_cast<float>(std::sqrt(power * exponential(rng)));
      }
    }
  }
  return pings;
}

TEST(SonarStatistics, RayleighSpeckleOnAFlatSeabed) {
  const auto pings = syntheticPings(256, 1000, 200, 0.01, 1.0, true);
  const SonarStatistics s = computeSonarStatistics(pings);
  EXPECT_EQ(s.pings, 256u);
  EXPECT_NEAR(s.range_m, 50.0, 1e-9);
  EXPECT_NEAR(s.first_return_m, 10.0, 1e-9);
  EXPECT_EQ(s.pings_with_altitude, 256u);
  EXPECT_NEAR(s.speckle_std_over_mean, std::sqrt(4.0 / M_PI - 1.0), 0.02);
  // 8 ping blocks x 9 sample blocks x 2 sides, all homogeneous.
  EXPECT_EQ(s.far_range_blocks, 2u * 8u * 9u);
  EXPECT_GT(s.homogeneous_blocks, s.far_range_blocks * 9 / 10);
  // Rayleigh quantiles: sqrt(-ln(1 - p)) x sqrt(power): p99 / p1 = 21.4, 26.6 dB.
  EXPECT_NEAR(s.dynamic_range_db, 26.6, 0.6);
  EXPECT_NEAR(s.p50, std::sqrt(std::log(2.0)), 0.01);
  // Water column 20 dB below the seabed in power, i.e. -20 dB in amplitude ratio of means.
  EXPECT_NEAR(s.water_column_db, -20.0, 0.3);
  EXPECT_NEAR(s.nadir_db, 0.0, 0.3);
  EXPECT_NEAR(s.falloff_db, 0.0, 0.2);
  ASSERT_EQ(s.profile_db.size(), 10u);
  EXPECT_NEAR(s.profile_db[9], 0.0, 0.2);
}

TEST(SonarStatistics, FirstReturnDetectedWithoutAltitude) {
  const SonarStatistics s = computeSonarStatistics(syntheticPings(64, 1000, 200, 0.001, 1.0, false));
  EXPECT_EQ(s.pings_with_altitude, 0u);
  EXPECT_NEAR(s.first_return_m, 10.0, 0.5);
  EXPECT_NEAR(s.water_column_db, -30.0, 1.0);
}

TEST(SonarStatistics, EdgesAreNotSpeckle) {
  auto pings = syntheticPings(64, 1000, 200, 0.01, 1.0, true);
  // A dark band over the first half of every 32-ping block: no far-range block is homogeneous.
  for (size_t p = 0; p < pings.size(); ++p) {
    if (p % 32 >= 16) continue;
    for (std::vector<float>* side : {&pings[p].port, &pings[p].starboard}) {
      for (size_t i = 500; i < 1000; ++i) (*side)[i] *= 0.5f;
    }
  }
  const SonarStatistics s = computeSonarStatistics(pings);
  EXPECT_GT(s.far_range_blocks, 0u);
  EXPECT_EQ(s.homogeneous_blocks, 0u);
  EXPECT_TRUE(std::isnan(s.speckle_std_over_mean));
}

TEST(SonarStatistics, SaturatedBlocksAreNotSpeckle) {
  auto pings = syntheticPings(64, 1000, 200, 0.01, 1.0, true);
  // A receiver that clips at 1.2: P(Rayleigh > 1.2) = exp(-1.44) = 23.7 % of the seabed samples.
  for (StatisticsPing& ping : pings) {
    for (std::vector<float>* side : {&ping.port, &ping.starboard}) {
      for (float& v : *side) v = std::min(v, 1.2f);
    }
  }
  const SonarStatistics s = computeSonarStatistics(pings);
  EXPECT_EQ(s.homogeneous_blocks, 0u);
  EXPECT_NEAR(s.saturated_fraction, 0.8 * 0.237, 0.01);
}

TEST(SonarStatistics, NoPingsGiveEmptyFigures) {
  const SonarStatistics s = computeSonarStatistics({});
  EXPECT_EQ(s.pings, 0u);
  EXPECT_TRUE(std::isnan(s.speckle_std_over_mean));
  EXPECT_NE(statisticsJson(s).find("\"speckle_std_over_mean\": null"), std::string::npos);
}

}  // namespace
}  // namespace sss::imagery
