// sss-process's engine: inputs in time order through the chain's libraries, then the outputs.
// See offline_runner.hpp.
#include "tools/process/offline_runner.hpp"

#include "tools/process/offline_inputs.hpp"
#include "tools/process/offline_runner_internal.hpp"
#include "tools/process/run_summary.hpp"

namespace sss::offline {

namespace fs = std::filesystem;
using sss::core::Pose;

OfflineResult runOffline(const OfflineRequest& request) {
  OfflineResult result;
  result.exit_code = 2;
  const bool from_log = !request.lcm_log_path.empty();
  if (from_log == !request.sonar_path.empty()) {
    result.error = "give either a sonar file (--sonar) or an LCM log (--lcm-log)";
    return result;
  }
  if (from_log && !request.corrected_dir.empty()) {
    result.error = "--write-corrected copies a sonar file: give --sonar, not --lcm-log";
    return result;
  }
  if (request.out_dir.empty()) {
    result.error = "no output folder (--out)";
    return result;
  }
  Options options;
  if (const sss::core::Status read = readOptions(request.config_path, options); !read) {
    result.error = read.message;
    return result;
  }
  for (const std::string& path : {request.sonar_path, request.ins_path, request.lcm_log_path}) {
    if (path.empty()) continue;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
      result.error = "cannot read " + path + ": no such file";
      return result;
    }
  }
  std::error_code ec;
  fs::create_directories(request.out_dir, ec);
  if (ec || !fs::is_directory(request.out_dir)) {
    result.error = "cannot create the output folder " + request.out_dir + (ec ? ": " + ec.message() : "");
    result.exit_code = 1;
    return result;
  }

  std::vector<sss::ins::PositionFix> fixes;
  FixSummary fix_summary;
  for (const std::string& spec : request.fix_paths) {
    const sss::core::Result<sss::ins::FixFileContents> contents = sss::ins::readPositionFixFile(spec, options.fix_reader);
    if (!contents) {
      result.error = contents.message();
      return result;
    }
    const std::vector<sss::ins::PositionFix>& read = contents->fixes;
    const sss::ins::FixReaderCounters& counters = contents->counters;
    const std::string& problem = contents->first_problem;
    ++fix_summary.files;
    fix_summary.read += read.size();
    fix_summary.sentences_skipped += counters.rejected_sentences + counters.malformed + counters.no_fix;
    if (fix_summary.first_problem.empty() && !problem.empty()) fix_summary.first_problem = spec + ": " + problem;
    for (const auto& fix : read) ++(fix.source == sss::ins::FixSource::kGnss ? fix_summary.gnss : fix_summary.usbl);
    if (request.progress) {
      std::fprintf(request.progress, "sss-process: %zu fixes from %s (%llu GNSS, %llu USBL so far)%s%s\n", read.size(),
                   spec.c_str(), static_cast<unsigned long long>(fix_summary.gnss),
                   static_cast<unsigned long long>(fix_summary.usbl), problem.empty() ? "" : "; skipped: ",
                   problem.c_str());
    }
    fixes.insert(fixes.end(), read.begin(), read.end());
  }

