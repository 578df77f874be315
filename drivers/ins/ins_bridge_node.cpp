// sss-ins-bridge: iXblue NMEA from UDP, TCP, a serial port or a file -> SSS_NAV on LCM, with
// staleness in the message flags and in SSS_STATUS; and, when fix_udp_port is set, absolute position
// fixes (GNSS at the surface, USBL relayed by the modem: NMEA GGA + GST + ZDA on their own UDP port)
// -> SSS_FIX, placed in the mission frame with the DR state at their time. Translation only; the
// logic is in InsBridge, PositionFixReader and FixAligner.
//   sss-ins-bridge [--config FILE] [--file ins.nmea [--speed X]] [--lcm-url URL]
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <string>

#include "drivers/ins/bridge_state.hpp"
#include "drivers/ins/fix_aligner.hpp"
#include "drivers/ins/fix_message.hpp"
#include "drivers/ins/ins_bridge.hpp"
#include "drivers/ins/position_fix.hpp"
#include "drivers/ins/nav_message.hpp"
#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/state_file.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/transport/logging.hpp"
#include "pipeline/transport/process_loop.hpp"
#include "pipeline/transport/replay_pacer.hpp"
#include "pipeline/transport/tcp_client.hpp"

namespace {

using sss::core::monotonicUtime;

struct NodeOptions {
  sss::transport::ProcessOptions process;
  sss::ins::InsBridgeOptions bridge;
  std::string source = "udp";  // udp | tcp | serial | file
  std::string bind_address = "0.0.0.0";
  int udp_port = 8110;
  sss::transport::TcpClientOptions tcp;
  std::string serial_device = "/dev/ttyS0";
  int serial_baud = 115200;
  std::string file;
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
  section.optional("source", options.source, {oneOf({"udp", "tcp", "serial", "file"})});
  section.optional("bind_address", options.bind_address, {nonEmpty()});
  section.optional("udp_port", options.udp_port, {inRange(1, 65535)});
  section.optional("host", options.tcp.host, {nonEmpty()});
  section.optional("port", options.tcp.port, {inRange(1, 65535)});
  section.optional("serial_device", options.serial_device, {nonEmpty()});
  section.optional("serial_baud", options.serial_baud,
                   {satisfies<int>([](int b) { return b == 9600 || b == 19200 || b == 38400 || b == 57600 ||
                                                      b == 115200 || b == 230400 || b == 460800; },
                                   "a standard baud rate (9600 ... 460800)")});
  section.optional("file", options.file);
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

speed_t baudConstant(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 230400: return B230400;
    case 460800: return B460800;
    default: return B115200;
  }
}

int openUdp(const std::string& bind_address, int port, std::string& error) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  ::inet_pton(AF_INET, bind_address.c_str(), &address.sin_addr);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    error = "cannot bind UDP " + bind_address + ":" + std::to_string(port) + ": " + std::strerror(errno);
    ::close(fd);
    return -1;
  }
  return fd;
}

int openSerial(const NodeOptions& options, std::string& error) {
  const int fd = ::open(options.serial_device.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    error = "cannot open serial port '" + options.serial_device + "': " + std::strerror(errno);
    return -1;
  }
  termios tty{};
  if (::tcgetattr(fd, &tty) == 0) {
    ::cfmakeraw(&tty);
    ::cfsetispeed(&tty, baudConstant(options.serial_baud));
    tty.c_cflag |= CLOCAL | CREAD;
    ::tcsetattr(fd, TCSANOW, &tty);
  }
  return fd;
}

}  // namespace

