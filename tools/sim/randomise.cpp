// Randomised mission parameters: one generator seeded from the mission seed, drawn in a fixed
// order so that a seed always gives the same mission on any machine.
#include "tools/sim/randomise.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace sss::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Uniform draws from a 64-bit Mersenne Twister through our own mapping: std::uniform_real_distribution
// is not specified bit for bit across standard libraries, the raw engine output is.
class Draw {
 public:
  explicit Draw(uint64_t seed) : engine_(seed) {}
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
  double logUniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
  bool chance(double probability) { return unit() < probability; }
  int integer(int lo, int hi) {  // inclusive
    return std::min(hi, lo + static_cast<int>(std::floor(unit() * (hi - lo + 1))));
  }

 private:
  double unit() { return static_cast<double>(engine_() >> 11) * (1.0 / 9007199254740992.0); }
  std::mt19937_64 engine_;
};

// The expected echo of sand at the far end of the swath, in the sonar model's units: reflectivity x
// cos^2(incidence) x beam gain, flat seabed (what the receiver noise is compared with).
double farRangeSandEcho(const SonarOptions& sonar, double altitude_m) {
  const double elevation = std::asin(std::clamp(altitude_m / sonar.range_m, 0.0, 1.0));
  const double cos_incidence = altitude_m / sonar.range_m;  // flat seabed: cos(incidence) = sin(elevation)
  const double beam_k = 4.0 * std::log(2.0) / (sonar.vertical_beam_width_rad * sonar.vertical_beam_width_rad);
  const double off_axis = elevation - sonar.depression_rad;
  const double beam = std::max(sonar.sidelobe_level, std::exp(-beam_k * off_axis * off_axis));
  return 0.35 * cos_incidence * cos_incidence * beam;
}

void drawSeabedFamily(const std::string& family, double area_km2, double resolution_m, Draw& draw, SeabedOptions& s,
                      SonarOptions& sonar) {
  // Features every family may carry a little of, overwritten below where the family is about them.
  const double min_ripple_wavelength_m = std::max(0.6, 5.0 * resolution_m);  // resolvable on the grid
  // Ripple steepness as sand forms it: wavelength / height 8-20 (ripples), 15-30 (megaripples);
  // the amplitudes here are half the height.
  s.ripple_fraction = draw.uniform(0.0, 0.2);
  s.ripple_wavelength_m = draw.uniform(min_ripple_wavelength_m, std::max(2.0, min_ripple_wavelength_m + 0.5));
  const double ripple_steepness = draw.uniform(1.0 / 40.0, 1.0 / 16.0);
  s.ripple_amplitude_m = 0.5 * ripple_steepness * s.ripple_wavelength_m;
  s.megaripple_amplitude_m = 0.0;
  s.megaripple_wavelength_m = draw.uniform(4.0, 15.0);
  const double megaripple_amplitude_m = s.megaripple_wavelength_m * draw.uniform(1.0 / 60.0, 1.0 / 30.0);
  const auto trawl_count = [&](double per_km2) { return static_cast<int>(std::min(60.0, std::round(per_km2 * area_km2))); };
  s.trawl_mark_count = trawl_count(draw.uniform(0.0, 20.0));
  s.trawl_mark_depth_m = draw.uniform(0.1, 0.3);
  s.trawl_mark_width_m = draw.uniform(0.8, 2.0);
  s.boulders_per_hectare = draw.uniform(0.0, 3.0);
  s.boulder_min_radius_m = 0.3;
  s.boulder_max_radius_m = draw.uniform(0.8, 2.0);
  s.sediment_patch_scale_m = draw.uniform(20.0, 80.0);
  s.reflectivity_scale = draw.uniform(0.8, 1.2);
  s.patch_contrast = draw.uniform(0.6, 1.2);
  s.texture_contrast = draw.uniform(0.2, 0.35);
  s.outcrop_fraction = 0.0;
  s.outcrop_relief_m = draw.uniform(0.5, 2.5);
  s.outcrop_scale_m = draw.uniform(30.0, 100.0);
  double speckle_min = 2.0, speckle_max = 8.0;

  if (family == "sand_ripples") {
    s.ripple_fraction = draw.uniform(0.5, 0.9);
    s.ripple_amplitude_m *= 2.0;  // well-formed ripples, the steep end
    s.megaripple_amplitude_m = megaripple_amplitude_m;
    s.reflectivity_scale = draw.uniform(0.9, 1.3);
    speckle_min = 3.0, speckle_max = 15.0;
  } else if (family == "mud") {
    s.ripple_fraction = draw.uniform(0.0, 0.05);
    s.trawl_mark_count = trawl_count(draw.uniform(0.0, 10.0));
    s.boulders_per_hectare = draw.uniform(0.0, 0.5);
    s.reflectivity_scale = draw.uniform(0.35, 0.6);
    s.patch_contrast = draw.uniform(0.2, 0.5);
    s.texture_contrast = draw.uniform(0.05, 0.15);
    speckle_min = 4.0, speckle_max = 30.0;
  } else if (family == "rock_outcrops") {
    s.outcrop_fraction = draw.uniform(0.2, 0.5);
    s.boulders_per_hectare = draw.uniform(5.0, 20.0);
    speckle_min = 0.7, speckle_max = 2.0;
  } else if (family == "boulder_field") {
    s.boulders_per_hectare = draw.uniform(30.0, 120.0);
    s.ripple_fraction = draw.uniform(0.1, 0.3);
    speckle_min = 1.5, speckle_max = 5.0;
  } else if (family == "trawled") {
    s.trawl_mark_count = trawl_count(draw.uniform(80.0, 200.0));
    s.trawl_mark_depth_m = draw.uniform(0.15, 0.4);
    s.reflectivity_scale = draw.uniform(0.5, 0.9);
    speckle_min = 2.0, speckle_max = 8.0;
  } else if (family == "mixed") {
    s.ripple_fraction = draw.uniform(0.2, 0.5);
    s.megaripple_amplitude_m = draw.uniform(0.0, 1.0) * megaripple_amplitude_m;
    s.trawl_mark_count = trawl_count(draw.uniform(20.0, 60.0));
    s.boulders_per_hectare = draw.uniform(3.0, 15.0);
    s.outcrop_fraction = draw.uniform(0.0, 0.15);
    speckle_min = 1.0, speckle_max = 6.0;
  } else {
    throw std::invalid_argument("randomiseMission: unknown seabed family '" + family + "'");
  }
  sonar.speckle_shape = draw.logUniform(speckle_min, speckle_max);
}

}  // namespace

