// EdgeTech 2205-like dual side-scan model: ray casts the seabed heightmap in each ping's fan
// plane and forms envelope samples (backscatter, beam, losses + TVG, shadows, speckle, noise).
#pragma once

#include "pipeline/core/pose.hpp"
#include "tools/sim/seabed.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace sss::sim {

enum class Side { kPort = 0, kStarboard = 1 };

struct SonarOptions {
  double frequency_hz = 410e3;               // 2205 low-frequency side-scan option
  double bandwidth_hz = 20e3;                // chirp sweep around frequency_hz (header only)
  double range_m = 75.0;                     // per side
  int samples_per_side = 5000;               // 2 * 75 m / 1500 m/s / 5000 = 20 us = 1.5 cm
  double sound_speed_m_s = 1500.0;
  double ping_rate_hz = 4.0;                 // at most sound_speed / (2 range)
  double horizontal_beam_width_rad = 0.0087; // 0.5 deg: 0.65 m along-track footprint at 75 m
  double vertical_beam_width_rad = 0.87;     // 50 deg, -3 dB full width
  double depression_rad = 0.44;              // 25 deg boresight below horizontal
  double sidelobe_level = 0.04;              // beam floor: why nadir still returns
  double absorption_db_per_km = 110.0;       // seawater at ~400 kHz
  // Receiver noise referred to the TVG output at max range, in the units of the backscatter
  // (reflectivity x cos^2 x ground length per range length): ~12 dB below sand at 75 m / 18 m.
  double noise_intensity_at_max_range = 0.0012;
  double tvg_spreading_db_per_decade = 30.0; // TVG = 30 log r + 2 alpha r; the 10 log r of the
                                             // footprint's along-track growth stays uncorrected
  // The absorption the sonar's TVG assumes; < 0: the true absorption_db_per_km. A mismatch (a
  // sound-velocity or temperature guess) leaves a range-dependent brightening or darkening.
  double tvg_absorption_db_per_km = -1.0;
  // Speckle statistics: 0 is fully developed speckle (Rayleigh envelope, std/mean 0.52); a
  // positive value is the shape nu of K-distributed clutter (gamma texture x exponential
  // intensity: few dominant scatterers per cell), std/mean 0.79 at nu = 1 as on real seabeds.
  double speckle_shape = 0.0;
  // Looks averaged into one recorded sample (a sonar that decimates or filters its envelope):
  // intensity gamma distributed with this shape, envelope std/mean 0.52 at 1 look, 0.36 at 2.
  double speckle_looks = 1.0;
  // Gain steps: every gain_step_interval_s (0: never) the operator or the sonar's AGC sets a new
  // gain, Gaussian in dB with this std (both sides alike, plus a third of it per side).
  double gain_step_interval_s = 0.0;
  double gain_step_sigma_db = 0.0;
  // JSF subsystem of the rendered channel pair: -1 picks it from the frequency (below 600 kHz the
  // low-frequency side-scan, 20, else 21); the lower band of a dual-frequency sonar is 20.
  int jsf_subsystem = -1;
  // Water-column floor after the TVG (volume reverberation, plankton, crosstalk), in the units of
  // the backscatter, the same at every range: what makes a real water column grey, not black.
  double volume_backscatter = 0.0;
  double ground_step_m = 0.05;               // ray-cast step along the seabed profile
  double output_scale = 1000.0;              // envelope magnitude per unit amplitude
  uint64_t seed = 1;

  double tvgAbsorptionDbPerKm() const { return tvg_absorption_db_per_km < 0.0 ? absorption_db_per_km : tvg_absorption_db_per_km; }
  double sampleIntervalS() const { return 2.0 * range_m / sound_speed_m_s / samples_per_side; }
  double sampleSpacingM() const { return 0.5 * sampleIntervalS() * sound_speed_m_s; }
};

// A seabed point in one ping's fan plane as the ray cast found it.
struct ProfilePoint {
  Eigen::Vector3d position_ned_m = Eigen::Vector3d::Zero();
  double slant_range_m = 0.0;
  bool visible = true;  // false where a nearer feature shadows it
};

// The fan plane of a ping: origin at the sonar, horizontal outward axis and in-plane down axis.
struct FanPlane {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();   // body x (forward) in world
  Eigen::Vector3d outward = Eigen::Vector3d::UnitY();  // horizontal, towards the side
  Eigen::Vector3d down = Eigen::Vector3d::UnitZ();     // in plane, perpendicular to outward
};
FanPlane fanPlane(const sss::core::Pose& T_world_sonar, Side side);

// The seabed profile of one side of one ping, outward from nadir every ground_step_m up to range.
std::vector<ProfilePoint> castProfile(const Seabed& seabed, const sss::core::Pose& T_world_sonar, Side side,
                                      const SonarOptions& options);

struct PingSamples {
  std::vector<float> port;       // envelope magnitude per sample, sample i at i * sampleSpacingM()
  std::vector<float> starboard;
};

class SonarModel {
 public:
  SonarModel(const SonarOptions& options, const Seabed* seabed);

  // Renders both sides of one ping. Speckle is seeded from (seed, ping_number), so the result does
  // not depend on which thread renders which ping.
  PingSamples render(const sss::core::Pose& T_world_sonar, uint32_t ping_number) const;
  // One side without speckle or noise: the expected TVG-corrected intensity (tests, previews).
  std::vector<float> expectedIntensity(const sss::core::Pose& T_world_sonar, Side side) const;
  // The gain step (dB) in force at ping_number on one side; 0 without gain steps.
  double gainStepDb(uint32_t ping_number, Side side) const;

  const SonarOptions& options() const { return options_; }

 private:
  std::vector<double> accumulate(const sss::core::Pose& T_world_sonar, Side side) const;

  SonarOptions options_;
  const Seabed* seabed_;
  std::vector<double> noise_intensity_;  // per sample, after TVG
  std::vector<double> tvg_residual_;     // per sample: what the TVG leaves of spreading/absorption
};

}  // namespace sss::sim
