// Sonar model: water column is noise only, a tall object returns brightly and casts a shadow,
// renders are deterministic per ping, and port/starboard see mirrored geometry.
#include "tools/sim/sonar_model.hpp"

#include "tests/sim/sim_test_scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace sss::sim {
namespace {

using namespace sss::sim::test;

class SonarModelTest : public ::testing::Test {
 protected:
  SonarModelTest() : bed_(boulderScene()), sonar_(SonarOptions(), &bed_) {}
  int sampleAt(double range_m) const { return static_cast<int>(std::lround(range_m / sonar_.options().sampleSpacingM())); }
  Seabed bed_;
  SonarModel sonar_;
};

TEST_F(SonarModelTest, WaterColumnBeforeFirstBottomReturnIsNoiseLevel) {
  const PingSamples ping = sonar_.render(levelPoseAt(-20.0), 3);
  const std::vector<float> expected = sonar_.expectedIntensity(levelPoseAt(-20.0), Side::kStarboard);
  const int first_bottom = sampleAt(kAltitudeM);
  // No seabed lies closer than the altitude: the expected echo is exactly zero there.
  EXPECT_EQ(*std::max_element(expected.begin(), expected.begin() + first_bottom - 1), 0.0f);
  for (const std::vector<float>* side : {&ping.port, &ping.starboard}) {
    const double water = mean(*side, 10, first_bottom - 20);
    const double bottom = mean(*side, sampleAt(20.0), sampleAt(30.0));
    // Noise after TVG at < 18 m is > 30 dB below the bottom return.
    EXPECT_LT(water, 0.05 * bottom);
    EXPECT_GT(bottom, 0.0);
  }
}

TEST_F(SonarModelTest, TallObjectReturnsBrightlyAndCastsAShadow) {
  const std::vector<float> expected = sonar_.expectedIntensity(levelPoseAt(0.0), Side::kStarboard);
  const std::vector<float> reference = sonar_.expectedIntensity(levelPoseAt(-20.0), Side::kStarboard);
  const double front_ground = kObjectEastM - kObjectRadiusM;
  const int front = sampleAt(std::hypot(front_ground, kAltitudeM));
  const int top = sampleAt(std::hypot(kObjectEastM, kAltitudeM - kObjectHeightM));
  // The shadow ends where the ray over the top meets the bed: 40 * 18 / 16.5 = 43.6 m ground.
  const double shadow_end_ground = kObjectEastM * kAltitudeM / (kAltitudeM - kObjectHeightM);
  const int back = sampleAt(std::hypot(kObjectEastM + kObjectRadiusM, kAltitudeM));
  const int shadow_end = sampleAt(std::hypot(shadow_end_ground, kAltitudeM));
  const double peak = *std::max_element(expected.begin() + front - 40, expected.begin() + top + 10);
  EXPECT_GT(peak, 3.0 * mean(reference, front - 40, top + 10));
  // Inside the shadow (with a margin of 10 samples at each end) nothing is ensonified.
  EXPECT_EQ(mean(expected, back + 10, shadow_end - 10), 0.0);
  EXPECT_GT(mean(reference, back + 10, shadow_end - 10), 0.0);
  // The rendered ping (speckle + noise) is dark there too.
  const PingSamples ping = sonar_.render(levelPoseAt(0.0), 11);
  const PingSamples open = sonar_.render(levelPoseAt(-20.0), 11);
  EXPECT_LT(mean(ping.starboard, back + 10, shadow_end - 10), 0.5 * mean(open.starboard, back + 10, shadow_end - 10));
  // Port side has no object: similar to the open bed.
  EXPECT_NEAR(mean(ping.port, back + 10, shadow_end - 10) / mean(open.port, back + 10, shadow_end - 10), 1.0, 0.15);
}

TEST_F(SonarModelTest, RenderIsDeterministicPerPingNumber) {
  const PingSamples a = sonar_.render(levelPoseAt(1.0), 5);
  const PingSamples b = sonar_.render(levelPoseAt(1.0), 5);
  const PingSamples c = sonar_.render(levelPoseAt(1.0), 6);
  EXPECT_EQ(a.port, b.port);
  EXPECT_EQ(a.starboard, b.starboard);
  EXPECT_NE(a.starboard, c.starboard);
  EXPECT_EQ(static_cast<int>(a.port.size()), sonar_.options().samples_per_side);
}

TEST_F(SonarModelTest, SpeckleIsRayleigh) {
  // Over a uniform flat stretch the envelope is Rayleigh: std/mean = sqrt(4/pi - 1) = 0.523.
  const PingSamples ping = sonar_.render(levelPoseAt(-20.0), 9);
  const int first = sampleAt(50.0), last = sampleAt(52.0);
  const double m = mean(ping.port, first, last);
  double var = 0.0;
  for (int i = first; i < last; ++i) var += (ping.port[i] - m) * (ping.port[i] - m);
  const double ratio = std::sqrt(var / (last - first)) / m;
  EXPECT_NEAR(ratio, 0.523, 0.06);
}

TEST_F(SonarModelTest, RollTiltsTheBeamNotTheFanPlane) {
  const sss::core::Pose rolled(sss::core::quaternionFromEuler(0.1, 0.0, 0.0), levelPoseAt(-20.0).translation);
  const FanPlane level = fanPlane(levelPoseAt(-20.0), Side::kStarboard);
  const FanPlane tilted = fanPlane(rolled, Side::kStarboard);
  EXPECT_LT((level.outward - tilted.outward).norm(), 1e-12);
  EXPECT_NEAR(level.outward.y(), 1.0, 1e-12);  // starboard of a northbound vehicle is east
  // Rolling to starboard points the starboard beam down: more near-range, less far-range energy.
  const std::vector<float> flat = sonar_.expectedIntensity(levelPoseAt(-20.0), Side::kStarboard);
  const std::vector<float> roll = sonar_.expectedIntensity(rolled, Side::kStarboard);
  EXPECT_LT(mean(roll, sampleAt(65.0), sampleAt(74.0)), mean(flat, sampleAt(65.0), sampleAt(74.0)));
}


// ---- speckle statistics, TVG mismatch, gain steps ----------------------------------------------

// std/mean of the envelope over many pings in a band of the flat bed, away from the boulder.
double envelopeStdOverMean(const SonarModel& sonar, double from_m, double to_m) {
  const double spacing = sonar.options().sampleSpacingM();
  const int first = static_cast<int>(from_m / spacing), last = static_cast<int>(to_m / spacing);
  const std::vector<float> expected = sonar.expectedIntensity(levelPoseAt(-20.0), Side::kPort);
  double sum = 0.0, sum_sq = 0.0;
  size_t count = 0;
  for (uint32_t ping = 0; ping < 40; ++ping) {
    const PingSamples samples = sonar.render(levelPoseAt(-20.0), ping);
    for (int i = first; i < last; ++i) {
      // Divide out the expected level so the band's mean trend does not count as speckle.
      const double v = samples.port[i] / std::sqrt(expected[i]);
      sum += v, sum_sq += v * v, ++count;
    }
  }
  const double m = sum / count;
  return std::sqrt(sum_sq / count - m * m) / m;
}

SonarOptions quietSonar() {
  SonarOptions options;
  options.noise_intensity_at_max_range = 0.0;  // echo only: the statistics are the speckle's
  return options;
}

TEST(SonarModelSpeckle, RayleighByDefaultKDistributedWithAShape) {
  const Seabed bed(boulderScene());
  const SonarModel rayleigh(quietSonar(), &bed);
  // Rayleigh envelope: std/mean = sqrt(4 / pi - 1) = 0.523.
  EXPECT_NEAR(envelopeStdOverMean(rayleigh, 30.0, 35.0), 0.523, 0.02);
  for (const auto& [shape, expected] : {std::pair{1.0, 0.790}, std::pair{4.0, 0.596}}) {
    SonarOptions options = quietSonar();
    options.speckle_shape = shape;
    // K envelope: E[A] = sqrt(pi)/2 * Gamma(nu + 1/2) / (Gamma(nu) sqrt(nu)), E[A^2] = 1.
    const double mean_a = std::sqrt(M_PI) / 2.0 * std::tgamma(shape + 0.5) / (std::tgamma(shape) * std::sqrt(shape));
    ASSERT_NEAR(std::sqrt(1.0 / (mean_a * mean_a) - 1.0), expected, 0.002);
    EXPECT_NEAR(envelopeStdOverMean(SonarModel(options, &bed), 30.0, 35.0), expected, 0.03) << "shape " << shape;
  }
}

TEST(SonarModelTvg, AbsorptionMismatchTiltsTheSwathByTwoAlphaR) {
  const Seabed bed(boulderScene());
  SonarOptions over = quietSonar();
  over.tvg_absorption_db_per_km = over.absorption_db_per_km + 100.0;  // the TVG assumes 100 dB/km too much
  const std::vector<float> matched = SonarModel(quietSonar(), &bed).expectedIntensity(levelPoseAt(-20.0), Side::kPort);
  const std::vector<float> tilted = SonarModel(over, &bed).expectedIntensity(levelPoseAt(-20.0), Side::kPort);
  const double spacing = over.sampleSpacingM();
  for (double range_m : {25.0, 50.0, 74.0}) {
    const int i = static_cast<int>(range_m / spacing);
    // Intensity gain 2 x 0.1 dB/m x (r - R): 0 dB at the end of the range, -10 dB at 25 m.
    const double gain_db = 10.0 * std::log10(tilted[i] / matched[i]);
    EXPECT_NEAR(gain_db, 0.2 * (i * spacing - over.range_m), 0.01) << range_m;
  }
}

TEST(SonarModelGain, StepsHoldWithinAnIntervalAndChangeBetween) {
  const Seabed bed(boulderScene());
  SonarOptions options = quietSonar();
  EXPECT_EQ(SonarModel(options, &bed).gainStepDb(100, Side::kPort), 0.0);
  options.gain_step_interval_s = 10.0;  // 40 pings at 4 Hz
  options.gain_step_sigma_db = 3.0;
  const SonarModel sonar(options, &bed);
  EXPECT_EQ(sonar.gainStepDb(0, Side::kPort), sonar.gainStepDb(39, Side::kPort));
  EXPECT_NE(sonar.gainStepDb(39, Side::kPort), sonar.gainStepDb(40, Side::kPort));
  EXPECT_NE(sonar.gainStepDb(0, Side::kPort), sonar.gainStepDb(0, Side::kStarboard));
  double sum_sq = 0.0;
  for (uint32_t step = 0; step < 400; ++step) sum_sq += std::pow(sonar.gainStepDb(40 * step, Side::kPort), 2);
  // sigma x sqrt(1 + 1/9) = 3.16 dB
  EXPECT_NEAR(std::sqrt(sum_sq / 400), 3.16, 0.35);
  // The rendered envelope carries the step: amplitude ratio 10^(dB / 20) against a render without it.
  const PingSamples plain = SonarModel(quietSonar(), &bed).render(levelPoseAt(-20.0), 40);
  const PingSamples stepped = sonar.render(levelPoseAt(-20.0), 40);
  const int i = static_cast<int>(30.0 / options.sampleSpacingM());
  EXPECT_NEAR(stepped.port[i] / plain.port[i], std::pow(10.0, sonar.gainStepDb(40, Side::kPort) / 20.0), 1e-4);
}

}  // namespace
}  // namespace sss::sim
