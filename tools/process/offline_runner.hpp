// The offline runner behind sss-process: the live chain's libraries (sonar driver / XTF reader, INS
// bridge, subframe buffer, matcher engine, optimiser engine) called in one thread, in time order,
// so the same input and configuration always give the same output whatever the machine load.
// Inputs: a .jsf or .xtf file with an INS NMEA file or the navigation embedded in the sonar file's
// ping headers, or a recorded LCM log (SSS_PING + SSS_NAV). Outputs go to one folder (see
// writeOutputs in offline_runner.cpp and the README).
#pragma once

#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>

#include "pipeline/core/mission_origin.hpp"
#include "pipeline/optimiser/pose_graph.hpp"
#include "pipeline/subframe/subframe_buffer.hpp"
#include <vector>

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
  // Absolute position fixes: NMEA files (GGA + GST + ZDA/RMC), each PATH, gnss:PATH or usbl:PATH
  // (drivers/ins/position_fix.hpp). GNSS fixes count only while the vehicle is at the surface.
  std::vector<std::string> fix_paths;
  // Non-empty (sonar file input): also write the SSS_PING and SSS_NAV messages fed to the chain
  // into this LCM log, for lcm-logplayer into the live chain or a later --lcm-log run. Messages
  // made from the sonar's embedded navigation are not in it (give --ins for a complete log).
  std::string record_lcm_log_path;
  bool write_mosaics = true;
  // Non-empty (sonar file input): also write a copy of the sonar file into this folder with every
  // ping's navigation fields replaced by the SLAM pose and every other byte unchanged.
  std::string corrected_dir;
  // Also write out_dir/matches.csv: every dense match, subframe row and recall probe of every pair the
  // matcher tried (for sss-eval --matches; format in match_writer.hpp).
  bool write_matches = false;
  // Evaluation of the optimiser's defences: this fraction of the matched pairs, drawn
  // with false_closure_seed, get a wrong relative pose (3-10 m and 2-10 deg off, the same for
  // every association round of the pair) with the matcher's covariance and costs left as they
  // were, as a matcher fooled by repetitive seabed would send. 0: the closures as matched.
  double false_closure_fraction = 0.0;
  uint64_t false_closure_seed = 1;
  std::FILE* progress = nullptr;  // progress lines every progress_period_s of wall time; null: quiet
  double progress_period_s = 2.0;
};

// What became of the fixes of OfflineRequest::fix_paths.
struct FixSummary {
  uint64_t files = 0;
  uint64_t read = 0;               // fixes in the files
  uint64_t gnss = 0, usbl = 0;
  uint64_t sentences_skipped = 0;  // corrupt or malformed sentences, and GGA without a fix
  std::string first_problem;       // of the skipped sentences
  uint64_t below_surface = 0;      // GNSS while the vehicle was deeper than fixes.gnss_max_depth_m
  uint64_t outside_navigation = 0; // before the navigation starts or after it ends
  uint64_t no_frame = 0;           // the frame has no latitude/longitude (projected XTF)
  uint64_t fed = 0;                // given to the optimiser
  uint64_t accepted = 0;
  uint64_t rejected_gate = 0;
  uint64_t refused = 0;            // by the optimiser (non-finite, bad covariance)
  double rms_residual_m = 0.0;     // of the accepted fixes at the final estimate (horizontal)
  // What the accepted fixes are worth in independent fixes once their errors' correlation in time
  // is counted (optimiser.graph.gnss_fix_correlation_s): a surfacing of 1 Hz GNSS is a few.
  double accepted_independent_equivalent = 0.0;
};

