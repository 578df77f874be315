// sss-sim's options: read from YAML (the --config file), validated, and written back as the
// mission's record (sim_options.yaml). See mission.hpp.
#include "tools/sim/mission.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>
#include <vector>

namespace sss::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

using sss::core::inRange;
using sss::core::greaterThan;
using sss::core::atLeast;

// ConfigSection::section throws yaml-cpp's InvalidNode when the key is absent (it assigns to the
// zombie node a const lookup returns), so an absent sub-section reads as an empty map here.
sss::core::ConfigSection subsection(sss::core::ConfigSection& parent, const std::string& key) {
  if (parent.has(key)) return parent.section(key);
  return sss::core::ConfigSection(YAML::Node(YAML::NodeType::Map), parent.keyPath(key),
                                  std::make_shared<std::vector<sss::core::ConfigProblem>>());
}

}  // namespace

void readSimOptions(sss::core::ConfigSection section, SimOptions& o) {
  section.optional("seed", o.seed, {atLeast<int64_t>(0)});
  section.optional("family", o.family);
  section.optional("origin_latitude_deg", o.origin_latitude_deg, {inRange(-89.0, 89.0)});
  section.optional("origin_longitude_deg", o.origin_longitude_deg, {inRange(-180.0, 180.0)});
  section.optional("start_utime_us", o.start_utime_us, {inRange<int64_t>(946684800000000, 4102444800000000)});
  section.optional("duration_s", o.duration_s, {atLeast(0.0)});
  section.optional("seabed_margin_m", o.seabed_margin_m, {atLeast(0.0)});
  section.optional("auto_seabed_extent", o.auto_seabed_extent);
  section.optional("waterfall_bins_per_side", o.waterfall_bins_per_side, {inRange(16, 20000)});
  section.optional("mosaic_resolution_m", o.mosaic_resolution_m, {inRange(0.05, 10.0)});
  section.optional("record_altitude", o.record_altitude);

  sss::core::ConfigSection seabed = subsection(section, "seabed");
  SeabedOptions& s = o.seabed;
  seabed.optional("north_min_m", s.north_min_m);
  seabed.optional("east_min_m", s.east_min_m);
  seabed.optional("size_north_m", s.size_north_m, {inRange(10.0, 5000.0)});
  seabed.optional("size_east_m", s.size_east_m, {inRange(10.0, 5000.0)});
  seabed.optional("resolution_m", s.resolution_m, {inRange(0.02, 2.0)});
  seabed.optional("mean_depth_m", s.mean_depth_m, {inRange(5.0, 6000.0)});
  seabed.optional("slope_deg", s.slope_deg, {inRange(0.0, 10.0)});
  seabed.optional("undulation_amplitude_m", s.undulation_amplitude_m, {inRange(0.0, 20.0)});
  seabed.optional("undulation_wavelength_m", s.undulation_wavelength_m, {inRange(5.0, 2000.0)});
  seabed.optional("ripple_amplitude_m", s.ripple_amplitude_m, {inRange(0.0, 1.0)});
  seabed.optional("ripple_wavelength_m", s.ripple_wavelength_m, {inRange(0.3, 20.0)});
  seabed.optional("ripple_fraction", s.ripple_fraction, {inRange(0.0, 1.0)});
  seabed.optional("trawl_mark_count", s.trawl_mark_count, {inRange(0, 1000)});
  seabed.optional("trawl_mark_depth_m", s.trawl_mark_depth_m, {inRange(0.0, 2.0)});
  seabed.optional("trawl_mark_width_m", s.trawl_mark_width_m, {inRange(0.1, 10.0)});
  seabed.optional("boulders_per_hectare", s.boulders_per_hectare, {inRange(0.0, 500.0)});
  seabed.optional("boulder_min_radius_m", s.boulder_min_radius_m, {inRange(0.05, 20.0)});
  seabed.optional("boulder_max_radius_m", s.boulder_max_radius_m, {inRange(0.05, 20.0)});
  seabed.optional("sediment_patch_scale_m", s.sediment_patch_scale_m, {inRange(1.0, 1000.0)});
  seabed.optional("reflectivity_scale", s.reflectivity_scale, {inRange(0.05, 5.0)});
  seabed.optional("patch_contrast", s.patch_contrast, {inRange(0.0, 3.0)});
  seabed.optional("texture_contrast", s.texture_contrast, {inRange(0.0, 1.0)});
  seabed.optional("megaripple_amplitude_m", s.megaripple_amplitude_m, {inRange(0.0, 2.0)});
  seabed.optional("megaripple_wavelength_m", s.megaripple_wavelength_m, {inRange(1.0, 50.0)});
  seabed.optional("outcrop_fraction", s.outcrop_fraction, {inRange(0.0, 1.0)});
  seabed.optional("outcrop_relief_m", s.outcrop_relief_m, {inRange(0.0, 10.0)});
  seabed.optional("outcrop_scale_m", s.outcrop_scale_m, {inRange(5.0, 1000.0)});
  seabed.optional("enable_texture", s.enable_texture);
  // Hand-placed objects (targets a test or a survey check looks for at known coordinates).
  for (sss::core::ConfigSection item : seabed.sequence("objects")) {
    SeabedObject object;
    item.required("north_m", object.north_m);
    item.required("east_m", object.east_m);
    item.optional("radius_m", object.radius_m, {inRange(0.05, 50.0)});
    item.optional("height_m", object.height_m, {inRange(0.0, 20.0)});
    item.optional("reflectivity", object.reflectivity, {inRange(0.0, 5.0)});
    item.rejectUnknownKeys();
    s.objects.push_back(object);
  }
  seabed.rejectUnknownKeys();

  sss::core::ConfigSection vehicle = subsection(section, "vehicle");
  TrajectoryOptions& t = o.trajectory;
  vehicle.optional("pattern", t.pattern, {sss::core::oneOf({"lawnmower", "loop", "cross"})});
  vehicle.optional("lines", t.lines, {inRange(1, 200)});
  vehicle.optional("cross_lines", t.cross_lines, {inRange(1, 200)});
  vehicle.optional("cross_turn_radius_m", t.cross_turn_radius_m, {inRange(5.0, 1000.0)});
  vehicle.optional("line_length_m", t.line_length_m, {inRange(10.0, 20000.0)});
  vehicle.optional("line_spacing_m", t.line_spacing_m, {inRange(5.0, 2000.0)});
  vehicle.optional("line_heading_deg", t.line_heading_deg, {inRange(-360.0, 360.0)});
  vehicle.optional("speed_m_s", t.speed_m_s, {inRange(0.2, 10.0)});
  vehicle.optional("altitude_m", t.altitude_m, {inRange(1.0, 500.0)});
  vehicle.optional("roll_amplitude_rad", t.roll_amplitude_rad, {inRange(0.0, 0.5)});
  vehicle.optional("roll_period_s", t.roll_period_s, {greaterThan(0.0)});
  vehicle.optional("pitch_amplitude_rad", t.pitch_amplitude_rad, {inRange(0.0, 0.5)});
  vehicle.optional("pitch_period_s", t.pitch_period_s, {greaterThan(0.0)});
  vehicle.optional("yaw_amplitude_rad", t.yaw_amplitude_rad, {inRange(0.0, 0.5)});
  vehicle.optional("yaw_period_s", t.yaw_period_s, {greaterThan(0.0)});
  vehicle.optional("altitude_wobble_m", t.altitude_wobble_m, {inRange(0.0, 10.0)});
  vehicle.optional("altitude_variation_m", t.altitude_variation_m, {inRange(0.0, 50.0)});
  vehicle.optional("altitude_variation_length_m", t.altitude_variation_length_m, {inRange(10.0, 10000.0)});
  vehicle.optional("max_turn_bank_rad", t.max_turn_bank_rad, {inRange(0.0, 0.5)});
  vehicle.optional("surface_hold_m", t.surface_hold_m, {inRange(0.0, 10000.0)});
  vehicle.optional("surface_ramp_m", t.surface_ramp_m, {inRange(1.0, 10000.0)});
  vehicle.optional("surface_depth_m", t.surface_depth_m, {inRange(0.0, 10.0)});
  vehicle.rejectUnknownKeys();

  sss::core::ConfigSection dr = subsection(section, "dead_reckoning");
  DeadReckoningOptions& d = o.dead_reckoning;
  dr.optional("rate_hz", d.rate_hz, {inRange(1.0, 200.0)});
  dr.optional("drift_scale", d.drift_scale, {inRange(0.0, 100.0)});
  dr.optional("velocity_scale_factor_min", d.velocity_scale_factor_min, {inRange(0.0, 0.1)});
  dr.optional("velocity_scale_factor_max", d.velocity_scale_factor_max, {inRange(0.0, 0.1)});
  dr.optional("heading_bias_min_rad", d.heading_bias_min_rad, {inRange(0.0, 0.1)});
  dr.optional("heading_bias_max_rad", d.heading_bias_max_rad, {inRange(0.0, 0.1)});
  dr.optional("heading_deviation_min_rad", d.heading_deviation_min_rad, {inRange(0.0, 0.1)});
  dr.optional("heading_deviation_max_rad", d.heading_deviation_max_rad, {inRange(0.0, 0.1)});
  dr.optional("heading_random_walk_rad_per_sqrt_s", d.heading_random_walk_rad_per_sqrt_s, {inRange(0.0, 0.01)});
  dr.optional("velocity_white_noise_m_s", d.velocity_white_noise_m_s, {inRange(0.0, 1.0)});
  dr.optional("attitude_noise_rad", d.attitude_noise_rad, {inRange(0.0, 0.1)});
  dr.optional("attitude_bias_rad", d.attitude_bias_rad, {inRange(0.0, 0.1)});
  dr.optional("depth_noise_m", d.depth_noise_m, {inRange(0.0, 10.0)});
  dr.optional("heading_noise_rad", d.heading_noise_rad, {inRange(0.0, 1.0)});
  dr.optional("heading_noise_interval_s", d.heading_noise_interval_s, {inRange(0.01, 100.0)});
  dr.optional("reported_start_std_m", d.reported_start_std_m, {inRange(0.0, 1000.0)});
  dr.optional("reported_drift_fraction", d.reported_drift_fraction, {inRange(0.0, 1.0)});
  dr.optional("reported_heading_std_rad", d.reported_heading_std_rad, {inRange(0.0, 1.0)});
  dr.rejectUnknownKeys();

  sss::core::ConfigSection sonar = subsection(section, "sonar");
  SonarOptions& n = o.sonar;
  sonar.optional("frequency_hz", n.frequency_hz, {inRange(10e3, 2e6)});
  sonar.optional("bandwidth_hz", n.bandwidth_hz, {inRange(0.0, 500e3)});
  sonar.optional("range_m", n.range_m, {inRange(5.0, 1000.0)});
  sonar.optional("samples_per_side", n.samples_per_side, {inRange(16, 65535)});
  sonar.optional("sound_speed_m_s", n.sound_speed_m_s, {inRange(1400.0, 1600.0)});
  sonar.optional("ping_rate_hz", n.ping_rate_hz, {inRange(0.1, 100.0)});
  sonar.optional("horizontal_beam_width_rad", n.horizontal_beam_width_rad, {inRange(0.0, 0.2)});
  sonar.optional("vertical_beam_width_rad", n.vertical_beam_width_rad, {inRange(0.05, 3.0)});
  sonar.optional("depression_rad", n.depression_rad, {inRange(0.0, 1.5)});
  sonar.optional("sidelobe_level", n.sidelobe_level, {inRange(0.0, 1.0)});
  sonar.optional("absorption_db_per_km", n.absorption_db_per_km, {inRange(0.0, 1000.0)});
  sonar.optional("noise_intensity_at_max_range", n.noise_intensity_at_max_range, {inRange(0.0, 10.0)});
  sonar.optional("tvg_spreading_db_per_decade", n.tvg_spreading_db_per_decade, {inRange(0.0, 40.0)});
  sonar.optional("tvg_absorption_db_per_km", n.tvg_absorption_db_per_km, {inRange(-1.0, 1000.0)});
  sonar.optional("speckle_shape", n.speckle_shape, {inRange(0.0, 1000.0)});
  sonar.optional("speckle_looks", n.speckle_looks, {inRange(1.0, 100.0)});
  sonar.optional("gain_step_interval_s", n.gain_step_interval_s, {inRange(0.0, 1e6)});
  sonar.optional("gain_step_sigma_db", n.gain_step_sigma_db, {inRange(0.0, 20.0)});
  sonar.optional("jsf_subsystem", n.jsf_subsystem, {inRange(-1, 255)});
  sonar.optional("volume_backscatter", n.volume_backscatter, {inRange(0.0, 10.0)});
  sonar.optional("ground_step_m", n.ground_step_m, {inRange(0.005, 1.0)});
  sonar.optional("output_scale", n.output_scale, {greaterThan(0.0)});
  sonar.rejectUnknownKeys();

  sss::core::ConfigSection fixes = subsection(section, "fixes");
  SimFixOptions& f = o.fixes;
  fixes.optional("gnss", f.gnss, {sss::core::oneOf({"none", "start", "start-end", "lines"})});
  fixes.optional("gnss_sigma_m", f.gnss_sigma_m, {inRange(0.01, 100.0)});
  fixes.optional("gnss_correlation_time_s", f.gnss_correlation_time_s, {inRange(0.0, 86400.0)});
  fixes.optional("gnss_period_s", f.gnss_period_s, {inRange(0.1, 600.0)});
  fixes.optional("gnss_max_depth_m", f.gnss_max_depth_m, {inRange(0.0, 10.0)});
  fixes.optional("usbl_period_s", f.usbl_period_s, {inRange(0.0, 3600.0)});
  fixes.optional("usbl_sigma_fraction", f.usbl_sigma_fraction, {inRange(0.0, 0.1)});
  fixes.optional("usbl_sigma_floor_m", f.usbl_sigma_floor_m, {inRange(0.01, 100.0)});
  fixes.optional("usbl_dropout_fraction", f.usbl_dropout_fraction, {inRange(0.0, 1.0)});
  fixes.optional("usbl_outlier_fraction", f.usbl_outlier_fraction, {inRange(0.0, 1.0)});
  fixes.optional("usbl_outlier_min_m", f.usbl_outlier_min_m, {inRange(0.0, 10000.0)});
  fixes.optional("usbl_outlier_max_m", f.usbl_outlier_max_m, {inRange(0.0, 10000.0)});
  fixes.rejectUnknownKeys();
  section.rejectUnknownKeys();
}

