// What a run yields, and why not. See run_summary.hpp.
#include "tools/process/run_summary.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>

#include "tools/eval/json_values.hpp"

namespace sss::offline {

namespace {

std::string count(uint64_t n) { return std::to_string(static_cast<unsigned long long>(n)); }

}  // namespace

std::vector<std::string> explainRun(const OfflineSummary& s, const Options& options) {
  std::vector<std::string> findings;
  const auto& fusion = s.buffer.fusion;
  const uint64_t pings = s.pings;
  if (s.pings_with_pose == 0) {
    // The largest cause of loss first.
    const std::pair<uint64_t, std::string> causes[] = {
        {s.nav_from_packets > 0 ? 0 : s.pings_without_position,
         count(s.pings_without_position) + " of " + count(pings) + " ping headers carry no position: the file has no "
         "navigation of its own" +
             std::string(s.jsf_old_side_scan_messages > 0
                             ? " (its side-scan is in the older JSF message 82, which has no position field, and "
                               "it holds no NMEA or situation messages)"
                             : "") +
             "; give the INS file with --ins"},
        {fusion.dropped_no_altitude,
         count(fusion.dropped_no_altitude) + " of " + count(pings) + " pings have no altitude: the navigation and "
         "the ping headers carry none" +
             (options.buffer.fusion.altitude_source == sss::subframe::AltitudePolicy::kNav
                  ? "; set subframe_buffer.fusion.altitude_source: auto (tracks the bottom in the returns)"
                  : " and no seabed return was found in the sonar returns (bottom tracking found one in " +
                        count(s.bottom_track.detected) + " pings); check that the file holds the sonar's raw "
                        "returns from the water column down, or give an INS file with altitude (--ins)")},
        {fusion.dropped_nav_gap,
         count(fusion.dropped_nav_gap) + " of " + count(pings) + " pings fall between navigation samples more than " +
             std::to_string(options.buffer.fusion.max_nav_gap_s) + " s apart; raise subframe_buffer.fusion."
             "max_nav_gap_s to the navigation's sample interval"},
        {fusion.dropped_no_nav + fusion.dropped_too_old + fusion.dropped_before_first_fix,
         count(fusion.dropped_no_nav + fusion.dropped_too_old + fusion.dropped_before_first_fix) + " of " +
             count(pings) + " pings have no navigation at their time (" + count(fusion.dropped_before_first_fix) +
             " before the first fix): the INS file does not cover the sonar file's times (another day? a clock "
             "offset?); give the INS file recorded with it"},
        {fusion.pings_duplicate + fusion.pings_out_of_order,
         count(fusion.pings_duplicate + fusion.pings_out_of_order) + " of " + count(pings) +
             " pings repeat a ping number or go back in time; check the file's ping times"},
    };
    const auto* worst = &causes[0];
    for (const auto& cause : causes) {
      if (cause.first > worst->first) worst = &cause;
    }
    findings.push_back(worst->first > 0 ? "no ping got a pose: " + worst->second
                                        : "no ping got a pose (" + count(pings) + " pings, " + count(s.nav_samples) +
                                              " navigation samples)");
    return findings;
  }
  // XTF NavUnits 0 (metres) whose positions are degrees: read as metres, a survey of kilometres
  // moves millimetres, at a first fix within +-90 / +-180 of the grid's origin.
  if (s.projected_track_m >= 0.0 && s.projected_track_m < 1.0 && s.mission_s > 60.0 &&
      std::abs(s.projected_origin_northing_m) <= 90.0 && std::abs(s.projected_origin_easting_m) <= 180.0 &&
      !(s.projected_origin_northing_m == 0.0 && s.projected_origin_easting_m == 0.0)) {
    char text[512];
    std::snprintf(text, sizeof text,
                  "the file's positions are declared projected metres (XTF NavUnits 0) but move %.4f m in %.0f s "
                  "from (%.6f, %.6f): they look like latitude and longitude in degrees; set sonar_driver."
                  "xtf_nav_units: latlon",
                  s.projected_track_m, s.mission_s, s.projected_origin_northing_m, s.projected_origin_easting_m);
    findings.push_back(text);
  }
  if (s.jsf_adopted_subsystem >= 0) {
    findings.push_back("the file holds no side-scan records of sonar_driver.subsystem " +
                       std::to_string(options.sonar.assembler.subsystem) + ", only of subsystem " +
                       std::to_string(s.jsf_adopted_subsystem) + " (another frequency): that one was used");
  }
  if (s.jsf_records_with_layback > 0 && !options.sonar.apply_layback) {
    char text[64];
    std::snprintf(text, sizeof text, "%.1f m", s.jsf_max_layback_m);
    findings.push_back(count(s.jsf_records_with_layback) + " JSF sonar records carry a towfish layback (up to " +
                       std::string(text) + "); their positions are used as recorded. If those are the ship's GPS "
                       "rather than the fish's, set sonar_driver.jsf_layback: apply to move the fish back along its "
                       "heading");
  }
  if (s.nav_laybacks_applied > 0 || s.nav_laybacks_without_heading > 0) {
    char text[160];
    std::snprintf(text, sizeof text, "%.1f m", s.nav_max_layback_m);
    const bool jsf = s.jsf_records_with_layback > 0;
    findings.push_back(
        "the file's positions are the ship's with a towfish layback (" +
        std::string(jsf ? "JSF layback, up to " : "XTF Layback, up to ") + std::string(text) +
        (jsf ? ", sonar_driver.jsf_layback: apply" : ", SensorY/X equal to ShipY/X or unset") + "): " +
        count(s.nav_laybacks_applied) + " ping positions were moved back by it along the heading" +
        (s.nav_laybacks_without_heading > 0
             ? ", " + count(s.nav_laybacks_without_heading) + " left at the ship's for want of a heading"
             : std::string()) +
        "; if they are already the fish's, set sonar_driver." + (jsf ? "jsf_layback: ignore" : "xtf_layback: ignore"));
  }
  const uint64_t headings_missing = s.nav_headings_from_course + s.nav_headings_from_track + s.nav_headings_unknown;
  // A header or two (an XTF compass reading exactly north) is no missing compass.
  if (headings_missing > 0 && 100 * headings_missing > pings) {
    findings.push_back(
        count(headings_missing) + " of " + count(pings) + " ping headers carry no valid heading (a towfish without a "
        "compass): the course over ground stands in for it (" + count(s.nav_headings_from_course) + " recorded, " +
        count(s.nav_headings_from_track) + " from the track over 10 m" +
        (s.nav_headings_unknown > 0 ? ", " + count(s.nav_headings_unknown) + " left as recorded: no motion" : "") +
        "), so a crab angle turns the images; give the vehicle's INS file with --ins for its true heading");
  }
  if (s.subframes == 0) {
    const auto& builder = s.buffer.builder;
    std::string why;
    if (builder.lines == 0) {
      why = "no straight survey line was found: the " + count(s.pings_with_pose) + " pings with a pose are all in "
            "turns (" + count(builder.turn_pings) + ") or the heading wanders more than subframe_buffer.lines."
            "max_heading_deviation_rad; a curved line needs that raised";
    } else {
      why = "the " + count(builder.lines) + " survey line(s) are shorter than subframe_buffer.subframes.min_pings (" +
            std::to_string(options.buffer.subframes.min_pings) + " pings; " + count(builder.dropped_tail_pings) +
            " pings dropped as short tails); lower min_pings for short lines";
    }
    findings.push_back("no subframe: " + why);
    return findings;
  }
  if (s.subframes_refused > 0) {
    findings.push_back(count(s.subframes_refused) + " of " + count(s.subframes) + " subframes refused by the optimiser " +
                       "and left out (first: " + s.first_subframe_refusal + "); this is a bug in the subframe buffer, " +
                       "please report it with the input file");
  }
  // Most lines shorter than a subframe: the track turns slowly rather than running straight lines
  // joined by turns (a towed sonar behind a ship, a wide turn radius). Below the turn-rate threshold
  // a turn is cut into a new line at every max_heading_deviation_rad of heading.
  if (s.short_lines >= 2 && 2 * s.short_lines > s.survey_lines) {
    char text[768];
    std::snprintf(text, sizeof text,
                  "%llu of the %llu survey lines hold less than one subframe (%d pings): the track turns more "
                  "slowly than subframe_buffer.canonical.max_heading_rate_rad_s (%.3g rad/s), so a turn is not "
                  "left out but cut into a new line at every subframe_buffer.lines.max_heading_deviation_rad "
                  "(%.3g rad) of heading, and the pieces are matched like lines; if they are wide turns, "
                  "subframe_buffer.lines.curved_pieces_are_turns: true (or a lower max_heading_rate_rad_s) "
                  "leaves them out",
                  static_cast<unsigned long long>(s.short_lines), static_cast<unsigned long long>(s.survey_lines),
                  options.buffer.subframes.pings_per_subframe, options.buffer.canonical.max_heading_rate_rad_s,
                  options.buffer.lines.max_heading_deviation_rad);
    findings.push_back(text);
  }
  const double swath_m = s.canonical_swath_m;
  if (s.pairs_attempted == 0) {
    if (s.survey_lines < 2) {
      findings.push_back("no pair to match: every subframe is on one survey line; loop closures need a second line "
                         "over the same seabed (the result is dead reckoning)");
    } else if (s.nearest_other_line_m < 0.0) {
      findings.push_back("no pair to match: the " + count(s.survey_lines) + " survey lines follow one another along "
                         "one track (split where the heading changed), none runs beside another; loop closures need "
                         "a second pass over the same seabed (the result is dead reckoning)");
    } else {
      char text[512];
      if (options.buffer.canonical.swath_from_range && s.nearest_other_line_m > 2.0 * swath_m) {
        std::snprintf(text, sizeof text,
                      "no pair to match: the nearest lines run %.0f m apart, more than twice the %.0f m of seabed "
                      "the sonar records per side: no seabed is seen from two lines (closer lines or a longer "
                      "range would overlap)",
                      s.nearest_other_line_m, swath_m);
      } else if (options.buffer.canonical.swath_from_range) {
        // The swath is already the recorded range: what is missing is overlap, not swath.
        std::snprintf(text, sizeof text,
                      "no pair to match: the nearest lines run %.0f m apart, and the %.0f m of seabed the sonar "
                      "records per side leave their subframes less overlap than a pair needs "
                      "(matcher.overlap.min_overlap_fraction of the smaller footprint; fraction_of_swath: true "
                      "counts it per swath); closer lines or a longer "
                      "range would overlap",
                      s.nearest_other_line_m, swath_m);
      } else {
        std::snprintf(text, sizeof text,
                      "no pair to match: no two subframes of different lines overlap within the canonical swath of "
                      "%.0f m per side (the nearest lines run %.0f m apart); subframe_buffer.canonical."
                      "swath_from_range: true widens it to the sonar's recorded range (or set bins_per_side x "
                      "bin_size_m)",
                      swath_m, s.nearest_other_line_m);
      }
      findings.push_back(text);
    }
    return findings;
  }
  if (s.matcher_closures == 0) {
    findings.push_back("no loop closure: " + count(s.pairs_attempted) + " pair attempts, " +
                       count(s.pairs_few_matches) + " with too few dense matches (little overlap or texture), " +
                       count(s.pairs_pose_rejected) + " with a rejected relative pose; first: " + s.first_pair_rejection +
                       " (the result is dead reckoning)");
    return findings;
  }
  if (s.closures_accepted == 0) {
    // Pending closures were not found wrong: they lack independent support. Saying "rejected"
    // would send the user after a fault that is not there.
    const auto& graph = options.optimiser.graph;
    std::string text = "no closure accepted (the result is dead reckoning): ";
    if (s.closures_rejected > 0) {
      text += "the optimiser rejected " + count(s.closures_rejected) +
              " (inconsistent with dead reckoning or with each other; see loop_closures.csv)";
    }
    if (s.closures_pending > 0) {
      if (s.closures_rejected > 0) text += "; ";
      const bool one = s.closures_pending == 1;
      text += count(s.closures_pending) + (one ? " closure still waits" : " closures still wait") +
              " for support: a closure is trusted once " + std::to_string(graph.min_consistent_closures) +
              " mutually consistent closures" + (graph.pcm_count_independent_subframes ? " through different subframes" : "") +
              " back it (optimiser.graph.min_consistent_closures), and " + (one ? "it" : "these") +
              " had none (too few pairs between the lines: more overlap, another pass or a cross line would give " +
              (one ? "it" : "them") + " support)";
    }
    if (s.closures_rejected == 0 && s.closures_pending == 0) {
      text += "the " + count(s.matcher_closures) + " closures of the matcher were all superseded or refused (see "
              "loop_closures.csv)";
    }
    findings.push_back(text);
  }
  // DR strained beyond its own error model: on the randomised missions this marked exactly the
  // runs SLAM made worse than DR (closures with an error common to a pair, relief at far range).
  const double strain = s.variance_factors.odometry_strain;
  if (s.closures_accepted > 0 && std::isfinite(strain) && strain > 1.0) {
    char text[512];
    std::snprintf(text, sizeof(text),
                  "the accepted closures bend dead reckoning %.1fx beyond its error model (variance; "
                  "optimiser.graph.odometry_*): closures sharing an error (a biased pair, relief at far range) are "
                  "likely, and SLAM may be worse than dead reckoning here: compare loop_closures.csv with the DR "
                  "and SLAM mosaics before using slam.tum over dead_reckoning.tum",
                  strain);
    findings.push_back(text);
  }
  // Opposite-side closures and DR disagree on how far apart the lines run, all pairs alike.
  const sss::optimiser::SeparationBias& bias = s.separation_bias;
  if (bias.significant && !bias.applied) {
    char text[640];
    std::snprintf(text, sizeof(text),
                  "the closures between lines that look at their overlap from opposite sides put the lines %.2f m "
                  "%s together than dead reckoning does (+- %.2f m, over %d closures, every pair alike): either raised "
                  "features (rocks, boulders) show each line their near face and bias the matches, or dead reckoning's "
                  "turns between lines are off (a DVL scale factor); cross lines or fixes tell the two apart. "
                  "optimiser.graph.separation_bias_apply: true corrects the closures by it",
                  std::abs(bias.tested_m), bias.tested_m > 0.0 ? "closer" : "further", bias.sigma_m, bias.closures);
    findings.push_back(text);
  }
  return findings;
}

// One line each for fixes that were given but not used, naming the cause and the fix.
std::vector<std::string> explainFixes(const FixSummary& f, const Options& options) {
  std::vector<std::string> findings;
  if (f.files == 0) return findings;
  char text[640];
  if (f.read == 0) {
    std::snprintf(text, sizeof text,
                  "the %llu fix file(s) hold no usable fix (GGA sentences with a fix; %llu sentences skipped%s%s)",
                  static_cast<unsigned long long>(f.files), static_cast<unsigned long long>(f.sentences_skipped),
                  f.first_problem.empty() ? "" : ", first: ", f.first_problem.c_str());
    findings.push_back(text);
    return findings;
  }
  if (f.no_frame > 0) {
    std::snprintf(text, sizeof text,
                  "%llu fixes not used: the mission frame is the sonar file's projected grid without a CRS, so "
                  "latitude/longitude fixes cannot be placed in it; give the INS file (--ins) or configure "
                  "mission.origin_latitude_deg/origin_longitude_deg",
                  static_cast<unsigned long long>(f.no_frame));
    findings.push_back(text);
  }
  if (f.outside_navigation > 0) {
    std::snprintf(text, sizeof text,
                  "%llu of %llu fixes fall outside the navigation's time span (more than %.1f s before it starts or "
                  "after it ends): check that the fix file belongs to this mission and its dates (files without "
                  "ZDA/RMC are dated from the navigation's first day)",
                  static_cast<unsigned long long>(f.outside_navigation), static_cast<unsigned long long>(f.read),
                  options.fix_aligner.max_extrapolation_s);
    findings.push_back(text);
  }
  if (f.below_surface > 0 && f.below_surface == f.gnss) {
    std::snprintf(text, sizeof text,
                  "all %llu GNSS fixes came while the vehicle was deeper than fixes.gnss_max_depth_m (%.1f m) and were "
                  "ignored (a receiver under water reports stale positions); if they are the ship's USBL, name the file "
                  "usbl:PATH",
                  static_cast<unsigned long long>(f.below_surface), options.fix_aligner.gnss_max_depth_m);
    findings.push_back(text);
  }
  if (f.fed > 0 && f.accepted == 0) {
    std::snprintf(text, sizeof text,
                  "none of the %llu fixes given to the optimiser was accepted (%llu rejected by the gate against "
                  "dead reckoning; see fixes.csv): fixes and navigation disagree, check the fixes' datum and time",
                  static_cast<unsigned long long>(f.fed), static_cast<unsigned long long>(f.rejected_gate));
    findings.push_back(text);
  }
  return findings;
}

// ---- outputs -----------------------------------------------------------------------------------

sss::core::Status writeSummaryJson(const std::string& path, const OfflineRequest& request, const OfflineSummary& s) {
  using sss::eval::Json;
  using sss::eval::jsonValue;
  Json json = Json::object();
  json["schema"] = jsonValue("sss-process/1");
  Json& inputs_json = (json["inputs"] = Json::object());
  inputs_json["sonar"] = jsonValue(request.sonar_path);
  inputs_json["ins"] = jsonValue(request.ins_path);
  inputs_json["lcm_log"] = jsonValue(request.lcm_log_path);
  inputs_json["config"] = jsonValue(request.config_path);
  // The frame of every trajectory, heightmap and point cloud of the run (local NED of this point).
  Json& origin_json = (json["origin"] = Json::object());
  if (s.origin) {
    origin_json["latitude_deg"] = jsonValue(s.origin->latitude_deg, 13);
    origin_json["longitude_deg"] = jsonValue(s.origin->longitude_deg, 13);
  }
  if (s.origin_source == "projected_first_fix") {
    origin_json["projected_easting_m"] = jsonValue(s.projected_origin_easting_m, 12);
    origin_json["projected_northing_m"] = jsonValue(s.projected_origin_northing_m, 12);
  }
  origin_json["source"] = jsonValue(s.origin_source);
  origin_json["detail"] = jsonValue(s.origin_detail);
  const std::pair<const char*, uint64_t> counts[] = {
      {"nav_samples", s.nav_samples},         {"pings", s.pings},
      {"pings_with_pose", s.pings_with_pose}, {"subframes", s.subframes},
      {"subframes_refused", s.subframes_refused},
      {"pairs_attempted", s.pairs_attempted}, {"matcher_closures", s.matcher_closures},
      {"false_closures_injected", s.false_closures_injected},
      {"closures_accepted", s.closures_accepted}, {"closures_rejected", s.closures_rejected},
      {"closures_pending", s.closures_pending}, {"closures_superseded", s.closures_superseded}, {"seabed_points", s.seabed_points},
      {"input_faults", s.input_faults}};
  for (const auto& [name, value] : counts) json[name] = jsonValue(value);
  const auto& fusion = s.buffer.fusion;
  Json& navigation_json = (json["navigation"] = Json::object());
  navigation_json["ping_headers_without_position"] = jsonValue(s.pings_without_position);
  navigation_json["samples_from_nav_packets"] = jsonValue(s.nav_from_packets);  // XTF attitude/navigation packets
  // ping headers repeating the previous position (no new fix), placed between the fixes in time
  navigation_json["positions_interpolated"] = jsonValue(s.nav_positions_interpolated);
  // ping headers without a valid heading: what stood in for it
  navigation_json["headings_from_course"] = jsonValue(s.nav_headings_from_course);
  navigation_json["headings_from_track"] = jsonValue(s.nav_headings_from_track);
  navigation_json["headings_unknown"] = jsonValue(s.nav_headings_unknown);
  navigation_json["headings_from_next_header"] = jsonValue(s.nav_headings_from_next);
  // a towfish's layback applied to positions that were the ship's (XTF Layback, JSF with jsf_layback: apply)
  navigation_json["laybacks_applied"] = jsonValue(s.nav_laybacks_applied);
  navigation_json["max_layback_m"] = jsonValue(s.nav_max_layback_m);
  navigation_json["laybacks_without_heading"] = jsonValue(s.nav_laybacks_without_heading);
  navigation_json["xtf_layback_over_ship_position"] = jsonValue(s.xtf_layback_pings);
  navigation_json["xtf_layback_in_position"] = jsonValue(s.xtf_layback_in_position_pings);
  json["jsf_old_side_scan_messages"] = jsonValue(s.jsf_old_side_scan_messages);
  json["jsf_records_with_layback"] = jsonValue(s.jsf_records_with_layback);
  json["jsf_max_layback_m"] = jsonValue(s.jsf_max_layback_m);
  json["jsf_subsystem_adopted"] = s.jsf_adopted_subsystem >= 0 ? jsonValue(static_cast<uint64_t>(s.jsf_adopted_subsystem)) : Json();
  navigation_json["samples_without_position"] = jsonValue(fusion.nav_without_position);
  Json& pings_dropped_json = (json["pings_dropped"] = Json::object());
  const std::pair<const char*, uint64_t> drops[] = {
      {"before_first_fix", fusion.dropped_before_first_fix},
      {"no_nav", fusion.dropped_no_nav},
      {"older_than_nav_history", fusion.dropped_too_old},
      {"nav_gap", fusion.dropped_nav_gap},
      {"no_altitude", fusion.dropped_no_altitude},
      {"duplicate", fusion.pings_duplicate},
      {"out_of_order", fusion.pings_out_of_order}};
  for (const auto& [name, value] : drops) pings_dropped_json[name] = jsonValue(value);
  Json& altitude_sources_json = (json["altitude_sources"] = Json::object());
  altitude_sources_json["nav"] = jsonValue(fusion.altitude_from_nav);
  altitude_sources_json["ping_header"] = jsonValue(fusion.altitude_from_ping);
  altitude_sources_json["bottom_track"] = jsonValue(fusion.altitude_from_bottom_track);
  altitude_sources_json["implausible_rejected"] = jsonValue(fusion.altitude_implausible);
  Json& bottom_track_json = (json["bottom_track"] = Json::object());
  bottom_track_json["pings"] = jsonValue(s.bottom_track.pings);
  bottom_track_json["detected"] = jsonValue(s.bottom_track.detected);
  bottom_track_json["one_side_only"] = jsonValue(s.bottom_track.one_side_only);
  bottom_track_json["outliers"] = jsonValue(s.bottom_track.outliers);
  bottom_track_json["scale_applied"] = jsonValue(fusion.bottom_track_scale, 6);
  Json& variance_factors_json = (json["variance_factors"] = Json::object());  // what the graph learnt of its own weights
  variance_factors_json["closure"] = jsonValue(s.variance_factors.closure, 6);
  variance_factors_json["odometry"] = jsonValue(s.variance_factors.odometry, 6);
  variance_factors_json["closure_redundancy"] = jsonValue(s.variance_factors.closure_redundancy, 4);
  variance_factors_json["odometry_redundancy"] = jsonValue(s.variance_factors.odometry_redundancy, 4);
  variance_factors_json["odometry_strain"] = jsonValue(s.variance_factors.odometry_strain, 4);
  variance_factors_json["closures"] = jsonValue(static_cast<uint64_t>(s.variance_factors.closures));
  variance_factors_json["iterations"] = jsonValue(static_cast<uint64_t>(s.variance_factors.iterations));
  Json& separation_bias_json = (json["separation_bias"] = Json::object());  // how much closer opposite-side closures put the lines
  separation_bias_json["estimate_m"] = jsonValue(s.separation_bias.tested_m, 4);
  separation_bias_json["sigma_m"] = jsonValue(s.separation_bias.sigma_m, 4);
  separation_bias_json["significant"] = jsonValue(s.separation_bias.significant);
  separation_bias_json["applied"] = jsonValue(s.separation_bias.applied);
  separation_bias_json["closures"] = jsonValue(static_cast<uint64_t>(s.separation_bias.closures));
  Json& fixes_json = (json["fixes"] = Json::object());  // absolute fixes (--fixes): what was read and what became of it
  fixes_json["files"] = jsonValue(s.fixes.files);
  fixes_json["read"] = jsonValue(s.fixes.read);
  fixes_json["gnss"] = jsonValue(s.fixes.gnss);
  fixes_json["usbl"] = jsonValue(s.fixes.usbl);
  fixes_json["sentences_skipped"] = jsonValue(s.fixes.sentences_skipped);
  fixes_json["first_problem"] = jsonValue(s.fixes.first_problem);
  fixes_json["below_surface"] = jsonValue(s.fixes.below_surface);
  fixes_json["outside_navigation"] = jsonValue(s.fixes.outside_navigation);
  fixes_json["no_geographic_frame"] = jsonValue(s.fixes.no_frame);
  fixes_json["fed"] = jsonValue(s.fixes.fed);
  fixes_json["accepted"] = jsonValue(s.fixes.accepted);
  fixes_json["rejected_gate"] = jsonValue(s.fixes.rejected_gate);
  fixes_json["refused"] = jsonValue(s.fixes.refused);
  fixes_json["rms_residual_m"] = jsonValue(s.fixes.rms_residual_m, 4);
  fixes_json["accepted_independent_equivalent"] = jsonValue(s.fixes.accepted_independent_equivalent, 3);
  Json& coverage_json = (json["coverage"] = Json::object());  // coverage.yaml: how many lines saw each 5 m cell (SLAM poses)
  coverage_json["covered_m2"] = jsonValue(s.coverage_covered_m2, 8);
  coverage_json["seen_twice_m2"] = jsonValue(s.coverage_seen_twice_m2, 8);
  coverage_json["fraction_seen_twice"] = jsonValue(s.coverage_covered_m2 > 0.0 ? s.coverage_seen_twice_m2 / s.coverage_covered_m2 : 0.0, 4);
  // INS heading error (closures and fixes observe it) and DVL scale (with fixes only; else 0, sigma null)
  Json& calibration_json = (json["calibration"] = Json::object());
  calibration_json["estimated"] = jsonValue(s.calibration.estimated);
  calibration_json["dvl_scale_estimated"] = jsonValue(s.calibration.scale_estimated);
  calibration_json["dvl_scale"] = jsonValue(s.calibration.dvl_scale, 6);
  calibration_json["dvl_scale_sigma"] = jsonValue(s.calibration.sigma(0), 6);
  calibration_json["heading_bias_rad"] = jsonValue(s.calibration.heading_bias_rad, 6);
  calibration_json["heading_bias_sigma_rad"] = jsonValue(s.calibration.sigma(1), 6);
  calibration_json["heading_cos_rad"] = jsonValue(s.calibration.heading_cos_rad, 6);
  calibration_json["heading_cos_sigma_rad"] = jsonValue(s.calibration.sigma(2), 6);
  calibration_json["heading_sin_rad"] = jsonValue(s.calibration.heading_sin_rad, 6);
  calibration_json["heading_sin_sigma_rad"] = jsonValue(s.calibration.sigma(3), 6);
  // The survey's anchor: the first node's DR position, held to first_node_sigma_m or to the INS's own
  // reported accuracy there, whichever is wider (0: the INS reported none).
  Json& anchor_json = (json["anchor"] = Json::object());
  anchor_json["ins_position_sigma_north_m"] = jsonValue(s.anchor_ins_sigma_ne_m(0), 4);
  anchor_json["ins_position_sigma_east_m"] = jsonValue(s.anchor_ins_sigma_ne_m(1), 4);
  anchor_json["sigma_north_m"] = jsonValue(s.anchor_sigma_ne_m(0), 4);
  anchor_json["sigma_east_m"] = jsonValue(s.anchor_sigma_ne_m(1), 4);
  // The odometry's drift per metre travelled: the INS's own (from the growth of its reported
  // position accuracy) when it reported one, else the configured odometry_drift_fraction.
  Json& odometry_json = (json["odometry"] = Json::object());
  odometry_json["drift_fraction"] = jsonValue(s.odometry_drift_fraction, 6);
  odometry_json["drift_from_ins"] = s.odometry_drift_updates > 0;
  odometry_json["drift_updates"] = jsonValue(s.odometry_drift_updates);
  odometry_json["configured_drift_fraction"] = jsonValue(s.odometry_drift_fraction_configured, 6);
  Json& lines_json = (json["lines"] = Json::object());
  lines_json["survey_lines"] = jsonValue(s.survey_lines);
  lines_json["short_lines"] = jsonValue(s.short_lines);
  lines_json["turn_pings"] = jsonValue(s.buffer.builder.turn_pings);
  lines_json["short_tail_pings"] = jsonValue(s.buffer.builder.dropped_tail_pings);
  lines_json["curved_pieces"] = jsonValue(s.buffer.builder.curved_pieces);
  lines_json["nearest_other_line_m"] = jsonValue(s.nearest_other_line_m, 6);
  lines_json["canonical_swath_m"] = jsonValue(s.canonical_swath_m, 6);
  Json& pairs_rejected_json = (json["pairs_rejected"] = Json::object());
  pairs_rejected_json["few_dense_matches"] = jsonValue(s.pairs_few_matches);
  pairs_rejected_json["relative_pose"] = jsonValue(s.pairs_pose_rejected);
  pairs_rejected_json["first_reason"] = jsonValue(s.first_pair_rejection);
  // The GeoTIFFs written and their CRS (QGIS and gdalinfo read it from the files too).
  Json& corrected_copy_json = (json["corrected_copy"] = Json::object());
  corrected_copy_json["path"] = jsonValue(s.corrected_copy);
  corrected_copy_json["pings_corrected"] = jsonValue(s.corrected_records);
  corrected_copy_json["pings_without_pose"] = jsonValue(s.corrected_records_without_pose);
  Json& geotiff_json = (json["geotiff"] = Json::object());
  geotiff_json["crs"] = jsonValue(s.geotiff_crs);
  geotiff_json["epsg"] = jsonValue(static_cast<uint64_t>(s.geotiff_epsg));
  Json& files_json = (geotiff_json["files"] = Json::array());
  for (const std::string& file : s.geotiffs) files_json.push_back(jsonValue(file));
  Json& findings_json = (json["findings"] = Json::array());
  for (const std::string& finding : s.findings) findings_json.push_back(jsonValue(finding));
  const std::pair<const char*, double> figures[] = {
      {"mission_s", s.mission_s},     {"wall_s", s.wall_s},
      {"matcher_s", s.matcher_s},     {"optimiser_s", s.optimiser_s},
      {"real_time_factor", s.real_time_factor}, {"peak_rss_mib", s.peak_rss_mib}};
  for (const auto& [name, value] : figures) json[name] = jsonValue(value, 6);
  std::ofstream out(path);
  out << json.dump(2) << "\n";
  if (!out) {
    return sss::core::Status::error("cannot write " + path);
  }
  return sss::core::Status::success();
}


}  // namespace sss::offline
