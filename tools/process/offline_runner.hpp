// The offline runner behind sss-process: the live chain's libraries (sonar driver / XTF reader, INS
// bridge, subframe buffer, matcher engine, optimiser engine) called in one thread, in time order,
// so the same input and configuration always give the same output whatever the machine load.
// Inputs: a .jsf or .xtf file with an INS NMEA file or the navigation embedded in the sonar file's
// ping headers, or a recorded LCM log (SSS_PING + SSS_NAV). Outputs go to one folder (see
// writeOutputs in offline_runner.cpp and the README).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

namespace sss::offline {

struct OfflineRequest {
  std::string sonar_path;    // .jsf or .xtf (case-insensitive extension)
  std::string ins_path;      // iXblue NMEA; empty: the navigation in the sonar file's ping headers
  std::string lcm_log_path;  // instead of sonar_path/ins_path: a log with SSS_PING and SSS_NAV
  std::string ping_channel = "SSS_PING";
  std::string nav_channel = "SSS_NAV";
  std::string config_path;   // deployment YAML (sections mission, sonar_driver, ins_bridge,
                             // subframe_buffer, matcher, optimiser); empty: defaults
  std::string out_dir;
  // Non-empty (sonar file input): also write the SSS_PING and SSS_NAV messages fed to the chain
  // into this LCM log, for lcm-logplayer into the live chain or a later --lcm-log run. Messages
  // made from the sonar's embedded navigation are not in it (give --ins for a complete log).
  std::string record_lcm_log_path;
  bool write_mosaics = true;
  // Also write out_dir/matches.csv: every dense match, subframe row and recall probe of every pair the
  // matcher tried (for sss-eval --matches; format in match_writer.hpp).
  bool write_matches = false;
  // Evaluation of the optimiser's defences (issue 7): this fraction of the matched pairs, drawn
  // with false_closure_seed, get a wrong relative pose (3-10 m and 2-10 deg off, the same for
  // every association round of the pair) with the matcher's covariance and costs left as they
  // were, as a matcher fooled by repetitive seabed would send. 0: the closures as matched.
  double false_closure_fraction = 0.0;
  uint64_t false_closure_seed = 1;
  std::FILE* progress = nullptr;  // progress lines every progress_period_s of wall time; null: quiet
  double progress_period_s = 2.0;
};

struct OfflineSummary {
  uint64_t nav_samples = 0;
  uint64_t pings = 0;            // pings read
  uint64_t pings_with_pose = 0;  // pings that got a DR pose (in the trajectories)
  uint64_t subframes = 0;
  uint64_t pairs_attempted = 0;
  uint64_t matcher_closures = 0;   // closures the matcher produced (all rounds)
  uint64_t false_closures_injected = 0;  // of those, made wrong on purpose (false_closure_fraction)
  uint64_t closures_accepted = 0;  // by the optimiser, after full smoothing
  uint64_t closures_rejected = 0;
  uint64_t closures_superseded = 0;
  uint64_t seabed_points = 0;
  uint64_t input_faults = 0;       // corrupt records, bad messages, dropped pings
  double mission_s = 0.0;          // first to last ping time
  double wall_s = 0.0;
  double matcher_s = 0.0;
  double optimiser_s = 0.0;
  double real_time_factor = 0.0;   // mission_s / wall_s
  double peak_rss_mib = 0.0;
};

struct OfflineResult {
  bool ok = false;
  int exit_code = 1;      // 0 ok, 2 unusable input or configuration, 1 failure while writing
  std::string error;      // one line, names the file
  OfflineSummary summary;
};

OfflineResult runOffline(const OfflineRequest& request);

}  // namespace sss::offline
