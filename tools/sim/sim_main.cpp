// sss-sim: renders a simulated side-scan mission (JSF, INS NMEA, ground truth, seabed, previews)
// into --out DIR. Options: YAML `sim` section via --config, then command-line overrides.
#include "pipeline/core/config.hpp"
#include "pipeline/transport/command_line.hpp"
#include "tools/sim/mission.hpp"
#include "tools/sim/randomise.hpp"

#include <cstdio>
#include <iostream>
#include <optional>
#include <type_traits>
#include <string>

namespace {

const char* kExplanation =
    "--no-altitude: no altitude in ins.nmea nor in the JSF headers (a towed fish, no DVL).\n"
    "--gnss-fixes: the vehicle surfaces for GNSS fixes before the dive (start), also after the last line\n"
    "  (start-end), also half way through every turn (lines); --usbl-period-s S: a USBL fix every S s from a\n"
    "  ship over the survey (0.2 % of slant range + 0.5 m, 10 % lost, 5 % outliers 10-50 m off). Both write\n"
    "  fixes.nmea (GGA + GST + ZDA; GNSS talker GP, USBL II) for sss-process --fixes (sim.fixes in the config).\n"
    "The mission is flown around the origin (59.35 N 18.07 E unless set; --randomise draws one).\n"
    "Defaults make a ~20 minute, 5-line lawnmower at 2 m/s, 18 m altitude, 75 m range per side.\n"
    "--randomise draws the whole mission from --seed: a seabed family (sand_ripples, mud, rock_outcrops,\n"
    "  boulder_field, trawled, mixed; --family forces one), relief, sonar range 50-200 m with its\n"
    "  frequency, absorption, TVG, gain steps and speckle, vehicle motion, survey geometry, DR errors and\n"
    "  the place on Earth (within 70 degrees of the equator).\n"
    "  mission.yaml records every drawn value; --config and the flags above then override them.\n"
    "--pattern cross: the lawnmower's --lines, then --cross-lines K (2) lines perpendicular to them\n"
    "  across the block at 1/(K+1) ... K/(K+1) of the line length, one spacing beyond the outer lines.\n"
    "The config file's `sim` section holds every other parameter (see mission.yaml of any run).\n";

}  // namespace

