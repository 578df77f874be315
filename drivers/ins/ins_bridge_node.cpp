// sss-ins-bridge: iXblue NMEA from UDP, TCP, a serial port or a file -> SSS_NAV on LCM, with
// staleness in the message flags and in SSS_STATUS; and, when fix_udp_port is set, absolute position
// fixes (GNSS at the surface, USBL relayed by the modem: NMEA GGA + GST + ZDA on their own UDP port)
// -> SSS_FIX, placed in the mission frame with the DR state at their time. Wiring only: the bytes come
// from InsInputSource, the logic is InsBridgeService (ins_bridge_service.hpp).
//   sss-ins-bridge [--config FILE] [--file ins.nmea [--speed X]] [--lcm-url URL]
#include <cstdlib>
#include <string>

#include "drivers/ins/ins_bridge_service.hpp"
#include "drivers/ins/ins_input_source.hpp"
#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/state_file.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/transport/logging.hpp"
#include "pipeline/transport/process_loop.hpp"

namespace {

using sss::core::monotonicUtime;

struct NodeOptions {
  sss::transport::ProcessOptions process;
  sss::ins::InsBridgeOptions bridge;
  sss::ins::InsInputOptions input;
  double replay_speed = 1.0;
  std::string nav_channel = "SSS_NAV";
  // Absolute fixes on their own UDP port (0: none): not mixed into the INS stream, whose assembler
  // would take a GNSS ZDA for its own epoch's time.
  int fix_udp_port = 0;
  std::string fix_channel = "SSS_FIX";
  sss::ins::FixReaderOptions fix_reader;
  sss::ins::FixAlignerOptions fix_aligner;
  // The odometer survives restarts here. Empty: $STATE_DIRECTORY (systemd StateDirectory=), else
  // none (a restarted bridge counts distance travelled from 0 again).
  std::string state_directory;
};

// The node's options from the configuration file (none: the defaults). Empty when valid, else the
// problems, one per line.
std::string readNodeOptions(const std::string& config_path, NodeOptions& options) {
  options.process.process_name = "sss-ins-bridge";
  if (config_path.empty()) return {};
  using namespace sss::core;
  Config config = Config::fromFile(config_path);
  ConfigSection mission = config.section("mission");
  options.bridge.origin = sss::core::readMissionOrigin(mission);
  ConfigSection section = config.section("ins_bridge");
  sss::transport::readProcessOptions(section, options.process);
  sss::ins::readInsBridgeOptions(section, options.bridge);
  section.optional("source", options.input.source, {oneOf({"udp", "tcp", "serial", "file"})});
  section.optional("bind_address", options.input.bind_address, {nonEmpty()});
  section.optional("udp_port", options.input.udp_port, {inRange(1, 65535)});
  section.optional("host", options.input.tcp.host, {nonEmpty()});
  section.optional("port", options.input.tcp.port, {inRange(1, 65535)});
  section.optional("serial_device", options.input.serial_device, {nonEmpty()});
  section.optional("serial_baud", options.input.serial_baud,
                   {satisfies<int>([](int b) { return b == 9600 || b == 19200 || b == 38400 || b == 57600 ||
                                                      b == 115200 || b == 230400 || b == 460800; },
                                   "a standard baud rate (9600 ... 460800)")});
  section.optional("file", options.input.file);
  section.optional("replay_speed", options.replay_speed, {inRange(0.0, 1000.0)});
  section.optional("nav_channel", options.nav_channel, {nonEmpty()});
  section.optional("fix_udp_port", options.fix_udp_port, {inRange(0, 65535)});
  section.optional("fix_channel", options.fix_channel, {nonEmpty()});
  section.optional("fix_gnss_max_depth_m", options.fix_aligner.gnss_max_depth_m, {atLeast(0.0)});
  section.optional("fix_max_latency_s", options.fix_aligner.max_latency_s, {inRange(1.0, 3600.0)});
  section.optional("fix_usbl_default_sigma_m", options.fix_reader.usbl_default_sigma_m, {greaterThan(0.0)});
  section.optional("state_directory", options.state_directory);
  section.rejectUnknownKeys();
  return config.problemReport();
}

// The service's options: the node's, with the state directory resolved.
sss::ins::InsBridgeServiceOptions serviceOptions(const NodeOptions& options) {
  sss::ins::InsBridgeServiceOptions service;
  service.bridge = options.bridge;
  service.replay = options.input.source == "file";
  service.replay_speed = options.replay_speed;
  service.read_fixes = options.fix_udp_port > 0;
  service.fix_reader = options.fix_reader;
  service.fix_aligner = options.fix_aligner;
  service.state_directory =
      sss::core::resolveSystemdDirectory(options.state_directory, std::getenv("STATE_DIRECTORY"));
  return service;
}

// The fixes' own UDP port, on the INS input's address.
sss::ins::InsInputOptions fixInputOptions(const NodeOptions& options) {
  sss::ins::InsInputOptions fix_input;
  fix_input.bind_address = options.input.bind_address;
  fix_input.udp_port = options.fix_udp_port;
  return fix_input;
}

// Puts the INS input on the loop: its descriptor watched (it changes as a serial port comes back or
// the TCP link reconnects) and the source serviced as often as it asks.
class InputOnLoop {
 public:
  InputOnLoop(sss::ins::InsInputSource& input, sss::transport::ProcessLoop& loop) : input_(input), loop_(loop) {
    watch();
    if (input_.servicePeriodS() > 0.0) {
      loop_.addTimer(input_.servicePeriodS(), [this] {
        input_.service(monotonicUtime());
        watch();
      });
    }
  }
  InputOnLoop(const InputOnLoop&) = delete;  // the loop's callbacks hold this
  InputOnLoop& operator=(const InputOnLoop&) = delete;