  Runner runner(request, options);
  runner.summary().fixes = fix_summary;
  runner.setFixes(std::move(fixes));
  if (request.write_matches) {
    if (const sss::core::Status opened = runner.openMatchWriter(); !opened) {
      result.error = opened.message;
      result.exit_code = 1;
      return result;
    }
  }
  uint64_t faults = 0;
  std::optional<Eigen::Vector2d> projected_origin;  // a projected frame (XTF NavUnits 0): E0, N0
  if (from_log) {
    lcm::LogFile log(request.lcm_log_path, "r");
    if (!log.good()) {
      result.error = "cannot read the LCM log " + request.lcm_log_path;
      return result;
    }
    const uint64_t size = fs::file_size(request.lcm_log_path, ec);
    uint64_t events = 0;
    for (const lcm::LogEvent* event = log.readNextEvent(); event; event = log.readNextEvent()) {
      if (event->channel == request.nav_channel) {
        sss_msgs::nav_t message;
        if (message.decode(event->data, 0, event->datalen) < 0) {
          ++faults;
          continue;
        }
        runner.addNav(sss::messages::fromNavMessage(message));
      } else if (event->channel == request.ping_channel) {
        sss_msgs::ping_t message;
        if (message.decode(event->data, 0, event->datalen) < 0) {
          ++faults;
          continue;
        }
        runner.addPing(sss::messages::fromPingMessage(message));
      }
      if (++events % 256 == 0 && size > 0) {
        runner.progress(static_cast<double>(std::ftell(log.getFilePtr())) / static_cast<double>(size), false);
      }
    }
    if (runner.summary().pings == 0) {
      result.error = "the LCM log " + request.lcm_log_path + " has no " + request.ping_channel + " messages";
      return result;
    }
  } else {
    std::unique_ptr<PingSource> pings;
    const JsfSource* jsf_source = nullptr;  // the JSF reader, when the file is one
    const XtfSource* xtf_source = nullptr;  // the XTF reader, when the file is one
    if (hasExtension(request.sonar_path, ".xtf")) {
      auto xtf = std::make_unique<XtfSource>(request.sonar_path, options.xtf);
      if (!xtf->reader().isOpen()) {
        result.error = "cannot read " + request.sonar_path + ": " + xtf->reader().error();
        return result;
      }
      xtf_source = xtf.get();
      pings = std::move(xtf);
    } else if (hasExtension(request.sonar_path, ".jsf")) {
      auto jsf = std::make_unique<JsfSource>(request.sonar_path, options.sonar);
      if (!jsf->good()) {
        result.error = "cannot read " + request.sonar_path;
        return result;
      }
      jsf_source = jsf.get();
      pings = std::move(jsf);
    } else {
      result.error = "unknown sonar file type " + request.sonar_path + " (expected .jsf or .xtf)";
      return result;
    }
    std::unique_ptr<InsFileSource> ins;
    std::optional<EmbeddedNavigation> embedded;
    if (!request.ins_path.empty()) {
      ins = std::make_unique<InsFileSource>(request.ins_path, options.ins);
      if (!ins->good()) {
        result.error = "cannot read " + request.ins_path;
        return result;
      }
    } else {
      embedded.emplace(options.origin);
    }
    // Merge by time: nav before a ping of the same time, so the ping finds its bracketing nav.
    // Everything goes through the SSS_PING and SSS_NAV messages, exactly as in the live chain.
    std::unique_ptr<lcm::LogFile> recording;
    if (!request.record_lcm_log_path.empty()) {
      recording = std::make_unique<lcm::LogFile>(request.record_lcm_log_path, "w");
      if (!recording->good()) {
        result.error = "cannot write the LCM log " + request.record_lcm_log_path;
        result.exit_code = 1;
        return result;
      }
    }
    int64_t event_number = 0;
    auto record = [&](const std::string& channel, const auto& message, int64_t utime_us) {
      if (!recording) return;
      std::vector<uint8_t> bytes(static_cast<size_t>(message.getEncodedSize()));
      message.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
      lcm::LogEvent event;
      event.eventnum = event_number++;
      event.timestamp = utime_us;
      event.channel = channel;
      event.datalen = static_cast<int32_t>(bytes.size());
      event.data = bytes.data();
      recording->writeEvent(&event);
    };
    std::deque<sss::sonar::DriverPing> ping_queue;
    std::deque<sss_msgs::nav_t> nav_queue;
    // Navigation packets of the sonar file (XTF 3/42/107), used while its pings carry no
    // position of their own: fed in time order before the pings they precede.
    std::deque<FileNavigation> packet_queue;
    bool ping_positions_seen = false;
    auto feedPackets = [&](int64_t up_to_us) {
      while (!packet_queue.empty() && packet_queue.front().utime_us <= up_to_us) {
        if (embedded && !ping_positions_seen) {
          if (embedded->fromPacket(packet_queue.front(), pings->projectedUnits())) ++runner.summary().nav_from_packets;
          for (const NavInput& nav : embedded->takeReady()) runner.addNav(nav);
        }
        packet_queue.pop_front();
      }
    };
    bool pings_left = true, nav_left = ins != nullptr;
    uint64_t without_nav = 0;
    for (;;) {
      while (pings_left && ping_queue.empty()) pings_left = pings->read(ping_queue);
      for (auto& record : pings->takeNavigation()) packet_queue.push_back(record);
      while (nav_left && nav_queue.empty()) nav_left = ins->read(nav_queue);
      if (ping_queue.empty() && nav_queue.empty()) break;
      const bool nav_first =
          !nav_queue.empty() && (ping_queue.empty() || nav_queue.front().utime <= ping_queue.front().utime_us);
      if (nav_first) {
        record(request.nav_channel, nav_queue.front(), nav_queue.front().utime);
        runner.addNav(sss::messages::fromNavMessage(nav_queue.front()));
        nav_queue.pop_front();
        continue;
      }
      sss::sonar::DriverPing ping = std::move(ping_queue.front());
      ping_queue.pop_front();
      feedPackets(ping.utime_us);
      if (embedded) {
        if (embedded->fromPing(ping)) {
          ping_positions_seen = true;
        } else {
          ++without_nav;
          ++runner.summary().pings_without_position;
        }
        for (const NavInput& nav : embedded->takeReady()) runner.addNav(nav);
      }
      const sss_msgs::ping_t message = sss::edgetech::toPingMessage(ping);
      record(request.ping_channel, message, message.utime);
      runner.addPing(sss::messages::fromPingMessage(message));
      runner.progress(pings->fractionRead(), false);
    }
    feedPackets(INT64_MAX);  // the file's last navigation, after its last ping
    if (embedded) {
      for (const NavInput& nav : embedded->finish()) runner.addNav(nav);
      runner.summary().nav_positions_interpolated = embedded->positionsInterpolated();
      runner.summary().nav_headings_from_course = embedded->headingsFromCourse();
      runner.summary().nav_headings_from_track = embedded->headingsFromTrack();
      runner.summary().nav_headings_unknown = embedded->headingsUnknown();
      runner.summary().nav_headings_from_next = embedded->headingsFromNext();
      runner.summary().nav_laybacks_applied = embedded->laybacksApplied();
      runner.summary().nav_max_layback_m = embedded->maxLaybackM();
      runner.summary().nav_laybacks_without_heading = embedded->laybacksWithoutHeading();
    }
    if (xtf_source) {
      runner.summary().xtf_layback_pings = xtf_source->reader().counters().pings_layback_to_apply;
      runner.summary().xtf_layback_in_position_pings = xtf_source->reader().counters().pings_layback_in_position;
    }
    faults += pings->faults() + (ins ? ins->faults() : 0);
    if (jsf_source) {
      runner.summary().jsf_adopted_subsystem = jsf_source->assemblerCounters().adopted_subsystem;
      runner.summary().jsf_old_side_scan_messages = jsf_source->oldSideScanMessages();
      runner.summary().jsf_records_with_layback = jsf_source->recordsWithLayback();
      runner.summary().jsf_max_layback_m = jsf_source->maxLaybackM();
    }
    if (runner.summary().pings == 0) {
      result.error = "no usable pings in " + request.sonar_path;
      if (jsf_source && jsf_source->assemblerCounters().other_subsystem > 0) {
        result.error += ": " + std::to_string(jsf_source->assemblerCounters().other_subsystem) +
                        " sonar records of other subsystems than sonar_driver.subsystem (" +
                        std::to_string(options.sonar.assembler.subsystem) +
                        ") were ignored; set sonar_driver.subsystem to the side-scan frequency wanted (20 low, 21 high)";
      }
      return result;
    }
    if (embedded) projected_origin = embedded->projectedOrigin();
    if (embedded && projected_origin) runner.summary().projected_track_m = embedded->distanceM();
    if (embedded && without_nav == runner.summary().pings && runner.summary().nav_from_packets == 0) {
      result.error = request.sonar_path + " carries no navigation in its ping headers; give an INS file with --ins";
      return result;
    }
  }
  if (projected_origin) runner.setProjectedOrigin(*projected_origin);
  runner.progress(1.0, true);
  runner.finish();
  runner.countStages();
  OfflineSummary& summary = runner.summary();
  summary.origin = runner.origin();
  if (projected_origin) {
    summary.origin_source = "projected_first_fix";
    summary.projected_origin_easting_m = projected_origin->x();
    summary.projected_origin_northing_m = projected_origin->y();
    char text[320];
    std::snprintf(text, sizeof text,
                  "projected metres (XTF NavUnits 0): north = northing - %.3f, east = easting - %.3f of the first "
                  "fix, in the file's grid; the file records no CRS, so no latitude/longitude; headings are used as "
                  "recorded (true north, not grid north)",
                  summary.projected_origin_northing_m, summary.projected_origin_easting_m);
    summary.origin_detail = text;
  } else if (options.origin) {
    summary.origin_source = sss::core::originSourceName(sss::core::OriginSource::kConfigured);
    summary.origin_detail = "mission.origin_latitude_deg / origin_longitude_deg in " + request.config_path;
  } else if (from_log) {
    summary.origin_source = sss::core::originSourceName(sss::core::OriginSource::kFromNavigation);
    summary.origin_detail = "carried by the log's " + request.nav_channel + " messages (the INS bridge's origin)";
  } else {
    summary.origin_source = sss::core::originSourceName(sss::core::OriginSource::kFirstFix);
    summary.origin_detail = request.ins_path.empty() ? "the first position in the sonar file's ping headers"
                                                     : "the first position fix in " + request.ins_path;
  }
  if (request.progress && summary.origin) {
    std::fprintf(request.progress, "sss-process: mission origin %.7f %.7f (%s: %s)\n", summary.origin->latitude_deg,
                 summary.origin->longitude_deg, summary.origin_source.c_str(), summary.origin_detail.c_str());
  } else if (request.progress && !summary.origin_detail.empty()) {
    std::fprintf(request.progress, "sss-process: frame: %s\n", summary.origin_detail.c_str());
  }
  summary.input_faults = faults;
  result.exit_code = 1;
  if (const sss::core::Status written = runner.writeOutputs(); !written) {
    result.error = written.message;
    return result;
  }
  summary.wall_s = wallSeconds() - runner.startSeconds();
  summary.mission_s = runner.missionSeconds();
  summary.real_time_factor = summary.wall_s > 0.0 ? summary.mission_s / summary.wall_s : 0.0;
  summary.peak_rss_mib = peakRssMib();
  summary.findings = explainRun(summary, options);
  for (const std::string& finding : explainFixes(summary.fixes, options)) summary.findings.push_back(finding);
  if (!request.corrected_dir.empty() && summary.pings_with_pose > 0) {
    if (summary.corrected_copy.empty()) {
      summary.findings.push_back("no corrected copy of " + request.sonar_path +
                                 ": the mission frame has no position on Earth; set mission.origin_latitude_deg and "
                                 "origin_longitude_deg");
    }
    if (summary.corrected_records_without_position_field > 0) {
      summary.findings.push_back(std::to_string(summary.corrected_records_without_position_field) +
                                 " side-scan records of " + summary.corrected_copy +
                                 " are the older JSF message 82, which has no position field: they keep their "
                                 "recorded navigation (use navigation.csv or navigation.nmea for the corrected track)");
    }
    if (!summary.corrected_copy.empty() && summary.corrected_records_without_pose > 0) {
      summary.findings.push_back(std::to_string(summary.corrected_records_without_pose) + " sonar records of " +
                                 summary.corrected_copy +
                                 " keep their recorded navigation: no pose at their time (before the navigation "
                                 "started, in a gap, or dropped by the chain)");
    }
  }
  if (options.write_geotiff && summary.pings_with_pose > 0) {
    if (summary.origin_source == "projected_first_fix" && options.projected_crs.empty()) {
      summary.findings.push_back(
          "GeoTIFFs without a CRS: the sonar file gives positions in projected metres (XTF NavUnits 0) and does not "
          "name its grid; set products.projected_crs (e.g. EPSG:32633) so that GIS software places them");
    } else if (summary.geotiffs.empty() && !summary.origin && summary.origin_source != "projected_first_fix") {
      summary.findings.push_back("no GeoTIFF: the mission frame has no position on Earth; set mission.origin_latitude_deg "
                                 "and origin_longitude_deg");
    }
  }
  result.summary = summary;
  if (const sss::core::Status written = writeSummaryJson(request.out_dir + "/summary.json", request, summary);
      !written) {
    result.error = written.message;
    return result;
  }
  if (summary.pings_with_pose == 0 || summary.subframes == 0) {
    // Nothing could be processed: the outputs say so (summary.json), and so does the exit code.
    result.exit_code = 3;
    result.error = summary.findings.empty() ? "nothing could be processed" : summary.findings.front();
    return result;
  }
  result.ok = true;
  result.exit_code = 0;
  return result;
}

}  // namespace sss::offline