int main(int argc, char** argv) {
  sss::transport::NodeArguments arguments;
  NodeOptions options;
  sss::cli::CommandLine command_line("sss-ins-bridge",
                                     "iXblue NMEA ($PIXSE) over UDP, TCP, a serial line or a file -> SSS_NAV; "
                                     "absolute fixes -> SSS_FIX");
  sss::transport::addNodeFlags(command_line, arguments);
  sss::transport::ReplayFlags replay_flags;
  sss::transport::addReplayFlags(command_line, "replay this NMEA file (source: file)", replay_flags);
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  const std::string& config_path = arguments.config_path;
  const std::string& lcm_url_override = arguments.lcm_url_override;
  const std::string config_problems = readNodeOptions(config_path, options);
  if (replay_flags.file) {
    options.file = *replay_flags.file;
    options.source = "file";
  }
  options.replay_speed = replay_flags.speed.value_or(options.replay_speed);
  if (const int code = sss::transport::configVerdict("sss-ins-bridge", config_problems, config_path,
                                                      arguments.check_config_only);
      code >= 0) {
    return code;
  }
  if (!lcm_url_override.empty()) options.process.lcm_url = lcm_url_override;

  sss::transport::initLogging(options.process.process_name, options.process.log_level);
  sss::transport::ProcessLoop loop(options.process);
  sss::core::HealthMonitor& health = loop.health();
  sss::ins::InsBridge bridge(options.bridge);
  std::vector<sss::ins::NavSample> samples;

  // The odometer and the mission origin across restarts (bridge_state.hpp). A file replay is
  // offline: nothing kept.
  sss::ins::BridgeStateStore state(options.source == "file" ? std::string()
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

  std::string error;
  int input_fd = -1;
  std::unique_ptr<sss::transport::TcpClient> tcp;
  int tcp_registered_fd = -1;
  std::ifstream file;
  std::deque<sss::ins::NavSample> replay_queue;
  sss::transport::ReplayPacer pacer(options.replay_speed);
  bool replay_eof = false;

  int fix_fd = -1;
  if (options.fix_udp_port > 0) {
    fix_fd = openUdp(options.bind_address, options.fix_udp_port, error);
    if (fix_fd < 0) {
      spdlog::critical("fixes: {}", error);
      return 1;
    }
    spdlog::info("absolute fixes (NMEA GGA + GST + ZDA) on UDP {}:{} -> {}", options.bind_address, options.fix_udp_port,
                 options.fix_channel);
    loop.addFileDescriptor(fix_fd, [&] {
      char datagram[65536];
      ssize_t n;
      while ((n = ::recv(fix_fd, datagram, sizeof(datagram), 0)) > 0) {
        fix_reader.feed(std::string_view(datagram, static_cast<size_t>(n)));
        for (const sss::ins::PositionFix& fix : fix_reader.take()) fix_aligner.addFix(fix);
      }
      publishFixes(monotonicUtime());
    });
  }

  if (options.source == "udp") {
    input_fd = openUdp(options.bind_address, options.udp_port, error);
    if (input_fd < 0) {
      spdlog::critical("{}", error);
      return 1;
    }
    loop.addFileDescriptor(input_fd, [&] {
      uint8_t datagram[65536];
      ssize_t n;
      while ((n = ::recv(input_fd, datagram, sizeof(datagram), 0)) > 0) {
        const int64_t now = monotonicUtime();
        bridge.onBytes(datagram, static_cast<size_t>(n), now, samples);
        bridge.onChunkEnd(now, samples);
        publishAll(now);
      }
    });
  } else if (options.source == "serial") {
    // A serial port can vanish (USB adapter): reopen every 2 s until it is back.
    auto tryOpen = [&] {
      if (input_fd >= 0) return;
      input_fd = openSerial(options, error);
      if (input_fd < 0) {
        if (health.recordError("serial_open", error, sss::core::nowUtime())) spdlog::warn("{}; retrying", error);
        return;
      }
      spdlog::info("reading INS from {}", options.serial_device);
      loop.addFileDescriptor(input_fd, [&] {
        uint8_t buffer[4096];
        const ssize_t n = ::read(input_fd, buffer, sizeof(buffer));
        if (n > 0) {
          const int64_t now = monotonicUtime();
          bridge.onBytes(buffer, static_cast<size_t>(n), now, samples);
          publishAll(now);
        } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
          spdlog::warn("serial port '{}' closed; reopening", options.serial_device);
          loop.removeFileDescriptor(input_fd);
          ::close(input_fd);
          input_fd = -1;
        }
      });
    };
    tryOpen();
    loop.addTimer(2.0, tryOpen);
  } else if (options.source == "tcp") {
    tcp = std::make_unique<sss::transport::TcpClient>(
        options.tcp,
        [&](const uint8_t* data, size_t size) {
          const int64_t now = monotonicUtime();
          bridge.onBytes(data, size, now, samples);
          publishAll(now);
        },
        [&](sss::transport::LinkState state, const std::string& reason) {
          if (state == sss::transport::LinkState::kDisconnected) {
            spdlog::warn("INS link: {}", reason);
            bridge.onChunkEnd(monotonicUtime(), samples);
            publishAll(monotonicUtime());
          } else if (state == sss::transport::LinkState::kConnected) {
            spdlog::info("INS link: {}", reason);
          }
        });
    loop.addTimer(0.05, [&] {
      tcp->service(monotonicUtime());
      if (tcp->fd() != tcp_registered_fd) {
        if (tcp_registered_fd >= 0) loop.removeFileDescriptor(tcp_registered_fd);
        tcp_registered_fd = tcp->fd();
        if (tcp_registered_fd >= 0) loop.addFileDescriptor(tcp_registered_fd, [&] { tcp->onReadable(monotonicUtime()); });
      }
    });
  } else {
    file.open(options.file, std::ios::binary);
    if (!file) {
      spdlog::critical("cannot open INS file '{}'", options.file);
      return 1;
    }
    loop.addTimer(0.002, [&] {
      char chunk[16384];
      while (!replay_eof && replay_queue.size() < 256) {
        file.read(chunk, sizeof(chunk));
        const size_t n = static_cast<size_t>(file.gcount());
        std::vector<sss::ins::NavSample> read;
        bridge.onBytes(reinterpret_cast<const uint8_t*>(chunk), n, monotonicUtime(), read);
        if (n < sizeof(chunk)) {
          bridge.finish(monotonicUtime(), read);
          replay_eof = true;
        }
        replay_queue.insert(replay_queue.end(), read.begin(), read.end());
      }
      const int64_t now = monotonicUtime();
      for (int budget = 500; budget > 0 && !replay_queue.empty() && pacer.due(replay_queue.front().ins.utime_us, now); --budget) {
        samples.push_back(replay_queue.front());
        replay_queue.pop_front();
        publishAll(now);
      }
      if (replay_eof && replay_queue.empty()) {
        spdlog::info("replay of '{}' finished: {} epochs", options.file, bridge.assemblerCounters().epochs);
        loop.stop();
      }
    });
  }
  const int code = loop.run();
  saveOdometerIfMoved();
  if (input_fd >= 0) ::close(input_fd);
  if (fix_fd >= 0) ::close(fix_fd);
  return code;
}