int main(int argc, char** argv) {
  std::string out_dir, config_path, family;
  bool randomise = false;
  bool no_altitude = false;
  // Every override is optional: the mission (drawn or default, then the config's) keeps its value
  // unless the flag is given.
  std::optional<int64_t> seed, lines, cross_lines;
  std::optional<double> line_length_m, line_spacing_m, range_m, altitude_m, ping_rate_hz, drift_scale,
      heading_noise_rad, duration_s, origin_latitude_deg, origin_longitude_deg, usbl_period_s;
  std::optional<std::string> pattern, gnss_fixes;
  sss::cli::CommandLine command_line("sss-sim",
                                     "renders a simulated side-scan mission (JSF, INS NMEA, ground truth, seabed, "
                                     "previews) into --out DIR",
                                     kExplanation);
  command_line.add_option("--out", out_dir, "output folder")->required();
  command_line.add_option("--config", config_path, "YAML file with a `sim` section");
  command_line.add_option("--seed", seed, "random seed (default 1)")->check(sss::cli::nonNegative());
  command_line.add_option("--pattern", pattern, "lawnmower | loop | cross");
  command_line.add_option("--lines", lines, "survey lines")->check(sss::cli::nonNegative());
  command_line.add_option("--cross-lines", cross_lines, "cross lines of --pattern cross")->check(sss::cli::nonNegative());
  command_line.add_option("--line-length-m", line_length_m, "line length");
  command_line.add_option("--line-spacing-m", line_spacing_m, "line spacing");
  command_line.add_option("--range-m", range_m, "sonar range per side");
  command_line.add_option("--altitude-m", altitude_m, "altitude above the seabed");
  command_line.add_option("--ping-rate-hz", ping_rate_hz, "ping rate");
  command_line.add_option("--drift-scale", drift_scale, "scale of the DR errors");
  command_line.add_option("--heading-noise-rad", heading_noise_rad, "INS heading noise");
  command_line.add_option("--duration-s", duration_s, "mission duration (0: the survey's)");
  command_line.add_option("--origin-latitude-deg", origin_latitude_deg, "origin latitude");
  command_line.add_option("--origin-longitude-deg", origin_longitude_deg, "origin longitude");
  command_line.add_flag("--no-altitude", no_altitude, "no altitude in ins.nmea nor in the JSF headers");
  command_line.add_option("--gnss-fixes", gnss_fixes, "none | start | start-end | lines");
  command_line.add_option("--usbl-period-s", usbl_period_s, "a USBL fix every S s (0: none)");
  command_line.add_flag("--randomise", randomise, "draw the whole mission from --seed");
  command_line.add_option("--family", family, "the seabed family of --randomise")
      ->check(CLI::IsMember(sss::sim::seabedFamilies()))
      ->needs("--randomise");
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;

  sss::sim::SimOptions options;
  if (randomise) {
    sss::sim::RandomiseOptions request;
    request.seed = seed.value_or(1);
    request.family = family;
    options = sss::sim::randomiseMission(request);
  }
  if (!config_path.empty()) {
    sss::core::Config config = sss::core::Config::fromFile(config_path);
    // has() first: ConfigSection::section throws on an absent key (see tools/sim/mission.cpp).
    if (config.ok() && !config.root().has("sim")) {
      std::cerr << "sss-sim: " << config_path << " has no `sim` section (see mission.yaml of any run)\n";
      return 2;
    }
    if (config.ok()) sss::sim::readSimOptions(config.section("sim"), options);
    if (!config.ok()) {
      std::cerr << "sss-sim: invalid configuration " << config_path << ":\n" << config.problemReport() << "\n";
      return 2;
    }
  }
  if (no_altitude) options.record_altitude = false;
  const auto apply = [](const auto& flag, auto& target) {
    if (flag) target = static_cast<std::decay_t<decltype(target)>>(*flag);
  };
  apply(seed, options.seed);
  apply(pattern, options.trajectory.pattern);
  apply(gnss_fixes, options.fixes.gnss);
  apply(lines, options.trajectory.lines);
  apply(cross_lines, options.trajectory.cross_lines);
  apply(line_length_m, options.trajectory.line_length_m);
  apply(line_spacing_m, options.trajectory.line_spacing_m);
  apply(range_m, options.sonar.range_m);
  apply(altitude_m, options.trajectory.altitude_m);
  apply(ping_rate_hz, options.sonar.ping_rate_hz);
  apply(drift_scale, options.dead_reckoning.drift_scale);
  apply(heading_noise_rad, options.dead_reckoning.heading_noise_rad);
  apply(duration_s, options.duration_s);
  apply(origin_latitude_deg, options.origin_latitude_deg);
  apply(origin_longitude_deg, options.origin_longitude_deg);
  apply(usbl_period_s, options.fixes.usbl_period_s);
  const std::vector<std::string> problems = sss::sim::validateSimOptions(options);
  if (!problems.empty()) {
    for (const std::string& problem : problems) std::cerr << "sss-sim: " << problem << "\n";
    return 2;
  }

  try {
    const sss::sim::Mission mission(options);
    if (randomise) {
      const auto& o = mission.options();
      std::printf("sss-sim: randomised seed %lld: family %s, range %.0f m at %.0f kHz, altitude %.0f m, %s of %d lines "
                  "x %.0f m, spacing %.0f m, relief %.1f m / %.0f m, speckle shape %.2f, drift x%.2f\n",
                  static_cast<long long>(o.seed), o.family.c_str(), o.sonar.range_m, o.sonar.frequency_hz / 1e3,
                  o.trajectory.altitude_m, o.trajectory.pattern.c_str(), o.trajectory.lines, o.trajectory.line_length_m,
                  o.trajectory.line_spacing_m, o.seabed.undulation_amplitude_m, o.seabed.undulation_wavelength_m,
                  o.sonar.speckle_shape, o.dead_reckoning.drift_scale);
    }
    std::cout << "sss-sim: " << mission.pingCount() << " pings, " << mission.durationS() << " s, seabed "
              << mission.seabed().rows() << " x " << mission.seabed().cols() << " cells\n";
    sss::sim::MissionReport report;
    if (const sss::core::Status written = sss::sim::writeMission(mission, out_dir, report); !written) {
      std::cerr << "sss-sim: " << written.message << "\n";
      return 1;
    }
    std::printf("sss-sim: wrote %s: %zu pings, %.0f m, DR error final %.2f m (%.3f %% of distance), max %.2f m; "
                "render %.1f s, total %.1f s\n",
                out_dir.c_str(), report.pings, report.distance_m, report.final_dr_error_m,
                100.0 * report.final_dr_error_m / std::max(1.0, report.distance_m), report.max_dr_error_m,
                report.render_wall_s, report.total_wall_s);
  } catch (const std::exception& e) {
    std::cerr << "sss-sim: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