 private:
  void watch() {
    if (input_.fd() == watched_fd_) return;
    if (watched_fd_ >= 0) loop_.removeFileDescriptor(watched_fd_);
    watched_fd_ = input_.fd();
    if (watched_fd_ >= 0) {
      loop_.addFileDescriptor(watched_fd_, [this] {
        input_.read(0.0);
        watch();
      });
    }
  }

  sss::ins::InsInputSource& input_;
  sss::transport::ProcessLoop& loop_;
  int watched_fd_ = -1;
};

}  // namespace

int main(int argc, char** argv) {
  sss::transport::NodeArguments arguments;
  sss::transport::ReplayFlags replay_flags;
  if (const int code = sss::transport::parseNodeArguments(
          "sss-ins-bridge", "iXblue NMEA ($PIXSE) over UDP, TCP, a serial line or a file -> SSS_NAV; absolute fixes -> SSS_FIX",
          "replay this NMEA file (source: file)", argc, argv, arguments, replay_flags);
      code >= 0) {
    return code;
  }
  NodeOptions options;
  const std::string config_problems = readNodeOptions(arguments.config_path, options);
  if (replay_flags.file) {
    options.input.file = *replay_flags.file;
    options.input.source = "file";
  }
  options.replay_speed = replay_flags.speed.value_or(options.replay_speed);
  if (const int code = sss::transport::finishConfiguration(config_problems, arguments, options.process); code >= 0) {
    return code;
  }

  sss::transport::ProcessLoop loop(options.process);
  sss::core::ServiceLog log;
  sss::ins::InsBridgeService service(serviceOptions(options), log);
  sss::transport::writeServiceLog(log);

  auto publish = [&](const sss::ins::BridgeMessages& messages) {
    sss::transport::writeServiceLog(log);
    for (const auto& nav : messages.nav) loop.bus().publish(options.nav_channel, nav, messages.since_monotonic_us);
    for (const auto& fix : messages.fixes) loop.bus().publish(options.fix_channel, fix, messages.since_monotonic_us);
  };
  auto saveOdometerIfMoved = [&] {
    service.saveOdometerIfMoved(log);
    sss::transport::writeServiceLog(log);
  };
  loop.addTimer(1.0, saveOdometerIfMoved);
  loop.addTimer(0.5, [&] {
    service.reportHealth(loop.health(), monotonicUtime());
    loop.reportFaults("fix_input", service.takeFixFaults());
    loop.reportFaults("ins_input", service.takeInsFaults());
  });

  // Fixes: read from their own port, placed as the navigation passes their time.
  sss::ins::InsInputHooks fix_hooks;
  fix_hooks.chunk = [&](const sss::ins::InsInputChunk& chunk) { publish(service.onFixChunk(chunk)); };
  sss::ins::InsInputSource fix_input(fixInputOptions(options), fix_hooks);
  if (options.fix_udp_port > 0) {
    if (const sss::core::Status opened = fix_input.open(); !opened) {
      spdlog::critical("fixes: {}", opened.message);
      return 1;
    }
    spdlog::info("absolute fixes (NMEA GGA + GST + ZDA) on UDP {}:{} -> {}", options.input.bind_address,
                 options.fix_udp_port, options.fix_channel);
    loop.addFileDescriptor(fix_input.fd(), [&] { fix_input.read(0.0); });
  }

  // The INS bytes: live, samples go out as they come; replaying a file, at the recorded pace.
  sss::ins::InsInputHooks hooks;
  hooks.chunk = [&](const sss::ins::InsInputChunk& chunk) { publish(service.onInsChunk(chunk, log)); };
  hooks.info = [](const std::string& line) { spdlog::info("{}", line); };
  hooks.warning = [](const std::string& line) { spdlog::warn("{}", line); };
  hooks.open_failed = [&](const std::string& error) {
    if (loop.health().recordError("serial_open", error, sss::core::nowUtime())) spdlog::warn("{}; retrying", error);
  };
  sss::ins::InsInputSource input(options.input, hooks);
  if (const sss::core::Status opened = input.open(); !opened) {
    spdlog::critical("{}", opened.message);
    return 1;
  }
  InputOnLoop input_on_loop(input, loop);
  if (options.input.source == "file") {
    loop.addTimer(0.002, [&] {
      while (!input.atEnd() && service.wantsReplayInput()) input.read(0.0);
      publish(service.takeDue(monotonicUtime(), log));
      if (input.atEnd() && service.replayQueueEmpty()) {
        spdlog::info("replay of '{}' finished: {} epochs", options.input.file,
                     service.bridge().assemblerCounters().epochs);
        loop.stop();
      }
    });
  }
  const int code = loop.run();
  saveOdometerIfMoved();
  return code;
}
