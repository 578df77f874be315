// sss-process's configuration. See offline_options.hpp.
#include "tools/process/offline_options.hpp"

#include <strings.h>
#include <sys/resource.h>

#include <chrono>
#include <cstring>
#include <vector>

#include "pipeline/core/config.hpp"
#include "products/geotiff.hpp"

namespace sss::offline {

double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double peakRssMib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

bool hasExtension(const std::string& path, const char* extension) {
  const size_t n = std::strlen(extension);
  return path.size() > n && strcasecmp(path.c_str() + path.size() - n, extension) == 0;
}
sss::core::Status readOptions(const std::string& path, Options& options) {
  if (!path.empty()) {
    using namespace sss::core;
    Config config = Config::fromFile(path);
    ConfigSection mission = config.section("mission");
    options.origin = readMissionOrigin(mission);
    ConfigSection sonar = config.section("sonar_driver");
    sss::edgetech::readSonarDriverOptions(sonar, options.sonar);
    sonar.optional("xtf_pair_index", options.xtf.pair_index, {inRange(0, 7)});
    // XTF NavUnits as the file says (file), or forced: a header saying metres over pings in degrees.
    std::string nav_units = "file";
    sonar.optional("xtf_nav_units", nav_units, {oneOf({"file", "latlon", "metres"})});
    options.xtf.nav_units = sss::xtf::xtfNavUnitsFromName(nav_units);
    // A towfish's Layback over SensorY/X that are the ship's: applied (auto) or not (ignore).
    std::string layback = "auto";
    sonar.optional("xtf_layback", layback, {oneOf({"auto", "ignore"})});
    options.xtf.apply_layback = layback == "auto";
    ConfigSection ins = config.section("ins_bridge");
    sss::ins::readInsBridgeOptions(ins, options.ins);
    ConfigSection buffer = config.section("subframe_buffer");
    sss::subframe::readSubframeBufferOptions(buffer, options.buffer);
    ConfigSection matcher = config.section("matcher");
    sss::matcher::readMatcherEngineOptions(matcher, options.matcher);
    ConfigSection optimiser = config.section("optimiser");
    sss::optimiser::readOptimiserEngineOptions(optimiser, options.optimiser);
    {
      ConfigSection fixes = config.section("fixes");
      fixes.optional("gnss_max_depth_m", options.fix_aligner.gnss_max_depth_m, {atLeast(0.0)});
      fixes.optional("max_extrapolation_s", options.fix_aligner.max_extrapolation_s, {atLeast(0.0)});
      fixes.optional("gnss_sigma_per_hdop_m", options.fix_reader.gnss_sigma_per_hdop_m, {greaterThan(0.0)});
      fixes.optional("dgnss_sigma_per_hdop_m", options.fix_reader.dgnss_sigma_per_hdop_m, {greaterThan(0.0)});
      fixes.optional("rtk_fixed_sigma_per_hdop_m", options.fix_reader.rtk_fixed_sigma_per_hdop_m, {greaterThan(0.0)});
      fixes.optional("rtk_float_sigma_per_hdop_m", options.fix_reader.rtk_float_sigma_per_hdop_m, {greaterThan(0.0)});
      fixes.optional("missing_hdop", options.fix_reader.missing_hdop, {greaterThan(0.0)});
      fixes.optional("usbl_default_sigma_m", options.fix_reader.usbl_default_sigma_m, {greaterThan(0.0)});
      fixes.optional("min_sigma_m", options.fix_reader.min_sigma_m, {greaterThan(0.0)});
      fixes.rejectUnknownKeys();
    }
    {
      ConfigSection products = config.section("products");
      products.optional("projected_crs", options.projected_crs);
      products.optional("geotiff", options.write_geotiff);
      products.rejectUnknownKeys();
      if (!options.projected_crs.empty()) {
        const sss::core::Status known = sss::products::isKnownCrs(options.projected_crs);
        if (!known) products.addProblem("projected_crs", options.projected_crs, known.message);
      }
    }
    if (!config.ok()) {
      return sss::core::Status::error("invalid configuration " + path + ": " + config.problemReport());
    }
  }
  options.ins.origin = options.origin;
  // Files carry the ping time of the sonar's clock; a recording has no live clock to compare with.
  options.sonar.time_source = sss::edgetech::TimeSource::kSonarClock;
  options.sonar.recorder.directory.clear();
  // Deterministic: no wall-clock limit anywhere.
  options.matcher.pair.pose.time_limit_s = 0.0;
  options.optimiser.graph.max_solver_time_s = 0.0;
  std::vector<std::string> problems = sss::matcher::validateMatcherEngineOptions(options.matcher);
  for (const std::string& problem : sss::optimiser::validateOptimiserEngineOptions(options.optimiser)) {
    problems.push_back(problem);
  }
  if (!problems.empty()) {
    return sss::core::Status::error("invalid configuration " + path + ": " + problems.front());
  }
  return sss::core::Status::success();
}

}  // namespace sss::offline
