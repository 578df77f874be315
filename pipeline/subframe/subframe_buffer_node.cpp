// sss-subframe-buffer: SSS_PING + SSS_NAV -> SSS_SUBFRAME (canonical, geo-referenced subframes),
// with drops and latency in SSS_STATUS. Translation only; the logic is in SubframeBuffer.
//   sss-subframe-buffer [--config FILE] [--lcm-url URL]
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/state_file.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/subframe/subframe_buffer.hpp"
#include "pipeline/messages/subframe_messages.hpp"
#include "pipeline/messages/sensor_messages.hpp"
#include "pipeline/transport/logging.hpp"
#include "pipeline/transport/process_loop.hpp"
#include "pipeline/transport/process_options.hpp"

namespace {

struct NodeOptions {
  sss::transport::ProcessOptions process;
  sss::subframe::SubframeBufferOptions buffer;
  std::string ping_channel = "SSS_PING";
  std::string nav_channel = "SSS_NAV";
  std::string subframe_channel = "SSS_SUBFRAME";
  double horizontal_beam_width_rad = 0.0087;  // carried in the message for the matcher
  double vertical_beam_width_rad = 0.87;
  double idle_flush_s = 5.0;  // no ping for this long (host time): close the open line
  // The subframe and line numbering survives restarts here. Empty: $STATE_DIRECTORY (systemd
  // StateDirectory=), else none (a restarted buffer numbers from 0: the optimiser then refuses
  // the new subframes as duplicates).
  std::string state_directory;
};

constexpr const char* kNumberingFormat = "sss-subframe-buffer numbering 1";

// The numbering saved by an earlier run; {0, 0} when there is none. A file that cannot be read
// is reported (numbering from 0 may collide with the subframes the optimiser already has).
sss::subframe::SubframeNumbering loadNumbering(const std::string& path) {
  sss::subframe::SubframeNumbering numbering;
  if (path.empty() || access(path.c_str(), F_OK) != 0) return numbering;
  sss::core::StateValues values;
  std::string error;
  long long subframe_id = 0, line_id = 0;
  if (!sss::core::readStateFile(path, kNumberingFormat, values, error) ||
      !sss::core::stateInteger(values, "next_subframe_id", subframe_id) ||
      !sss::core::stateInteger(values, "next_line_id", line_id) || subframe_id < 0 || line_id < 0 ||
      line_id > std::numeric_limits<int>::max()) {
    spdlog::error("subframe numbering not resumed, starting from 0 (subframes the optimiser already has will be "
                  "refused as duplicates): {}",
                  error.empty() ? path + ": bad next_subframe_id / next_line_id" : error);
    return numbering;
  }
  numbering.next_subframe_id = subframe_id;
  numbering.next_line_id = static_cast<int>(line_id);
  spdlog::info("resumed the numbering from {}: next subframe {}, next line {}", path, subframe_id, line_id);
  return numbering;
}

}  // namespace