std::vector<std::string> validateSimOptions(const SimOptions& o) {
  std::vector<std::string> problems;
  const auto add = [&](const std::string& key, double value, const std::string& reason) {
    std::ostringstream text;
    text << "sim." << key << ": " << value << " " << reason;
    problems.push_back(text.str());
  };
  if (!(std::abs(o.origin_latitude_deg) <= 89.0)) add("origin_latitude_deg", o.origin_latitude_deg, "must be within [-89, 89]");
  if (!(std::abs(o.origin_longitude_deg) <= 180.0)) add("origin_longitude_deg", o.origin_longitude_deg, "must be within [-180, 180]");
  const double max_ping_rate = o.sonar.sound_speed_m_s / (2.0 * o.sonar.range_m);
  if (o.sonar.ping_rate_hz > max_ping_rate + 1e-9) {
    add("sonar.ping_rate_hz", o.sonar.ping_rate_hz,
        "exceeds sound_speed / (2 range) = " + std::to_string(max_ping_rate) + " Hz; lower the rate or the range");
  }
  if (o.sonar.range_m <= o.trajectory.altitude_m) add("sonar.range_m", o.sonar.range_m, "must exceed vehicle.altitude_m");
  const double interval_ns = o.sonar.sampleIntervalS() * 1e9;
  if (interval_ns < 1.0) add("sonar.samples_per_side", o.sonar.samples_per_side, "gives a sample interval below 1 ns");
  if (o.dead_reckoning.velocity_scale_factor_min > o.dead_reckoning.velocity_scale_factor_max)
    add("dead_reckoning.velocity_scale_factor_min", o.dead_reckoning.velocity_scale_factor_min, "exceeds the max");
  if (o.dead_reckoning.heading_bias_min_rad > o.dead_reckoning.heading_bias_max_rad)
    add("dead_reckoning.heading_bias_min_rad", o.dead_reckoning.heading_bias_min_rad, "exceeds the max");
  if (o.dead_reckoning.heading_deviation_min_rad > o.dead_reckoning.heading_deviation_max_rad)
    add("dead_reckoning.heading_deviation_min_rad", o.dead_reckoning.heading_deviation_min_rad, "exceeds the max");
  if (o.fixes.gnss != "none" && o.fixes.gnss != "start" && o.fixes.gnss != "start-end" && o.fixes.gnss != "lines")
    problems.push_back("sim.fixes.gnss: " + o.fixes.gnss + " is not none, start, start-end or lines");
  if (o.fixes.usbl_period_s < 0.0) add("fixes.usbl_period_s", o.fixes.usbl_period_s, "must be >= 0 (0: no USBL)");
  if (o.fixes.usbl_outlier_min_m > o.fixes.usbl_outlier_max_m)
    add("fixes.usbl_outlier_min_m", o.fixes.usbl_outlier_min_m, "exceeds usbl_outlier_max_m");
  if (o.fixes.gnss != "none" && o.trajectory.surface_depth_m > o.fixes.gnss_max_depth_m)
    add("vehicle.surface_depth_m", o.trajectory.surface_depth_m, "is deeper than fixes.gnss_max_depth_m: no GNSS fix");
  if (o.seabed.boulder_min_radius_m > o.seabed.boulder_max_radius_m)
    add("seabed.boulder_min_radius_m", o.seabed.boulder_min_radius_m, "exceeds boulder_max_radius_m");
  if (o.trajectory.pattern != "lawnmower" && o.trajectory.pattern != "loop" && o.trajectory.pattern != "cross")
    problems.push_back("sim.vehicle.pattern: " + o.trajectory.pattern + " is not lawnmower, loop or cross");
  if (o.trajectory.pattern == "cross" && o.trajectory.cross_lines < 1)
    add("vehicle.cross_lines", o.trajectory.cross_lines, "is too few for a cross pattern; use at least 1");
  if (o.trajectory.pattern != "loop" && o.trajectory.lines > 1 && o.trajectory.line_spacing_m < 20.0)
    add("vehicle.line_spacing_m", o.trajectory.line_spacing_m, "is below 20 m: the 10 m turn radius minimum");
  if (o.trajectory.pattern == "loop" && o.trajectory.lines < 3)
    add("vehicle.lines", o.trajectory.lines, "is too few for a loop; use at least 3");
  // Memory guard: two float rasters.
  const double cells = (o.seabed.size_north_m / o.seabed.resolution_m) * (o.seabed.size_east_m / o.seabed.resolution_m);
  if (!o.auto_seabed_extent && cells > 2.0e8) add("seabed.resolution_m", o.seabed.resolution_m, "gives more than 2e8 cells");
  return problems;
}

