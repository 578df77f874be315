// Randomised missions: a seed gives one plausible, valid mission and always the same one; seeds
// differ; every family is drawn; --family changes the seabed only; mission.yaml reproduces it.
#include "tools/sim/randomise.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <map>
#include <set>

namespace sss::sim {
namespace {

SimOptions draw(int64_t seed, const std::string& family = "") {
  RandomiseOptions request;
  request.seed = seed;
  request.family = family;
  return randomiseMission(request);
}

TEST(Randomise, SameSeedSameMissionOtherSeedOtherMission) {
  EXPECT_EQ(simOptionsYaml(draw(11)), simOptionsYaml(draw(11)));
  EXPECT_NE(simOptionsYaml(draw(11)), simOptionsYaml(draw(12)));
}

TEST(Randomise, EveryDrawIsValidAndWithinTheDocumentedRanges) {
  std::set<std::string> families;
  std::set<std::string> patterns;
  int with_gain_steps = 0;
  for (int64_t seed = 0; seed < 120; ++seed) {
    const SimOptions o = draw(seed);
    SCOPED_TRACE("seed " + std::to_string(seed));
    EXPECT_TRUE(validateSimOptions(o).empty()) << validateSimOptions(o).front();
    EXPECT_TRUE(isSeabedFamily(o.family));
    families.insert(o.family);
    patterns.insert(o.trajectory.pattern);
    EXPECT_EQ(o.seed, seed);
    EXPECT_GE(o.sonar.range_m, 50.0);
    EXPECT_LE(o.sonar.range_m, 200.0);
    EXPECT_LE(o.sonar.ping_rate_hz, o.sonar.sound_speed_m_s / (2.0 * o.sonar.range_m));
    EXPECT_GE(o.sonar.sampleSpacingM(), 0.0149);
    EXPECT_LE(o.sonar.sampleSpacingM(), 0.0401);
    EXPECT_GT(o.sonar.speckle_shape, 0.0);
    EXPECT_GE(o.trajectory.altitude_m, 6.0);
    EXPECT_LT(o.trajectory.altitude_m, 0.25 * o.sonar.range_m + 1.0);
    EXPECT_GE(o.seabed.undulation_amplitude_m, 0.5);
    EXPECT_LE(o.seabed.undulation_amplitude_m, 3.0);
    EXPECT_GE(o.seabed.undulation_wavelength_m, 40.0);
    EXPECT_LE(o.seabed.undulation_wavelength_m, 150.0);
    EXPECT_LE(std::tan(o.seabed.slope_deg * M_PI / 180.0), 0.05 + 1e-12);
    EXPECT_GE(o.trajectory.lines, 3);
    EXPECT_LE(o.trajectory.lines, 6);
    // Spacing between half and 1.7 x the ground swath per side: adjacent lines always overlap.
    const double swath = std::sqrt(std::pow(o.sonar.range_m, 2) - std::pow(o.trajectory.altitude_m, 2));
    EXPECT_LE(o.trajectory.line_spacing_m, 1.7 * swath + 0.5);
    EXPECT_GE(o.trajectory.line_spacing_m, std::min(0.5 * swath - 0.5, 20.0));
    EXPECT_GE(o.dead_reckoning.drift_scale, 0.5);
    EXPECT_LE(o.dead_reckoning.drift_scale, 2.0);
    EXPECT_LE(o.dead_reckoning.heading_noise_rad, 0.03);
    EXPECT_EQ(o.sonar.jsf_subsystem, 20);
    if (o.sonar.gain_step_interval_s > 0.0) ++with_gain_steps;
  }
  EXPECT_EQ(families.size(), seabedFamilies().size());
  EXPECT_EQ(patterns, (std::set<std::string>{"cross", "lawnmower"}));
  EXPECT_GT(with_gain_steps, 50);  // 60 % of 120
  EXPECT_LT(with_gain_steps, 95);
}

// A few drawn parameters per seed, pinned: a change to the draw order or ranges shows here.
TEST(Randomise, PinnedDrawsPerSeed) {
  struct Pin {
    int64_t seed;
    const char* family;
    double range_m;
    int lines;
    const char* pattern;
  };
  for (const Pin& pin : {Pin{1, "mud", 155.0, 4, "lawnmower"}, Pin{2, "mixed", 120.0, 3, "lawnmower"},
                        Pin{3, "boulder_field", 116.0, 6, "lawnmower"}, Pin{42, "trawled", 64.0, 3, "cross"}}) {
    const SimOptions o = draw(pin.seed);
    SCOPED_TRACE("seed " + std::to_string(pin.seed));
    EXPECT_EQ(o.family, pin.family);
    EXPECT_EQ(o.sonar.range_m, pin.range_m);
    EXPECT_EQ(o.trajectory.lines, pin.lines);
    EXPECT_EQ(o.trajectory.pattern, pin.pattern);
  }
}

TEST(Randomise, ForcingTheFamilyChangesTheSeabedOnly) {
  const SimOptions drawn = draw(5);
  for (const std::string& family : seabedFamilies()) {
    const SimOptions forced = draw(5, family);
    EXPECT_EQ(forced.family, family);
    EXPECT_EQ(forced.sonar.range_m, drawn.sonar.range_m);
    EXPECT_EQ(forced.trajectory.line_spacing_m, drawn.trajectory.line_spacing_m);
    EXPECT_EQ(forced.trajectory.roll_amplitude_rad, drawn.trajectory.roll_amplitude_rad);
    EXPECT_EQ(forced.dead_reckoning.drift_scale, drawn.dead_reckoning.drift_scale);
    EXPECT_EQ(forced.seabed.undulation_amplitude_m, drawn.seabed.undulation_amplitude_m);
  }
  // The families differ where they say they do.
  EXPECT_GE(draw(5, "rock_outcrops").seabed.outcrop_fraction, 0.2);
  EXPECT_EQ(draw(5, "mud").seabed.outcrop_fraction, 0.0);
  EXPECT_LE(draw(5, "mud").seabed.reflectivity_scale, 0.6);
  EXPECT_GE(draw(5, "boulder_field").seabed.boulders_per_hectare, 30.0);
  EXPECT_GE(draw(5, "sand_ripples").seabed.ripple_fraction, 0.5);
  EXPECT_GE(draw(5, "trawled").seabed.trawl_mark_count, 20);
  EXPECT_THROW(draw(5, "lava"), std::invalid_argument);
}

TEST(Randomise, MissionYamlReproducesTheDrawnMission) {
  const SimOptions drawn = draw(9);
  YAML::Node node = YAML::Load(simOptionsYaml(drawn));
  auto problems = std::make_shared<std::vector<core::ConfigProblem>>();
  SimOptions reread;
  readSimOptions(core::ConfigSection(node, "sim", problems), reread);
  ASSERT_TRUE(problems->empty()) << problems->front().message();
  EXPECT_EQ(simOptionsYaml(reread), simOptionsYaml(drawn));
}

}  // namespace
}  // namespace sss::sim
