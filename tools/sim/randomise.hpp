// Randomised missions: a whole simulated survey (seabed family and relief, sonar, vehicle motion,
// survey geometry, dead-reckoning errors) drawn from one seed, so that accuracy figures come from
// missions nobody tuned on. `sss-sim --randomise --seed N [--family NAME]`.
#pragma once

#include "tools/sim/mission.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace sss::sim {

// The seabed families, each a distribution over the seabed parameters:
//   sand_ripples   ripple fields at two wavelengths (0.6-2 m ripples on 4-15 m megaripples, with
//                  the steepness sand forms)
//   mud            dark, weakly textured sediment, few features (the matcher's hard case)
//   rock_outcrops  bright ridged rock over 20-50 % of the area, boulders around it
//   boulder_field  30-120 boulders per hectare with their shadows
//   trawled        a fishing ground: many parallel furrows with berms
//   mixed          a little of everything
const std::vector<std::string>& seabedFamilies();
bool isSeabedFamily(const std::string& name);

struct RandomiseOptions {
  int64_t seed = 1;
  std::string family;  // empty: drawn from the seed too
};

// Draws every parameter from the seed onto the defaults. Ranges (uniform unless said):
//   relief: undulation 0.5-3 m over 40-150 m, plane slope 0-5 %;
//   sonar: range 50-200 m per side (frequency, absorption and beam width follow it: 850 / 410 /
//     230 kHz), ping rate 80-95 % of c / 2R (at most 6 Hz), sample spacing 1.5-4 cm, depression
//     15-30 deg, vertical beam 40-60 deg, SNR at max range 3-20 dB over sand, TVG absorption
//     0.7-1.3 x the true one and spreading 26-34 dB/decade, a water-column floor -20..+2 dB re the
//     far-range sand echo, gain steps (60 % of missions) every
//     60-300 s of 1-5 dB, 1-3 looks per sample, K-distributed speckle whose shape depends on the family;
//   vehicle: altitude 8-20 % of the range (6-40 m), speed 1.5-2.5 m/s, roll 0.2-2.3 deg at 6-20 s,
//     pitch 0.2-1.4 deg at 8-30 s, yaw 0.1-0.9 deg at 20-60 s, altitude wobble 0.1-1 m and slow
//     altitude changes up to a quarter of the altitude;
//   survey: lawnmower (75 %) or lawnmower + 2 cross lines, 3-6 lines of 250-500 m at any heading,
//     spacing 0.5-1.7 x the ground swath per side (overlap of a line pair 75 % down to 15 %);
//   dead reckoning: drift scale 0.5-2, white heading noise 0-0.03 rad on half the missions.
//   origin: anywhere within 70 degrees of the equator (the chain takes its frame from the data).
SimOptions randomiseMission(const RandomiseOptions& options);

}  // namespace sss::sim