int main(int argc, char** argv) {
  sss::transport::NodeArguments arguments;
  const int usage_exit_code = sss::transport::parseNodeArguments(
      "sss-subframe-buffer", "canonical side-scan subframes: SSS_PING + SSS_NAV -> SSS_SUBFRAME",
      argc, argv, arguments);
  if (usage_exit_code >= 0) return usage_exit_code;
  const std::string& config_path = arguments.config_path;
  NodeOptions options;
  options.process.process_name = "sss-subframe-buffer";
  std::string config_problems;  // empty: valid (or no file: the defaults)
  if (!config_path.empty()) {
    using namespace sss::core;
    Config config = Config::fromFile(config_path);
    // The mission origin is the NED origin of SSS_NAV already (the INS bridge converts); it is
    // read here only so the shared mission section is validated the same way everywhere.
    ConfigSection mission = config.section("mission");
    (void)sss::core::readMissionOrigin(mission);
    ConfigSection section = config.section("subframe_buffer");
    sss::transport::readProcessOptions(section, options.process);
    sss::subframe::readSubframeBufferOptions(section, options.buffer);
    section.optional("ping_channel", options.ping_channel, {nonEmpty()});
    section.optional("nav_channel", options.nav_channel, {nonEmpty()});
    section.optional("subframe_channel", options.subframe_channel, {nonEmpty()});
    section.optional("horizontal_beam_width_rad", options.horizontal_beam_width_rad, {inRange(0.0, 1.0)});
    section.optional("vertical_beam_width_rad", options.vertical_beam_width_rad, {inRange(0.0, 3.2)});
    section.optional("idle_flush_s", options.idle_flush_s, {inRange(0.1, 3600.0)});
    section.optional("state_directory", options.state_directory);
    section.rejectUnknownKeys();
    config_problems = config.problemReport();
  }
  if (const int code = sss::transport::configVerdict("sss-subframe-buffer", config_problems, config_path, arguments.check_config_only); code >= 0) {
    return code;
  }
  if (!arguments.lcm_url_override.empty()) options.process.lcm_url = arguments.lcm_url_override;

  sss::transport::initLogging(options.process.process_name, options.process.log_level);
  sss::transport::ProcessLoop loop(options.process);
  sss::core::HealthMonitor& health = loop.health();
  sss::subframe::SubframeBuffer buffer(options.buffer);
  std::vector<sss::subframe::Subframe> subframes;
  const std::string state_directory =
      sss::core::resolveSystemdDirectory(options.state_directory, std::getenv("STATE_DIRECTORY"));
  const std::string numbering_path = state_directory.empty() ? "" : state_directory + "/numbering";
  if (numbering_path.empty()) {
    spdlog::warn("no state directory (subframe_buffer.state_directory or $STATE_DIRECTORY): after a restart the "
                 "subframe ids start from 0 again");
  }
  buffer.resumeNumbering(loadNumbering(numbering_path));
  uint64_t numbering_write_failures = 0;

  auto publishAll = [&] {
    // The numbering is saved before the subframes leave: a kill in between skips ids, it never
    // reuses one.
    if (!subframes.empty() && !numbering_path.empty()) {
      const sss::subframe::SubframeNumbering numbering = buffer.numbering();
      std::string error;
      if (!sss::core::writeStateFile(numbering_path, kNumberingFormat,
                                     {{"next_subframe_id", std::to_string(numbering.next_subframe_id)},
                                      {"next_line_id", std::to_string(numbering.next_line_id)}},
                                     error)) {
        if (numbering_write_failures++ == 0) spdlog::error("subframe numbering not saved (counted from now on): {}", error);
      }
    }
    for (const sss::subframe::Subframe& subframe : subframes) {
      const sss_msgs::subframe_t message = sss::messages::toSubframeMessage(
          subframe, options.buffer.subframes.intensity_bits, options.buffer.subframes.max_intensity,
          static_cast<float>(options.horizontal_beam_width_rad), static_cast<float>(options.vertical_beam_width_rad));
      // Latency in SSS_STATUS: from the arrival of the subframe's last ping to the end of the publish.
      loop.bus().publish(options.subframe_channel, message, subframe.last_ping_arrival_monotonic_us);
    }
    subframes.clear();
  };
  loop.bus().subscribe<sss_msgs::nav_t>(options.nav_channel, [&](const sss_msgs::nav_t& message) {
    buffer.addNav(sss::messages::fromNavMessage(message), subframes);
    publishAll();
  });
  int64_t last_ping_monotonic_us = 0;
  bool flushed_since_last_ping = true;
  loop.bus().subscribe<sss_msgs::ping_t>(options.ping_channel, [&](const sss_msgs::ping_t& message) {
    last_ping_monotonic_us = sss::core::monotonicUtime();
    flushed_since_last_ping = false;
    buffer.addPing(sss::messages::fromPingMessage(message, last_ping_monotonic_us), subframes);
    publishAll();
  });
  // When the sonar stops (end of the mission, a stop between surveys) nothing else ends the open
  // line: after idle_flush_s without pings its tail becomes a subframe instead of waiting forever.
  loop.addTimer(0.5, [&] {
    if (flushed_since_last_ping) return;
    if (sss::core::monotonicUtime() - last_ping_monotonic_us < static_cast<int64_t>(options.idle_flush_s * 1e6)) return;
    buffer.finish(subframes);
    publishAll();
    flushed_since_last_ping = true;
    spdlog::info("no ping for {} s: closed the open survey line", options.idle_flush_s);
  });

  // Counters and faults (logged once per kind, counted always).
  uint64_t reported_no_nav = 0, reported_out_of_order = 0, reported_no_altitude = 0;
  loop.addTimer(1.0, [&] {
    const sss::subframe::SubframeBufferCounters c = buffer.counters();
    const auto set = [&](const char* name, uint64_t value) { health.setCounter(name, static_cast<double>(value)); };
    set("pings_in", c.fusion.pings_in);
    set("pings_fused", c.fusion.pings_out);
    set("pings_dropped_without_nav", c.fusion.droppedWithoutNav());
    set("pings_dropped_no_nav", c.fusion.dropped_no_nav);
    set("pings_dropped_too_old", c.fusion.dropped_too_old);
    set("pings_dropped_nav_gap", c.fusion.dropped_nav_gap);
    set("pings_out_of_order", c.fusion.pings_out_of_order);
    set("pings_reordered", c.fusion.pings_reordered);
    set("pings_duplicate", c.fusion.pings_duplicate);
    set("pings_dropped_no_altitude", c.fusion.dropped_no_altitude);
    set("pings_dropped_before_first_fix", c.fusion.dropped_before_first_fix);
    set("altitude_from_nav", c.fusion.altitude_from_nav);
    set("altitude_from_ping", c.fusion.altitude_from_ping);
    set("altitude_from_bottom_track", c.fusion.altitude_from_bottom_track);
    set("altitude_implausible", c.fusion.altitude_implausible);
    set("nav_in", c.fusion.nav_in);
    set("nav_without_position", c.fusion.nav_without_position);
    set("nav_out_of_order", c.fusion.nav_out_of_order);
    set("turn_rows", c.turn_rows);
    set("lines", c.builder.lines);
    set("subframes_out", c.builder.subframes);
    set("partial_subframes", c.builder.partial_subframes);
    set("dropped_short_tails", c.builder.dropped_short_tails);
    set("memory_bytes", buffer.memoryBytes());
    set("numbering_write_failures", numbering_write_failures);
    health.setQueueDepth(options.ping_channel, false, 0);
    const int64_t now = sss::core::nowUtime();
    if (c.fusion.droppedWithoutNav() > reported_no_nav) {
      if (health.recordError("ping_without_nav", "pings dropped without bracketing navigation (check SSS_NAV)", now))
        spdlog::warn("pings dropped without bracketing navigation; further drops are counted in SSS_STATUS");
      reported_no_nav = c.fusion.droppedWithoutNav();
    }
    if (c.fusion.pings_out_of_order > reported_out_of_order) {
      if (health.recordError("ping_out_of_order", "pings older than one already processed were dropped", now))
        spdlog::warn("out-of-order pings dropped; further ones are counted in SSS_STATUS");
      reported_out_of_order = c.fusion.pings_out_of_order;
    }
    if (c.fusion.dropped_no_altitude > reported_no_altitude) {
      if (health.recordError("ping_without_altitude", "pings dropped: no valid nav or sonar altitude", now))
        spdlog::warn("pings dropped without a valid altitude (no DVL altitude in SSS_NAV, none in the ping and no "
                     "seabed return found; subframe_buffer.fusion.altitude_source: auto or bottom_track tracks the "
                     "bottom in the returns); further ones are counted in SSS_STATUS");
      reported_no_altitude = c.fusion.dropped_no_altitude;
    }
  });
  const int code = loop.run();
  buffer.finish(subframes);
  publishAll();
  return code;
}
