// sss-ins-bridge: iXblue NMEA from UDP, TCP, a serial port or a file -> SSS_NAV on LCM, with
// staleness in the message flags and in SSS_STATUS; and, when fix_udp_port is set, absolute position
// fixes (GNSS at the surface, USBL relayed by the modem: NMEA GGA + GST + ZDA on their own UDP port)
// -> SSS_FIX, placed in the mission frame with the DR state at their time. Translation only; the
// logic is in InsInputSource, InsBridge, PositionFixReader and FixAligner.
//   sss-ins-bridge [--config FILE] [--file ins.nmea [--speed X]] [--lcm-url URL]
#include <cstdlib>
#include <deque>
#include <string>
#include <string_view>

#include "drivers/ins/bridge_state.hpp"
#include "drivers/ins/fix_aligner.hpp"
#include "drivers/ins/fix_message.hpp"
#include "drivers/ins/ins_bridge.hpp"
#include "drivers/ins/ins_input_source.hpp"
#include "drivers/ins/position_fix.hpp"
#include "drivers/ins/nav_message.hpp"
#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/state_file.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/transport/logging.hpp"
#include "pipeline/transport/process_loop.hpp"
#include "pipeline/transport/replay_pacer.hpp"

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

// SSS_STATUS: the staleness (recovers by itself when data returns) and the counters; the fixes'
// counters only when fixes are read (fix_aligner set).
void setStatusCounters(const sss::ins::InsBridge& bridge, const sss::ins::BridgeStateStore& state,
                       const sss::ins::FixAligner* fix_aligner, const sss::ins::PositionFixReader& fix_reader,
                       uint64_t fixes_published, sss::core::HealthMonitor& health) {
  const std::string stale = bridge.describeStale(monotonicUtime());
  health.setState(stale.empty() ? sss::core::HealthState::kOk : sss::core::HealthState::kWarning,
                  stale.empty() ? "navigation ok" : stale);
  const auto& stream = bridge.streamCounters();
  health.setCounter("nmea_sentences", static_cast<double>(stream.sentences));
  health.setCounter("nmea_bad_checksum", static_cast<double>(stream.bad_checksum));
  health.setCounter("nmea_missing_checksum", static_cast<double>(stream.missing_checksum));
  health.setCounter("nmea_overlong", static_cast<double>(stream.overlong));
  health.setCounter("nmea_truncated", static_cast<double>(stream.truncated));
  health.setCounter("nmea_garbage_bytes", static_cast<double>(stream.garbage_bytes));
  health.setCounter("ins_epochs", static_cast<double>(bridge.assemblerCounters().epochs));
  health.setCounter("ins_epochs_out_of_order", static_cast<double>(bridge.epochsOutOfOrder()));
  health.setCounter("odometer_m", bridge.odometer().distance_travelled_m);
  health.setCounter("odometer_write_failures", static_cast<double>(state.odometerWriteFailures()));
  if (fix_aligner) {
    const auto& aligned = fix_aligner->counters();
    health.setCounter("fixes_in", static_cast<double>(aligned.fixes_in));
    health.setCounter("fixes_published", static_cast<double>(fixes_published));
    health.setCounter("fixes_below_surface", static_cast<double>(aligned.below_surface));
    health.setCounter("fixes_outside_navigation", static_cast<double>(aligned.outside_navigation));
    const auto& read = fix_reader.counters();
    health.setCounter("fix_sentences_skipped", static_cast<double>(read.rejected_sentences + read.malformed));
  }
  if (bridge.origin()) {  // the mission frame, for the operator (NaN-free: only once it is known)
    health.setCounter("origin_latitude_deg", bridge.origin()->latitude_deg);
    health.setCounter("origin_longitude_deg", bridge.origin()->longitude_deg);
  }
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

// The command line over the configuration file: an exit code when the process ends here (--help, a
// bad flag or configuration, --check-config), else -1.
int parseOptions(int argc, char** argv, NodeOptions& options) {
  sss::transport::NodeArguments arguments;
  sss::cli::CommandLine command_line("sss-ins-bridge",
                                     "iXblue NMEA ($PIXSE) over UDP, TCP, a serial line or a file -> SSS_NAV; "
                                     "absolute fixes -> SSS_FIX");
  sss::transport::addNodeFlags(command_line, arguments);
  sss::transport::ReplayFlags replay_flags;
  sss::transport::addReplayFlags(command_line, "replay this NMEA file (source: file)", replay_flags);
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  const std::string config_problems = readNodeOptions(arguments.config_path, options);
  if (replay_flags.file) {
    options.input.file = *replay_flags.file;
    options.input.source = "file";
  }
  options.replay_speed = replay_flags.speed.value_or(options.replay_speed);
  if (const int code = sss::transport::configVerdict("sss-ins-bridge", config_problems, arguments.config_path,
                                                      arguments.check_config_only);
      code >= 0) {
    return code;
  }
  if (!arguments.lcm_url_override.empty()) options.process.lcm_url = arguments.lcm_url_override;
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  NodeOptions options;
  if (const int code = parseOptions(argc, argv, options); code >= 0) return code;

  sss::transport::initLogging(options.process.process_name, options.process.log_level);
  sss::transport::ProcessLoop loop(options.process);
  sss::core::HealthMonitor& health = loop.health();
  sss::ins::InsBridge bridge(options.bridge);
  std::vector<sss::ins::NavSample> samples;

  // The odometer and the mission origin across restarts (bridge_state.hpp). A file replay is
  // offline: nothing kept.
  sss::ins::BridgeStateStore state(options.input.source == "file" ? std::string()
      : sss::core::resolveSystemdDirectory(options.state_directory, std::getenv("STATE_DIRECTORY")));
  // Runs one step of the store and writes what it says.
  auto logged = [](const auto& step) {
    sss::ins::BridgeStateLog lines;
    step(lines);
    for (const std::string& line : lines.info) spdlog::info("{}", line);
    for (const std::string& line : lines.errors) spdlog::error("{}", line);
  };
  logged([&](sss::ins::BridgeStateLog& lines) { state.restore(bridge, lines); });
  auto saveOdometerIfMoved = [&] {
    logged([&](sss::ins::BridgeStateLog& lines) { state.saveOdometerIfMoved(bridge, lines); });
  };
  loop.addTimer(1.0, saveOdometerIfMoved);

  // Fixes: read from their port, tied to the navigation as it passes their time.
  sss::ins::PositionFixReader fix_reader(options.fix_reader);
  sss::ins::FixAligner fix_aligner(options.fix_aligner);
  uint64_t fixes_published = 0;
  bool fix_problem_reported = false;
  auto publishFixes = [&](int64_t since_us) {
    if (!bridge.origin()) return;
    for (const sss::ins::AlignedFix& fix : fix_aligner.take()) {
      loop.bus().publish(options.fix_channel, sss::ins::toFixMessage(fix, *bridge.origin()), since_us);
      ++fixes_published;
    }
  };
  auto publishAll = [&](int64_t since_us) {
    logged([&](sss::ins::BridgeStateLog& lines) { state.noteOrigin(bridge, lines); });
    for (const auto& sample : samples) {
      loop.bus().publish(options.nav_channel, sss::ins::toNavMessage(sample), since_us);
      if ((sample.ins.validity & sss::ins::kValidPosition) && sample.origin)
        fix_aligner.addNav(sample.ins.utime_us, sample.position_ned_m, sample.distance_travelled_m, sample.origin);
    }
    samples.clear();
    if (options.fix_udp_port > 0) publishFixes(since_us);
  };
  // Health: staleness (recovers by itself when data returns), counters, faults logged once.
  loop.addTimer(0.5, [&] {
    setStatusCounters(bridge, state, options.fix_udp_port > 0 ? &fix_aligner : nullptr, fix_reader, fixes_published, health);
    if (options.fix_udp_port > 0 && !fix_problem_reported && !fix_reader.firstProblem().empty()) {
      loop.reportFaults("fix_input", {"fixes: " + fix_reader.firstProblem()});  // once: later ones are counted
      fix_problem_reported = true;
    }
    loop.reportFaults("ins_input", bridge.takeNewFaultMessages());
  });

  sss::ins::InsInputHooks fix_hooks;
  fix_hooks.chunk = [&](const sss::ins::InsInputChunk& chunk) {
    fix_reader.feed(std::string_view(reinterpret_cast<const char*>(chunk.data), chunk.size));
    for (const sss::ins::PositionFix& fix : fix_reader.take()) fix_aligner.addFix(fix);
  };
  sss::ins::InsInputSource fix_input(fixInputOptions(options), fix_hooks);
  if (options.fix_udp_port > 0) {
    if (const std::string error = fix_input.open(); !error.empty()) {
      spdlog::critical("fixes: {}", error);
      return 1;
    }
    spdlog::info("absolute fixes (NMEA GGA + GST + ZDA) on UDP {}:{} -> {}", options.input.bind_address,
                 options.fix_udp_port, options.fix_channel);
    loop.addFileDescriptor(fix_input.fd(), [&] { fix_input.read(0.0); publishFixes(monotonicUtime()); });
  }

  // The INS bytes: samples go out as they come, or, replaying a file, wait in a queue for the
  // recorded pace.
  const bool replay = options.input.source == "file";
  std::deque<sss::ins::NavSample> replay_queue;
  sss::transport::ReplayPacer pacer(options.replay_speed);
  sss::ins::InsInputHooks hooks;
  hooks.chunk = [&](const sss::ins::InsInputChunk& chunk) {
    bridge.onBytes(chunk.data, chunk.size, chunk.arrival_us, samples);
    if (chunk.end_of_file) bridge.finish(chunk.arrival_us, samples);
    else if (chunk.stream_break) bridge.onChunkEnd(chunk.arrival_us, samples);
    if (!replay) return publishAll(chunk.arrival_us);
    replay_queue.insert(replay_queue.end(), samples.begin(), samples.end());
    samples.clear();
  };
  hooks.info = [](const std::string& line) { spdlog::info("{}", line); };
  hooks.warning = [](const std::string& line) { spdlog::warn("{}", line); };
  hooks.open_failed = [&](const std::string& error) {
    if (health.recordError("serial_open", error, sss::core::nowUtime())) spdlog::warn("{}; retrying", error);
  };
  sss::ins::InsInputSource input(options.input, hooks);
  if (const std::string error = input.open(); !error.empty()) {
    spdlog::critical("{}", error);
    return 1;
  }
  InputOnLoop input_on_loop(input, loop);
  if (replay) {
    loop.addTimer(0.002, [&] {
      while (!input.atEnd() && replay_queue.size() < 256) input.read(0.0);
      const int64_t now = monotonicUtime();
      for (int budget = 500; budget > 0 && !replay_queue.empty() && pacer.due(replay_queue.front().ins.utime_us, now); --budget) {
        samples.push_back(replay_queue.front());
        replay_queue.pop_front();
        publishAll(now);
      }
      if (input.atEnd() && replay_queue.empty()) {
        spdlog::info("replay of '{}' finished: {} epochs", options.input.file, bridge.assemblerCounters().epochs);
        loop.stop();
      }
    });
  }
  const int code = loop.run();
  saveOdometerIfMoved();
  return code;
}