const std::vector<std::string>& seabedFamilies() {
  static const std::vector<std::string> families = {"sand_ripples", "mud",     "rock_outcrops",
                                                     "boulder_field", "trawled", "mixed"};
  return families;
}

bool isSeabedFamily(const std::string& name) {
  const auto& families = seabedFamilies();
  return std::find(families.begin(), families.end(), name) != families.end();
}

SimOptions randomiseMission(const RandomiseOptions& request) {
  if (!request.family.empty() && !isSeabedFamily(request.family)) {
    throw std::invalid_argument("randomiseMission: unknown seabed family '" + request.family + "'");
  }
  SimOptions o;
  o.seed = request.seed;
  Draw draw(mixSeed(static_cast<uint64_t>(request.seed), 0x7A4D0ull));
  const int family_index = draw.integer(0, static_cast<int>(seabedFamilies().size()) - 1);
  o.family = request.family.empty() ? seabedFamilies()[family_index] : request.family;

  // Sonar: the range decides the frequency, and with it absorption and beam width.
  SonarOptions& sonar = o.sonar;
  sonar.range_m = std::round(draw.logUniform(50.0, 200.0));
  double absorption_lo = 50.0, absorption_hi = 70.0, beam_deg_lo = 0.8, beam_deg_hi = 1.1;
  if (sonar.range_m <= 80.0) {
    sonar.frequency_hz = 850e3, absorption_lo = 170.0, absorption_hi = 230.0, beam_deg_lo = 0.3, beam_deg_hi = 0.45;
  } else if (sonar.range_m <= 130.0) {
    sonar.frequency_hz = 410e3, absorption_lo = 85.0, absorption_hi = 120.0, beam_deg_lo = 0.5, beam_deg_hi = 0.7;
  } else {
    sonar.frequency_hz = 230e3;
  }
  sonar.absorption_db_per_km = draw.uniform(absorption_lo, absorption_hi);
  sonar.jsf_subsystem = 20;  // the lower band of a dual-frequency 2205, the one the chain reads by default
  sonar.horizontal_beam_width_rad = draw.uniform(beam_deg_lo, beam_deg_hi) * kPi / 180.0;
  sonar.tvg_absorption_db_per_km = sonar.absorption_db_per_km * draw.uniform(0.7, 1.3);
  sonar.tvg_spreading_db_per_decade = draw.uniform(26.0, 34.0);
  sonar.samples_per_side = static_cast<int>(std::round(sonar.range_m / draw.uniform(0.015, 0.04)));
  sonar.ping_rate_hz = std::min(6.0, draw.uniform(0.8, 0.95) * sonar.sound_speed_m_s / (2.0 * sonar.range_m));
  sonar.ping_rate_hz = std::floor(sonar.ping_rate_hz * 100.0) / 100.0;
  sonar.depression_rad = draw.uniform(15.0, 30.0) * kPi / 180.0;
  sonar.vertical_beam_width_rad = draw.uniform(40.0, 60.0) * kPi / 180.0;
  const double snr_db = draw.uniform(3.0, 20.0);
  if (draw.chance(0.6)) {
    sonar.gain_step_interval_s = draw.uniform(60.0, 300.0);
    sonar.gain_step_sigma_db = draw.uniform(1.0, 5.0);
  }
  // Envelope samples averaged over 1-3 looks (a real 2 x 1024-sample Marine Sonic record shows
  // amplitude std/mean 0.45 on homogeneous far range: about 1.5 looks).
  sonar.speckle_looks = draw.logUniform(1.0, 3.0);

  // Vehicle.
  TrajectoryOptions& t = o.trajectory;
  t.altitude_m = std::clamp(std::round(sonar.range_m * draw.uniform(0.08, 0.2)), 6.0, 40.0);
  const double far_echo = farRangeSandEcho(sonar, t.altitude_m);
  sonar.noise_intensity_at_max_range = far_echo * std::pow(10.0, -snr_db / 10.0);
  // Water column from near black to the grey of the real Iver2 file (-7 dB re its seabed mean).
  sonar.volume_backscatter = far_echo * std::pow(10.0, draw.uniform(-20.0, 2.0) / 10.0);
  t.speed_m_s = draw.uniform(1.5, 2.5);
  t.roll_amplitude_rad = draw.uniform(0.004, 0.04);
  t.roll_period_s = draw.uniform(6.0, 20.0);
  t.pitch_amplitude_rad = draw.uniform(0.003, 0.025);
  t.pitch_period_s = draw.uniform(8.0, 30.0);
  t.yaw_amplitude_rad = draw.uniform(0.002, 0.015);
  t.yaw_period_s = draw.uniform(20.0, 60.0);
  t.altitude_wobble_m = draw.uniform(0.1, 1.0);
  t.altitude_variation_m = draw.uniform(0.0, 0.25) * t.altitude_m;
  t.altitude_variation_length_m = draw.uniform(150.0, 600.0);

  // Survey geometry: spacing as a share of the ground swath per side.
  t.pattern = draw.chance(0.25) ? "cross" : "lawnmower";
  t.lines = t.pattern == "cross" ? draw.integer(3, 5) : draw.integer(3, 6);
  t.cross_lines = 2;
  t.line_length_m = std::round(draw.uniform(250.0, 500.0));
  t.line_heading_deg = std::round(draw.uniform(0.0, 360.0));
  const double ground_swath_m = std::sqrt(sonar.range_m * sonar.range_m - t.altitude_m * t.altitude_m);
  t.line_spacing_m = std::max(20.0, std::round(ground_swath_m * draw.uniform(0.5, 1.7)));

  // Seabed: relief and the family's features, on a grid that the widest footprints do not need finer.
  SeabedOptions& s = o.seabed;
  s.mean_depth_m = std::round(draw.uniform(40.0, 200.0));
  s.undulation_amplitude_m = draw.uniform(0.5, 3.0);
  s.undulation_wavelength_m = draw.uniform(40.0, 150.0);
  s.slope_deg = std::atan(draw.uniform(0.0, 0.05)) * 180.0 / kPi;
  s.resolution_m = sonar.range_m <= 100.0 ? 0.15 : sonar.range_m <= 150.0 ? 0.2 : 0.25;
  const Eigen::Vector4d extent = Trajectory::planExtent(t);
  const double pad_m = sonar.range_m + o.seabed_margin_m;
  const double area_km2 = (extent[2] - extent[0] + 2.0 * pad_m) * (extent[3] - extent[1] + 2.0 * pad_m) / 1e6;
  // Dead reckoning, drawn before the family so that --family changes the seabed only.
  o.dead_reckoning.drift_scale = draw.uniform(0.5, 2.0);
  o.dead_reckoning.heading_noise_rad = draw.chance(0.5) ? draw.uniform(0.0, 0.03) : 0.0;
  drawSeabedFamily(o.family, area_km2, s.resolution_m, draw, s, sonar);
  o.mosaic_resolution_m = sonar.range_m <= 100.0 ? 0.5 : 1.0;
  // Anywhere on Earth up to 70 degrees of latitude (an own stream: the draws above keep their
  // values): the chain takes its frame from the data, and must hold wherever it was recorded.
  Draw where(mixSeed(static_cast<uint64_t>(request.seed), 0x0E1C1Dull));
  o.origin_latitude_deg = std::round(where.uniform(-70.0, 70.0) * 1e4) / 1e4;
  o.origin_longitude_deg = std::round(where.uniform(-179.99, 179.99) * 1e4) / 1e4;
  return o;
}

}  // namespace sss::sim