struct OfflineSummary {
  // The local NED frame of every output: configured (mission.origin_*), else the first valid
  // position of the navigation (INS file, sonar file headers) or the one SSS_NAV carries (a log).
  std::optional<sss::core::MissionOrigin> origin;
  std::string origin_source;  // "configured", "first_fix" (which source: origin_detail), "from_navigation"
  std::string origin_detail;  // e.g. "the first position in the sonar file's ping headers"
  // origin_source "projected_first_fix" (XTF NavUnits 0): the frame is the file's grid less these.
  double projected_origin_easting_m = 0.0;
  double projected_origin_northing_m = 0.0;
  double projected_track_m = -1.0;  // the track's length in the projected grid (-1: not projected)
  uint64_t nav_samples = 0;
  uint64_t pings = 0;            // pings read
  uint64_t pings_with_pose = 0;  // pings that got a DR pose (in the trajectories)
  uint64_t subframes = 0;
  uint64_t subframes_refused = 0;  // by the optimiser (no centre ping, distance not finite): a buffer bug
  std::string first_subframe_refusal;
  uint64_t pairs_attempted = 0;
  uint64_t matcher_closures = 0;   // closures the matcher produced (all rounds)
  uint64_t false_closures_injected = 0;  // of those, made wrong on purpose (false_closure_fraction)
  uint64_t closures_accepted = 0;  // by the optimiser, after full smoothing
  uint64_t closures_rejected = 0;
  // Still waiting at the end for the support they need (optimiser.graph.min_consistent_closures):
  // neither accepted nor rejected.
  uint64_t closures_pending = 0;
  uint64_t closures_superseded = 0;
  // Factors on the closure and odometry covariances learnt from the residuals at the final
  // smoothing (1 when optimiser.graph.variance_component_iterations is 0).
  sss::optimiser::VarianceFactors variance_factors;
  sss::optimiser::SeparationBias separation_bias;
  FixSummary fixes;
  // The DR calibration the final smoothing estimated (estimated: false when nothing observed it).
  sss::optimiser::DrCalibration calibration;
  // The INS's reported 1-sigma of its position at the first node, north and east (0: not reported):
  // the survey's anchor (SlidingWindowPoseGraph::setFirstNodeHorizontalSigma).
  Eigen::Vector2d anchor_ins_sigma_ne_m = Eigen::Vector2d::Zero();
  // The anchor's 1-sigma north and east as the graph held it (first_node_sigma_m, or the INS's
  // accuracy where wider and first_node_sigma_from_ins is on).
  Eigen::Vector2d anchor_sigma_ne_m = Eigen::Vector2d::Zero();
  // The odometry's drift fraction the graph ended with (per axis, of the distance between nodes):
  // the INS's own reported drift when odometry_drift_updates > 0, else the configured one.
  double odometry_drift_fraction = 0.0;
  double odometry_drift_fraction_configured = 0.0;
  uint64_t odometry_drift_updates = 0;
  // Seabed seen by the subframes under the SLAM poses (coverage.yaml), and by two lines or more.
  double coverage_covered_m2 = 0.0;
  double coverage_seen_twice_m2 = 0.0;
  uint64_t seabed_points = 0;
  // GeoTIFFs written (names in the output folder) and their CRS: the origin's UTM zone, the
  // projected input's products.projected_crs, or "" (a projected grid with no CRS named).
  std::vector<std::string> geotiffs;
  std::string geotiff_crs;
  int geotiff_epsg = 0;
  // The corrected copy of the sonar file (--write-corrected): its path, pings rewritten and pings
  // left with their recorded navigation (no pose at their time).
  std::string corrected_copy;
  uint64_t corrected_records = 0;
  uint64_t corrected_records_without_pose = 0;
  uint64_t corrected_records_without_position_field = 0;  // JSF message 82 records: left as recorded
  uint64_t input_faults = 0;       // corrupt records, bad messages, dropped pings
  // Where the pings went: the fusion's drops by cause and altitude sources, the line builder's.
  sss::subframe::SubframeBufferCounters buffer;
  sss::subframe::BottomTrackerCounters bottom_track;
  uint64_t pings_without_position = 0;  // embedded navigation: a ping header without a position
  uint64_t nav_from_packets = 0;        // navigation samples from the sonar file's own nav packets
  // Embedded navigation: samples that repeated the previous position (a recorder stamping every ping
  // with its newest GPS fix) and were interpolated in time between two new positions.
  uint64_t nav_positions_interpolated = 0;
  // Embedded navigation: headers without a valid heading (JSF validity bit 3 clear), given the
  // recorded course over ground, the track's direction, or left at the recorded value (no motion).
  uint64_t nav_headings_from_course = 0;
  uint64_t nav_headings_from_track = 0;
  uint64_t nav_headings_unknown = 0;
  // Samples without a heading of their own that took the next one to come (navigation messages
  // ahead of the first ping header, or headers without a heading before a valid one).
  uint64_t nav_headings_from_next = 0;
  // Embedded navigation of a towfish whose recorded positions are the ship's (XTF Layback over
  // SensorY/X equal to ShipY/X, or the JSF layback with sonar_driver.jsf_layback: apply): samples
  // moved back along their heading, the largest layback, and
  // samples left at the ship's position (no heading). xtf_layback_pings: pings that carried such
  // a layback (0 with sonar_driver.xtf_layback: ignore); xtf_layback_in_position_pings: a layback
  // over SensorY/X apart from ShipY/X (the writer applied it: used as recorded).
  uint64_t nav_laybacks_applied = 0;
  double nav_max_layback_m = 0.0;
  uint64_t nav_laybacks_without_heading = 0;
  uint64_t xtf_layback_pings = 0;
  uint64_t xtf_layback_in_position_pings = 0;
  // JSF: the side-scan subsystem used because the file holds none of sonar_driver.subsystem (-1: none).
  int jsf_adopted_subsystem = -1;
  // JSF side-scan messages of the older type 82 (no position of their own: NMEA, situation or --ins).
  uint64_t jsf_old_side_scan_messages = 0;
  // JSF side-scan records whose header carries a towfish layback, and the largest (applied only
  // with sonar_driver.jsf_layback: apply).
  uint64_t jsf_records_with_layback = 0;
  double jsf_max_layback_m = 0.0;
  uint64_t survey_lines = 0;
  // Lines holding fewer pings than one full subframe: short lines, or the pieces a turn slower than
  // the turn-rate threshold is cut into (a new line at every max_heading_deviation_rad of heading).
  uint64_t short_lines = 0;
  // Across-track distance of the nearest subframe of another line lying beside one (more across
  // than along); < 0: none beside another (one line, or lines following one another).
  double nearest_other_line_m = -1.0;
  double canonical_swath_m = 0.0;       // ground range per side of the subframes (bins x bin size)
  uint64_t pairs_few_matches = 0;       // pairs rejected for too few dense matches
  uint64_t pairs_pose_rejected = 0;     // pairs whose relative pose failed
  std::string first_pair_rejection;
  // One line each, cause and fix, when a stage yielded nothing (no pose, subframe, pair, closure).
  std::vector<std::string> findings;
  double mission_s = 0.0;          // first to last ping time
  double wall_s = 0.0;
  double matcher_s = 0.0;
  double optimiser_s = 0.0;
  double real_time_factor = 0.0;   // mission_s / wall_s
  double peak_rss_mib = 0.0;
};

struct OfflineResult {
  bool ok = false;
  // 0 ok (also with findings: a DR-only result is a result), 1 failure while writing, 2 unusable
  // input or configuration, 3 nothing could be processed: no ping got a pose or no subframe could
  // be built (the outputs and summary.json are written; error holds the first finding).
  int exit_code = 1;
  std::string error;      // one line, names the file
  OfflineSummary summary;
};

OfflineResult runOffline(const OfflineRequest& request);

}  // namespace sss::offline
