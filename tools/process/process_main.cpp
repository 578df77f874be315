// sss-process: post-processes a survey offline with the live chain's libraries, deterministically.
//   sss-process --sonar FILE.jsf|FILE.xtf [--ins FILE.nmea] [--fixes FILE]... [--config FILE] --out DIR
//   sss-process --lcm-log FILE [--config FILE] --out DIR
// Without --ins the navigation in the sonar file's ping headers is used. Exit 0 ok (with a warning
// per stage that yielded nothing), 1 an output could not be written, 2 bad input, 3 nothing could
// be processed (no ping got a pose, or no subframe: the reason is printed and in summary.json).
#include <cstdio>
#include <string>

#include "pipeline/transport/command_line.hpp"
#include "tools/process/offline_runner.hpp"

namespace {
const char* kExplanation =
    "Details:\n"
    "  --fixes [gnss:|usbl:]FILE  absolute position fixes, NMEA GGA (+ GST sigmas, ZDA/RMC dates); repeatable.\n"
    "                         GNSS counts only at the surface; the talker says GNSS (GP, GN, ...) or USBL\n"
    "                         (any other) unless the prefix does. Adds fixes.csv and dead_reckoning_fixed.tum\n"
    "                         (the same fixes without side-scan)\n"
    "  --write-corrected DIR  also write DIR/<sonar file name>: a copy of the sonar file with every ping's\n"
    "                         navigation (position, depth, heading, pitch, roll) replaced by the SLAM pose,\n"
    "                         every other byte unchanged, for the mosaicking software already in use\n"
    "  --record-lcm-log FILE  also write the SSS_PING and SSS_NAV messages fed to the chain to an LCM log\n"
    "  --write-matches        also write matches.csv: every dense match, subframe row and recall probe of\n"
    "                         every pair the matcher tried (for sss-eval --matches FILE --mission DIR)\n"
    "  --inject-false-closures FRACTION  evaluation: that fraction of the matched pairs (drawn with\n"
    "                         --inject-seed, default 1) get a relative pose 3-10 m and 2-10 deg wrong\n"
    "                         before the optimiser (summary.json: false_closures_injected)\n"
    "Writes to DIR: dead_reckoning.tum, slam.tum (every ping, TUM, local NED of the mission origin),\n"
    "navigation.csv and navigation.nmea (the corrected navigation per ping for other tools), track.geojson and\n"
    "subframes.geojson (tracks and subframe footprints for GIS),\n"
    "loop_closures.csv, bathymetry.ply (+ bathymetry_dr.ply), heightmap.yaml/.png (+ heightmap_dr),\n"
    "mosaic_dr.png, mosaic_slam.png (+ .yaml geo-references), GeoTIFFs of the mosaics, heightmaps and coverage\n"
    "(mosaic_dr.tif, mosaic_slam.tif, heightmap.tif, heightmap_dr.tif, coverage.tif: UTM zone of the origin,\n"
    "or the file's grid with products.projected_crs) and summary.json (counts, where the pings\n"
    "went, the mission origin and, when a stage yielded nothing, why).\n"
    "Exit: 0 ok, 1 an output could not be written, 2 bad arguments or input, 3 nothing could be\n"
    "processed (no ping got a pose, or no subframe).\n";
}  // namespace

int main(int argc, char** argv) {
  sss::offline::OfflineRequest request;
  request.progress = stderr;
  sss::cli::CommandLine command_line("sss-process",
                                     "post-processes a survey offline with the live chain's libraries, deterministically: "
                                     "--sonar FILE.jsf|FILE.xtf [--ins FILE.nmea] or --lcm-log FILE, and --out DIR",
                                     kExplanation);
  command_line.add_option("--sonar", request.sonar_path, "the side-scan file (.jsf or .xtf)");
  command_line.add_option("--ins", request.ins_path, "iXblue NMEA navigation (default: the sonar file's own)");
  command_line.add_option("--lcm-log", request.lcm_log_path, "an LCM log of SSS_PING and SSS_NAV instead of files");
  command_line.add_option("--config", request.config_path, "YAML configuration");
  command_line.add_option("--out", request.out_dir, "output folder");
  command_line.add_option("--ping-channel", request.ping_channel, "ping channel of --lcm-log");
  command_line.add_option("--nav-channel", request.nav_channel, "nav channel of --lcm-log");
  command_line.add_option("--record-lcm-log", request.record_lcm_log_path, "record the chain's input to this LCM log");
  command_line.add_option("--write-corrected", request.corrected_dir, "write a corrected copy of the sonar file here");
  command_line.add_option("--fixes", request.fix_paths, "[gnss:|usbl:]FILE of absolute fixes; repeatable");
  bool no_mosaics = false, quiet = false;
  command_line.add_flag("--no-mosaics", no_mosaics, "no mosaics");
  command_line.add_flag("--write-matches", request.write_matches, "also write matches.csv");
  command_line.add_option("--inject-false-closures", request.false_closure_fraction,
                          "make this fraction of the matched pairs false")
      ->check(CLI::Range(0.0, 1.0));
  command_line.add_option("--inject-seed", request.false_closure_seed, "seed of the false closures")
      ->capture_default_str();
  command_line.add_flag("--quiet", quiet, "no progress on stderr");
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  if (no_mosaics) request.write_mosaics = false;
  if (quiet) request.progress = nullptr;
  const sss::offline::OfflineResult result = sss::offline::runOffline(request);
  if (!result.ok) {
    std::fprintf(stderr, "sss-process: %s\n", result.error.c_str());
    return result.exit_code;
  }
  const auto& s = result.summary;
  for (const std::string& finding : s.findings) std::fprintf(stderr, "sss-process: warning: %s\n", finding.c_str());
  if (s.false_closures_injected > 0)
    std::printf("sss-process: %llu of the matcher's closures made false on purpose (--inject-false-closures)\n",
                static_cast<unsigned long long>(s.false_closures_injected));
  if (!s.corrected_copy.empty())
    std::printf("sss-process: corrected copy %s (%llu sonar records with the SLAM navigation)\n", s.corrected_copy.c_str(),
                static_cast<unsigned long long>(s.corrected_records));
  std::printf("sss-process: %llu pings, %llu subframes, %llu pairs, %llu closures (%llu accepted, %llu rejected, "
              "%llu pending), %llu seabed points; mission %.0f s in %.1f s (%.1fx real time), peak %.0f MiB -> %s\n",
              static_cast<unsigned long long>(s.pings), static_cast<unsigned long long>(s.subframes),
              static_cast<unsigned long long>(s.pairs_attempted), static_cast<unsigned long long>(s.matcher_closures),
              static_cast<unsigned long long>(s.closures_accepted), static_cast<unsigned long long>(s.closures_rejected),
              static_cast<unsigned long long>(s.closures_pending),
              static_cast<unsigned long long>(s.seabed_points), s.mission_s, s.wall_s, s.real_time_factor, s.peak_rss_mib,
              request.out_dir.c_str());
  return 0;
}
