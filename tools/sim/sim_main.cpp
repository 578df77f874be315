// sss-sim: renders a simulated side-scan mission (JSF, INS NMEA, ground truth, seabed, previews)
// into --out DIR. Options: YAML `sim` section via --config, then command-line overrides.
#include "pipeline/core/config.hpp"
#include "tools/sim/mission.hpp"
#include "tools/sim/randomise.hpp"

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <string>

namespace {

const char* kUsage =
    "usage: sss-sim --out DIR [--config FILE] [--seed N] [--pattern lawnmower|loop|cross] [--lines N]\n"
    "               [--cross-lines K] [--line-length-m M] [--line-spacing-m M] [--range-m M] [--altitude-m M]\n"
    "               [--ping-rate-hz HZ] [--drift-scale K] [--heading-noise-rad S] [--duration-s S]\n"
    "               [--origin-latitude-deg LAT --origin-longitude-deg LON] [--no-altitude]\n"
    "               [--gnss-fixes none|start|start-end|lines] [--usbl-period-s S] [--randomise [--family NAME]]\n"
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

bool parseNumber(const std::string& flag, const std::string& text, double& value) {
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0') {
    std::cerr << "sss-sim: " << flag << " expects a number, got '" << text << "'\n";
    return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  std::map<std::string, std::string> flags;
  bool randomise = false;
  bool no_altitude = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      return 0;
    }
    if (arg == "--no-altitude") {
      no_altitude = true;
      continue;
    }
    if (arg == "--randomise") {
      randomise = true;
      continue;
    }
    if (arg.rfind("--", 0) != 0 || i + 1 >= argc) {
      std::cerr << "sss-sim: unexpected argument '" << arg << "' (every flag takes a value)\n" << kUsage;
      return 2;
    }
    flags[arg] = argv[++i];
  }
  if (!flags.count("--out")) {
    std::cerr << "sss-sim: --out DIR is required\n" << kUsage;
    return 2;
  }

  sss::sim::SimOptions options;
  if (flags.count("--family") && !randomise) {
    std::cerr << "sss-sim: --family needs --randomise\n";
    return 2;
  }
  if (randomise) {
    sss::sim::RandomiseOptions request;
    double seed = 1.0;
    if (flags.count("--seed") && (!parseNumber("--seed", flags["--seed"], seed) || seed < 0 ||
                                  seed != static_cast<double>(static_cast<int64_t>(seed)))) {
      std::cerr << "sss-sim: --seed expects a non-negative integer, got '" << flags["--seed"] << "'\n";
      return 2;
    }
    request.seed = static_cast<int64_t>(seed);
    if (flags.count("--family")) {
      request.family = flags["--family"];
      if (!sss::sim::isSeabedFamily(request.family)) {
        std::cerr << "sss-sim: --family " << request.family << " is not one of sand_ripples, mud, rock_outcrops, "
                  << "boulder_field, trawled, mixed\n";
        return 2;
      }
    }
    options = sss::sim::randomiseMission(request);
  }
  if (flags.count("--config")) {
    sss::core::Config config = sss::core::Config::fromFile(flags["--config"]);
    // has() first: ConfigSection::section throws on an absent key (see tools/sim/mission.cpp).
    if (config.ok() && !config.root().has("sim")) {
      std::cerr << "sss-sim: " << flags["--config"] << " has no `sim` section (see mission.yaml of any run)\n";
      return 2;
    }
    if (config.ok()) sss::sim::readSimOptions(config.section("sim"), options);
    if (!config.ok()) {
      std::cerr << "sss-sim: invalid configuration " << flags["--config"] << ":\n" << config.problemReport() << "\n";
      return 2;
    }
  }
  const std::map<std::string, double*> numeric = {
      {"--line-length-m", &options.trajectory.line_length_m},
      {"--line-spacing-m", &options.trajectory.line_spacing_m},
      {"--range-m", &options.sonar.range_m},
      {"--altitude-m", &options.trajectory.altitude_m},
      {"--ping-rate-hz", &options.sonar.ping_rate_hz},
      {"--drift-scale", &options.dead_reckoning.drift_scale},
      {"--heading-noise-rad", &options.dead_reckoning.heading_noise_rad},
      {"--duration-s", &options.duration_s},
      {"--origin-latitude-deg", &options.origin_latitude_deg},
      {"--origin-longitude-deg", &options.origin_longitude_deg},
      {"--usbl-period-s", &options.fixes.usbl_period_s},
  };
  if (no_altitude) options.record_altitude = false;
  for (const auto& [flag, value] : flags) {
    if (flag == "--out" || flag == "--config" || flag == "--family") continue;
    double number = 0.0;
    if (flag == "--pattern") {
      options.trajectory.pattern = value;
    } else if (flag == "--gnss-fixes") {
      options.fixes.gnss = value;
    } else if (flag == "--seed" || flag == "--lines" || flag == "--cross-lines") {
      if (!parseNumber(flag, value, number) || number < 0 || number != static_cast<double>(static_cast<int64_t>(number))) {
        std::cerr << "sss-sim: " << flag << " expects a non-negative integer, got '" << value << "'\n";
        return 2;
      }
      if (flag == "--seed") options.seed = static_cast<int64_t>(number);
      else if (flag == "--lines") options.trajectory.lines = static_cast<int>(number);
      else options.trajectory.cross_lines = static_cast<int>(number);
    } else if (numeric.count(flag)) {
      if (!parseNumber(flag, value, number)) return 2;
      *numeric.at(flag) = number;
    } else {
      std::cerr << "sss-sim: unknown flag " << flag << "\n" << kUsage;
      return 2;
    }
  }
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
    std::string error;
    if (!sss::sim::writeMission(mission, flags["--out"], report, error)) {
      std::cerr << "sss-sim: " << error << "\n";
      return 1;
    }
    std::printf("sss-sim: wrote %s: %zu pings, %.0f m, DR error final %.2f m (%.3f %% of distance), max %.2f m; "
                "render %.1f s, total %.1f s\n",
                flags["--out"].c_str(), report.pings, report.distance_m, report.final_dr_error_m,
                100.0 * report.final_dr_error_m / std::max(1.0, report.distance_m), report.max_dr_error_m,
                report.render_wall_s, report.total_wall_s);
  } catch (const std::exception& e) {
    std::cerr << "sss-sim: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
