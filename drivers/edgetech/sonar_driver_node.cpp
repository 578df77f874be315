// sss-sonar-driver: EdgeTech 2205 JSF from the sonar processor's TCP data port (or a .jsf or
// .xtf file for replay) -> SSS_PING on LCM. Translation only; the logic is in SonarInputSource,
// SonarDriver and XtfReader.
//   sss-sonar-driver [--config FILE] [--file FILE.jsf|FILE.xtf [--speed X]] [--lcm-url URL]
#include <cstdlib>
#include <string>
#include <vector>

#include "drivers/edgetech/ping_message.hpp"
#include "drivers/edgetech/sonar_input_source.hpp"
#include "pipeline/transport/logging.hpp"
#include "pipeline/transport/process_loop.hpp"

namespace {

struct NodeOptions {
  sss::transport::ProcessOptions process;
  sss::edgetech::SonarInputOptions input;
  std::string ping_channel = "SSS_PING";
};

// The node's options from the configuration file (none: the defaults). Empty when valid, else the
// problems, one per line.
std::string readNodeOptions(const std::string& config_path, NodeOptions& options) {
  options.process.process_name = "sss-sonar-driver";
  if (config_path.empty()) return {};
  using namespace sss::core;
  Config config = Config::fromFile(config_path);
  ConfigSection section = config.section("sonar_driver");
  sss::transport::readProcessOptions(section, options.process);
  sss::edgetech::readSonarDriverOptions(section, options.input.driver);
  section.optional("host", options.input.tcp.host, {nonEmpty()});
  section.optional("port", options.input.tcp.port, {inRange(1, 65535)});
  section.optional("reconnect_min_s", options.input.tcp.reconnect_min_s, {inRange(0.01, 60.0)});
  section.optional("reconnect_max_s", options.input.tcp.reconnect_max_s, {inRange(0.1, 600.0)});
  section.optional("silence_timeout_s", options.input.tcp.silence_timeout_s, {inRange(0.0, 3600.0)});
  section.optional("ping_channel", options.ping_channel, {nonEmpty()});
  section.optional("replay_file", options.input.replay_file);
  section.optional("replay_speed", options.input.replay_speed, {inRange(0.0, 1000.0)});
  section.optional("xtf_pair_index", options.input.xtf_pair_index, {inRange(0, 7)});
  std::string nav_units = "file";
  section.optional("xtf_nav_units", nav_units, {oneOf({"file", "latlon", "metres"})});
  options.input.xtf_nav_units = sss::xtf::xtfNavUnitsFromName(nav_units);
  std::string layback = "auto";  // read so that one configuration serves sss-process as well
  section.optional("xtf_layback", layback, {oneOf({"auto", "ignore"})});
  section.rejectUnknownKeys();
  return config.problemReport();
}

}  // namespace

int main(int argc, char** argv) {
  sss::transport::NodeArguments arguments;
  sss::transport::ReplayFlags replay_flags;
  if (const int code = sss::transport::parseNodeArguments(
          "sss-sonar-driver", "EdgeTech 2205 JSF from the sonar processor's TCP data port, or a .jsf/.xtf file replayed -> SSS_PING",
          "replay this .jsf or .xtf file instead of TCP", argc, argv, arguments, replay_flags);
      code >= 0) {
    return code;
  }
  NodeOptions options;
  const std::string config_problems = readNodeOptions(arguments.config_path, options);
  options.input.replay_file = replay_flags.file.value_or(options.input.replay_file);
  options.input.replay_speed = replay_flags.speed.value_or(options.input.replay_speed);
  if (const int code = sss::transport::finishConfiguration(config_problems, arguments, options.process); code >= 0) {
    return code;
  }
  // Under systemd the sonar's raw bytes go to the unit's LogsDirectory= unless the config says
  // where; a file being replayed is already on disk.
  if (options.input.replay_file.empty()) {
    options.input.driver.recorder.directory =
        sss::edgetech::resolveRecordDirectory(options.input.driver.recorder.directory, std::getenv("LOGS_DIRECTORY"));
  }

  sss::transport::ProcessLoop loop(options.process);
  sss::edgetech::SonarInputHooks hooks;
  hooks.ping = [&](const sss::edgetech::DriverPing& ping) {
    loop.bus().publish(options.ping_channel, sss::edgetech::toPingMessage(ping), ping.ping.last_arrival_us);
  };
  hooks.info = [](const std::string& line) { spdlog::info("{}", line); };
  hooks.warning = [](const std::string& line) { spdlog::warn("{}", line); };
  hooks.faults = [&](const std::vector<std::string>& faults) { loop.reportFaults("sonar_input", faults); };
  sss::edgetech::SonarInputSource input(options.input, loop.health(), hooks);
  if (input.driver().recorder().enabled()) {
    spdlog::info("recording the raw JSF stream to {}", options.input.driver.recorder.directory);
  }
  loop.addTimer(1.0, [&] { input.updateStatus(); });

  if (const sss::core::Status opened = input.open(); !opened) {
    spdlog::critical("{}", opened.message);
    return 1;
  }
  // Step the input; (re)register the TCP socket with the loop as the link comes and goes.
  int watched_fd = -1;
  loop.addTimer(input.stepPeriodS(), [&] {
    input.step();
    if (input.fd() != watched_fd) {
      if (watched_fd >= 0) loop.removeFileDescriptor(watched_fd);
      watched_fd = input.fd();
      if (watched_fd >= 0) loop.addFileDescriptor(watched_fd, [&] { input.onReadable(); });
    }
    if (input.done()) loop.stop();
  });
  return loop.run();
}
