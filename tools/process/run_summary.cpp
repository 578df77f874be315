// What a run yields, and why not. See run_summary.hpp.
#include "tools/process/run_summary.hpp"

#include <cstdint>
#include <fstream>

#include "tools/eval/json_writer.hpp"

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
         "navigation of its own; give the INS file with --ins"},
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
    findings.push_back("no closure accepted: the optimiser rejected all " + count(s.matcher_closures) +
                       " (inconsistent with dead reckoning and with each other; see loop_closures.csv); the result is "
                       "dead reckoning");
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

bool writeSummaryJson(const std::string& path, const OfflineRequest& request, const OfflineSummary& s,
                      std::string& error) {
  sss::eval::JsonWriter json;
  json.beginObject();
  json.key("schema").value("sss-process/1");
  json.key("inputs").beginObject();
  json.key("sonar").value(request.sonar_path);
  json.key("ins").value(request.ins_path);
  json.key("lcm_log").value(request.lcm_log_path);
  json.key("config").value(request.config_path);
  json.endObject();
  // The frame of every trajectory, heightmap and point cloud of the run (local NED of this point).
  json.key("origin").beginObject();
  if (s.origin) {
    json.key("latitude_deg").value(s.origin->latitude_deg, 13);
    json.key("longitude_deg").value(s.origin->longitude_deg, 13);
  }
  if (s.origin_source == "projected_first_fix") {
    json.key("projected_easting_m").value(s.projected_origin_easting_m, 12);
    json.key("projected_northing_m").value(s.projected_origin_northing_m, 12);
  }
  json.key("source").value(s.origin_source);
  json.key("detail").value(s.origin_detail);
  json.endObject();
  const std::pair<const char*, uint64_t> counts[] = {
      {"nav_samples", s.nav_samples},         {"pings", s.pings},
      {"pings_with_pose", s.pings_with_pose}, {"subframes", s.subframes},
      {"pairs_attempted", s.pairs_attempted}, {"matcher_closures", s.matcher_closures},
      {"false_closures_injected", s.false_closures_injected},
      {"closures_accepted", s.closures_accepted}, {"closures_rejected", s.closures_rejected},
      {"closures_superseded", s.closures_superseded}, {"seabed_points", s.seabed_points},
      {"input_faults", s.input_faults}};
  for (const auto& [name, value] : counts) json.key(name).value(value);
  const auto& fusion = s.buffer.fusion;
  json.key("navigation").beginObject();
  json.key("ping_headers_without_position").value(s.pings_without_position);
  json.key("samples_from_nav_packets").value(s.nav_from_packets);  // XTF attitude/navigation packets
  json.key("samples_without_position").value(fusion.nav_without_position);
  json.endObject();
  json.key("pings_dropped").beginObject();
  const std::pair<const char*, uint64_t> drops[] = {
      {"before_first_fix", fusion.dropped_before_first_fix},
      {"no_nav", fusion.dropped_no_nav},
      {"older_than_nav_history", fusion.dropped_too_old},
      {"nav_gap", fusion.dropped_nav_gap},
      {"no_altitude", fusion.dropped_no_altitude},
      {"duplicate", fusion.pings_duplicate},
      {"out_of_order", fusion.pings_out_of_order}};
  for (const auto& [name, value] : drops) json.key(name).value(value);
  json.endObject();
  json.key("altitude_sources").beginObject();
  json.key("nav").value(fusion.altitude_from_nav);
  json.key("ping_header").value(fusion.altitude_from_ping);
  json.key("bottom_track").value(fusion.altitude_from_bottom_track);
  json.key("implausible_rejected").value(fusion.altitude_implausible);
  json.endObject();
  json.key("bottom_track").beginObject();
  json.key("pings").value(s.bottom_track.pings);
  json.key("detected").value(s.bottom_track.detected);
  json.key("one_side_only").value(s.bottom_track.one_side_only);
  json.key("outliers").value(s.bottom_track.outliers);
  json.key("scale_applied").value(fusion.bottom_track_scale, 6);
  json.endObject();
  json.key("variance_factors").beginObject();  // what the graph learnt of its own weights
  json.key("closure").value(s.variance_factors.closure, 6);
  json.key("odometry").value(s.variance_factors.odometry, 6);
  json.key("closure_redundancy").value(s.variance_factors.closure_redundancy, 4);
  json.key("odometry_redundancy").value(s.variance_factors.odometry_redundancy, 4);
  json.key("odometry_strain").value(s.variance_factors.odometry_strain, 4);
  json.key("closures").value(static_cast<uint64_t>(s.variance_factors.closures));
  json.key("iterations").value(static_cast<uint64_t>(s.variance_factors.iterations));
  json.endObject();
  json.key("separation_bias").beginObject();  // how much closer opposite-side closures put the lines
  json.key("estimate_m").value(s.separation_bias.tested_m, 4);
  json.key("sigma_m").value(s.separation_bias.sigma_m, 4);
  json.key("significant").value(s.separation_bias.significant);
  json.key("applied").value(s.separation_bias.applied);
  json.key("closures").value(static_cast<uint64_t>(s.separation_bias.closures));
  json.endObject();
  json.key("fixes").beginObject();  // absolute fixes (--fixes): what was read and what became of it
  json.key("files").value(s.fixes.files);
  json.key("read").value(s.fixes.read);
  json.key("gnss").value(s.fixes.gnss);
  json.key("usbl").value(s.fixes.usbl);
  json.key("sentences_skipped").value(s.fixes.sentences_skipped);
  json.key("first_problem").value(s.fixes.first_problem);
  json.key("below_surface").value(s.fixes.below_surface);
  json.key("outside_navigation").value(s.fixes.outside_navigation);
  json.key("no_geographic_frame").value(s.fixes.no_frame);
  json.key("fed").value(s.fixes.fed);
  json.key("accepted").value(s.fixes.accepted);
  json.key("rejected_gate").value(s.fixes.rejected_gate);
  json.key("refused").value(s.fixes.refused);
  json.key("rms_residual_m").value(s.fixes.rms_residual_m, 4);
  json.endObject();
  json.key("coverage").beginObject();  // coverage.yaml: how many lines saw each 5 m cell (SLAM poses)
  json.key("covered_m2").value(s.coverage_covered_m2, 8);
  json.key("seen_twice_m2").value(s.coverage_seen_twice_m2, 8);
  json.key("fraction_seen_twice").value(s.coverage_covered_m2 > 0.0 ? s.coverage_seen_twice_m2 / s.coverage_covered_m2 : 0.0, 4);
  json.endObject();
  // INS heading error (closures and fixes observe it) and DVL scale (with fixes only; else 0, sigma null)
  json.key("calibration").beginObject();
  json.key("estimated").value(s.calibration.estimated);
  json.key("dvl_scale_estimated").value(s.calibration.scale_estimated);
  json.key("dvl_scale").value(s.calibration.dvl_scale, 6);
  json.key("dvl_scale_sigma").value(s.calibration.sigma(0), 6);
  json.key("heading_bias_rad").value(s.calibration.heading_bias_rad, 6);
  json.key("heading_bias_sigma_rad").value(s.calibration.sigma(1), 6);
  json.key("heading_cos_rad").value(s.calibration.heading_cos_rad, 6);
  json.key("heading_cos_sigma_rad").value(s.calibration.sigma(2), 6);
  json.key("heading_sin_rad").value(s.calibration.heading_sin_rad, 6);
  json.key("heading_sin_sigma_rad").value(s.calibration.sigma(3), 6);
  json.endObject();
  json.key("lines").beginObject();
  json.key("survey_lines").value(s.survey_lines);
  json.key("turn_pings").value(s.buffer.builder.turn_pings);
  json.key("short_tail_pings").value(s.buffer.builder.dropped_tail_pings);
  json.key("nearest_other_line_m").value(s.nearest_other_line_m, 6);
  json.key("canonical_swath_m").value(s.canonical_swath_m, 6);
  json.endObject();
  json.key("pairs_rejected").beginObject();
  json.key("few_dense_matches").value(s.pairs_few_matches);
  json.key("relative_pose").value(s.pairs_pose_rejected);
  json.key("first_reason").value(s.first_pair_rejection);
  json.endObject();
  // The GeoTIFFs written and their CRS (QGIS and gdalinfo read it from the files too).
  json.key("corrected_copy").beginObject();
  json.key("path").value(s.corrected_copy);
  json.key("pings_corrected").value(s.corrected_records);
  json.key("pings_without_pose").value(s.corrected_records_without_pose);
  json.endObject();
  json.key("geotiff").beginObject();
  json.key("crs").value(s.geotiff_crs);
  json.key("epsg").value(static_cast<uint64_t>(s.geotiff_epsg));
  json.key("files").beginArray();
  for (const std::string& file : s.geotiffs) json.value(file);
  json.endArray();
  json.endObject();
  json.key("findings").beginArray();
  for (const std::string& finding : s.findings) json.value(finding);
  json.endArray();
  const std::pair<const char*, double> figures[] = {
      {"mission_s", s.mission_s},     {"wall_s", s.wall_s},
      {"matcher_s", s.matcher_s},     {"optimiser_s", s.optimiser_s},
      {"real_time_factor", s.real_time_factor}, {"peak_rss_mib", s.peak_rss_mib}};
  for (const auto& [name, value] : figures) json.key(name).value(value, 6);
  json.endObject();
  std::ofstream out(path);
  out << json.str() << "\n";
  if (!out) {
    error = "cannot write " + path;
    return false;
  }
  return true;
}


}  // namespace sss::offline
