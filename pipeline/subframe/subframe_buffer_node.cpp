// sss-subframe-buffer: SSS_PING + SSS_NAV -> SSS_SUBFRAME (canonical, geo-referenced subframes),
// with drops and latency in SSS_STATUS. Wiring only: the logic is in SubframeBuffer, the
// numbering across restarts, the idle flush and the status in SubframeBufferService.
//   sss-subframe-buffer [--config FILE] [--lcm-url URL]
#include <cstdlib>
#include <string>
#include <vector>

#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/state_file.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/subframe/subframe_buffer_service.hpp"
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
  if (const int code = sss::transport::finishConfiguration(config_problems, arguments, options.process); code >= 0) {
    return code;
  }

  sss::transport::ProcessLoop loop(options.process);
  const std::string state_directory =
      sss::core::resolveSystemdDirectory(options.state_directory, std::getenv("STATE_DIRECTORY"));
  sss::subframe::SubframeBufferServiceOptions service_options;
  service_options.buffer = options.buffer;
  service_options.idle_flush_s = options.idle_flush_s;
  service_options.numbering_path = state_directory.empty() ? "" : state_directory + "/numbering";
  sss::subframe::ServiceLog log;
  sss::subframe::SubframeBufferService service(service_options, log);
  sss::transport::writeServiceLog(log);

  const auto publish = [&](const std::vector<sss::subframe::Subframe>& subframes) {
    sss::transport::writeServiceLog(log);
    for (const sss::subframe::Subframe& subframe : subframes) {
      const sss_msgs::subframe_t message = sss::messages::toSubframeMessage(
          subframe, options.buffer.subframes.intensity_bits, options.buffer.subframes.max_intensity,
          static_cast<float>(options.horizontal_beam_width_rad), static_cast<float>(options.vertical_beam_width_rad));
      // Latency in SSS_STATUS: from the arrival of the subframe's last ping to the end of the publish.
      loop.bus().publish(options.subframe_channel, message, subframe.last_ping_arrival_monotonic_us);
    }
  };
  loop.bus().subscribe<sss_msgs::nav_t>(options.nav_channel, [&](const sss_msgs::nav_t& message) {
    publish(service.addNav(sss::messages::fromNavMessage(message), log));
  });
  loop.bus().subscribe<sss_msgs::ping_t>(options.ping_channel, [&](const sss_msgs::ping_t& message) {
    const int64_t now_monotonic_us = sss::core::monotonicUtime();
    publish(service.addPing(sss::messages::fromPingMessage(message, now_monotonic_us), now_monotonic_us, log));
  });
  loop.addTimer(0.5, [&] { publish(service.flushIfIdle(sss::core::monotonicUtime(), log)); });
  loop.addTimer(1.0, [&] {
    service.reportHealth(loop.health(), sss::core::nowUtime(), log);
    loop.health().setQueueDepth(options.ping_channel, false, 0);
    sss::transport::writeServiceLog(log);
  });
  const int code = loop.run();
  publish(service.finish(log));
  return code;
}