std::string simOptionsYaml(const SimOptions& o) {
  YAML::Emitter out;
  out.SetDoublePrecision(10);
  out << YAML::BeginMap;
  out << YAML::Key << "seed" << YAML::Value << o.seed;
  out << YAML::Key << "family" << YAML::Value << o.family;
  out << YAML::Key << "origin_latitude_deg" << YAML::Value << o.origin_latitude_deg;
  out << YAML::Key << "origin_longitude_deg" << YAML::Value << o.origin_longitude_deg;
  out << YAML::Key << "start_utime_us" << YAML::Value << o.start_utime_us;
  out << YAML::Key << "duration_s" << YAML::Value << o.duration_s;
  out << YAML::Key << "seabed_margin_m" << YAML::Value << o.seabed_margin_m;
  out << YAML::Key << "auto_seabed_extent" << YAML::Value << o.auto_seabed_extent;
  out << YAML::Key << "waterfall_bins_per_side" << YAML::Value << o.waterfall_bins_per_side;
  out << YAML::Key << "mosaic_resolution_m" << YAML::Value << o.mosaic_resolution_m;
  out << YAML::Key << "record_altitude" << YAML::Value << o.record_altitude;
  const SeabedOptions& s = o.seabed;
  out << YAML::Key << "seabed" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "north_min_m" << YAML::Value << s.north_min_m << YAML::Key << "east_min_m" << YAML::Value << s.east_min_m
      << YAML::Key << "size_north_m" << YAML::Value << s.size_north_m << YAML::Key << "size_east_m" << YAML::Value << s.size_east_m
      << YAML::Key << "resolution_m" << YAML::Value << s.resolution_m << YAML::Key << "mean_depth_m" << YAML::Value << s.mean_depth_m
      << YAML::Key << "slope_deg" << YAML::Value << s.slope_deg << YAML::Key << "undulation_amplitude_m" << YAML::Value
      << s.undulation_amplitude_m << YAML::Key << "undulation_wavelength_m" << YAML::Value << s.undulation_wavelength_m
      << YAML::Key << "ripple_amplitude_m" << YAML::Value << s.ripple_amplitude_m << YAML::Key << "ripple_wavelength_m"
      << YAML::Value << s.ripple_wavelength_m << YAML::Key << "ripple_fraction" << YAML::Value << s.ripple_fraction
      << YAML::Key << "trawl_mark_count" << YAML::Value << s.trawl_mark_count << YAML::Key << "trawl_mark_depth_m"
      << YAML::Value << s.trawl_mark_depth_m << YAML::Key << "trawl_mark_width_m" << YAML::Value << s.trawl_mark_width_m
      << YAML::Key << "boulders_per_hectare" << YAML::Value << s.boulders_per_hectare << YAML::Key << "boulder_min_radius_m"
      << YAML::Value << s.boulder_min_radius_m << YAML::Key << "boulder_max_radius_m" << YAML::Value << s.boulder_max_radius_m
      << YAML::Key << "sediment_patch_scale_m" << YAML::Value << s.sediment_patch_scale_m << YAML::Key << "enable_texture"
      << YAML::Value << s.enable_texture << YAML::Key << "reflectivity_scale" << YAML::Value << s.reflectivity_scale
      << YAML::Key << "patch_contrast" << YAML::Value << s.patch_contrast << YAML::Key << "texture_contrast" << YAML::Value
      << s.texture_contrast << YAML::Key << "megaripple_amplitude_m" << YAML::Value << s.megaripple_amplitude_m << YAML::Key
      << "megaripple_wavelength_m" << YAML::Value << s.megaripple_wavelength_m << YAML::Key << "outcrop_fraction"
      << YAML::Value << s.outcrop_fraction << YAML::Key << "outcrop_relief_m" << YAML::Value << s.outcrop_relief_m
      << YAML::Key << "outcrop_scale_m" << YAML::Value << s.outcrop_scale_m;
  if (!s.objects.empty()) {
    out << YAML::Key << "objects" << YAML::Value << YAML::BeginSeq;
    for (const SeabedObject& object : s.objects) {
      out << YAML::Flow << YAML::BeginMap << YAML::Key << "north_m" << YAML::Value << object.north_m << YAML::Key
          << "east_m" << YAML::Value << object.east_m << YAML::Key << "radius_m" << YAML::Value << object.radius_m
          << YAML::Key << "height_m" << YAML::Value << object.height_m << YAML::Key << "reflectivity" << YAML::Value
          << object.reflectivity << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  out << YAML::EndMap;
  const TrajectoryOptions& t = o.trajectory;
  out << YAML::Key << "vehicle" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "pattern" << YAML::Value << t.pattern << YAML::Key << "lines" << YAML::Value << t.lines << YAML::Key
      << "cross_lines" << YAML::Value << t.cross_lines << YAML::Key << "cross_turn_radius_m" << YAML::Value
      << t.cross_turn_radius_m << YAML::Key
      << "line_length_m" << YAML::Value << t.line_length_m << YAML::Key << "line_spacing_m" << YAML::Value << t.line_spacing_m
      << YAML::Key << "line_heading_deg" << YAML::Value << t.line_heading_deg << YAML::Key << "speed_m_s" << YAML::Value
      << t.speed_m_s << YAML::Key << "altitude_m" << YAML::Value << t.altitude_m << YAML::Key << "roll_amplitude_rad"
      << YAML::Value << t.roll_amplitude_rad << YAML::Key << "roll_period_s" << YAML::Value << t.roll_period_s << YAML::Key
      << "pitch_amplitude_rad" << YAML::Value << t.pitch_amplitude_rad << YAML::Key << "pitch_period_s" << YAML::Value
      << t.pitch_period_s << YAML::Key << "yaw_amplitude_rad" << YAML::Value << t.yaw_amplitude_rad << YAML::Key
      << "yaw_period_s" << YAML::Value << t.yaw_period_s << YAML::Key << "altitude_wobble_m" << YAML::Value
      << t.altitude_wobble_m << YAML::Key << "max_turn_bank_rad" << YAML::Value << t.max_turn_bank_rad << YAML::Key
      << "altitude_variation_m" << YAML::Value << t.altitude_variation_m << YAML::Key << "altitude_variation_length_m"
      << YAML::Value << t.altitude_variation_length_m << YAML::Key << "surface_hold_m" << YAML::Value << t.surface_hold_m
      << YAML::Key << "surface_ramp_m" << YAML::Value << t.surface_ramp_m << YAML::Key << "surface_depth_m" << YAML::Value
      << t.surface_depth_m;
  out << YAML::EndMap;
  const DeadReckoningOptions& d = o.dead_reckoning;
  out << YAML::Key << "dead_reckoning" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "rate_hz" << YAML::Value << d.rate_hz << YAML::Key << "drift_scale" << YAML::Value << d.drift_scale
      << YAML::Key << "velocity_scale_factor_min" << YAML::Value << d.velocity_scale_factor_min << YAML::Key
      << "velocity_scale_factor_max" << YAML::Value << d.velocity_scale_factor_max << YAML::Key << "heading_bias_min_rad"
      << YAML::Value << d.heading_bias_min_rad << YAML::Key << "heading_bias_max_rad" << YAML::Value << d.heading_bias_max_rad
      << YAML::Key << "heading_deviation_min_rad" << YAML::Value << d.heading_deviation_min_rad << YAML::Key
      << "heading_deviation_max_rad" << YAML::Value << d.heading_deviation_max_rad
      << YAML::Key << "heading_random_walk_rad_per_sqrt_s" << YAML::Value << d.heading_random_walk_rad_per_sqrt_s
      << YAML::Key << "velocity_white_noise_m_s" << YAML::Value << d.velocity_white_noise_m_s << YAML::Key
      << "attitude_noise_rad" << YAML::Value << d.attitude_noise_rad << YAML::Key << "attitude_bias_rad" << YAML::Value
      << d.attitude_bias_rad << YAML::Key << "depth_noise_m" << YAML::Value << d.depth_noise_m << YAML::Key
      << "heading_noise_rad" << YAML::Value << d.heading_noise_rad << YAML::Key << "heading_noise_interval_s" << YAML::Value
      << d.heading_noise_interval_s << YAML::Key << "reported_start_std_m" << YAML::Value << d.reported_start_std_m
      << YAML::Key << "reported_drift_fraction" << YAML::Value << d.reported_drift_fraction << YAML::Key
      << "reported_heading_std_rad" << YAML::Value << d.reported_heading_std_rad;
  out << YAML::EndMap;
  const SonarOptions& n = o.sonar;
  out << YAML::Key << "sonar" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "frequency_hz" << YAML::Value << n.frequency_hz << YAML::Key << "bandwidth_hz" << YAML::Value
      << n.bandwidth_hz << YAML::Key << "range_m" << YAML::Value << n.range_m << YAML::Key << "samples_per_side" << YAML::Value
      << n.samples_per_side << YAML::Key << "sound_speed_m_s" << YAML::Value << n.sound_speed_m_s << YAML::Key
      << "ping_rate_hz" << YAML::Value << n.ping_rate_hz << YAML::Key << "horizontal_beam_width_rad" << YAML::Value
      << n.horizontal_beam_width_rad << YAML::Key << "vertical_beam_width_rad" << YAML::Value << n.vertical_beam_width_rad
      << YAML::Key << "depression_rad" << YAML::Value << n.depression_rad << YAML::Key << "sidelobe_level" << YAML::Value
      << n.sidelobe_level << YAML::Key << "absorption_db_per_km" << YAML::Value << n.absorption_db_per_km << YAML::Key
      << "noise_intensity_at_max_range" << YAML::Value << n.noise_intensity_at_max_range << YAML::Key
      << "tvg_spreading_db_per_decade" << YAML::Value << n.tvg_spreading_db_per_decade << YAML::Key << "ground_step_m"
      << YAML::Value << n.ground_step_m << YAML::Key << "output_scale" << YAML::Value << n.output_scale << YAML::Key
      << "tvg_absorption_db_per_km" << YAML::Value << n.tvg_absorption_db_per_km << YAML::Key << "speckle_shape"
      << YAML::Value << n.speckle_shape << YAML::Key << "speckle_looks" << YAML::Value << n.speckle_looks << YAML::Key << "gain_step_interval_s" << YAML::Value << n.gain_step_interval_s
      << YAML::Key << "gain_step_sigma_db" << YAML::Value << n.gain_step_sigma_db << YAML::Key << "jsf_subsystem"
      << YAML::Value << n.jsf_subsystem << YAML::Key << "volume_backscatter" << YAML::Value << n.volume_backscatter;
  out << YAML::EndMap;
  const SimFixOptions& f = o.fixes;
  out << YAML::Key << "fixes" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "gnss" << YAML::Value << f.gnss << YAML::Key << "gnss_sigma_m" << YAML::Value << f.gnss_sigma_m
      << YAML::Key << "gnss_correlation_time_s" << YAML::Value << f.gnss_correlation_time_s
      << YAML::Key << "gnss_period_s" << YAML::Value << f.gnss_period_s << YAML::Key << "gnss_max_depth_m" << YAML::Value
      << f.gnss_max_depth_m << YAML::Key << "usbl_period_s" << YAML::Value << f.usbl_period_s << YAML::Key
      << "usbl_sigma_fraction" << YAML::Value << f.usbl_sigma_fraction << YAML::Key << "usbl_sigma_floor_m" << YAML::Value
      << f.usbl_sigma_floor_m << YAML::Key << "usbl_dropout_fraction" << YAML::Value << f.usbl_dropout_fraction
      << YAML::Key << "usbl_outlier_fraction" << YAML::Value << f.usbl_outlier_fraction << YAML::Key
      << "usbl_outlier_min_m" << YAML::Value << f.usbl_outlier_min_m << YAML::Key << "usbl_outlier_max_m" << YAML::Value
      << f.usbl_outlier_max_m;
  out << YAML::EndMap;
  out << YAML::EndMap;
  return out.c_str();
}
}  // namespace sss::sim
