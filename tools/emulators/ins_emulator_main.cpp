// sss-ins-emulator: sends a recorded iXblue NMEA stream as the INS does, one datagram per output
// burst over UDP (default) or as a TCP server, paced by the epoch times, with fault injection; with
// --fixes, also the absolute fixes of sss-sim's fixes.nmea (GNSS, USBL) as their receivers would, one
// UDP datagram per fix to --fixes-port, in step with the INS stream.
//   sss-ins-emulator --file ins.nmea [--udp | --tcp] [--host 127.0.0.1] [--port 8110] [--speed 1]
//                    [--fixes fixes.nmea --fixes-port 8111]
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "tools/emulators/emulator_options.hpp"
#include "tools/emulators/recorded_streams.hpp"

int main(int argc, char** argv) {
  sss::emulators::StreamServerOptions options;
  options.port = 8110;
  std::string file, fixes_file;
  int fixes_port = 8111;
  bool tcp = false;
  sss::cli::CommandLine command_line(
      "sss-ins-emulator",
      "sends a recorded iXblue NMEA stream as the INS does, paced by the epoch times, with fault injection",
      "UDP sends to --host:--port; TCP listens on --host:--port; fixes go by UDP to --host:--fixes-port\n"
      "(no faults injected into them).");
  command_line.add_option("--file", file, "the NMEA file to send")->required();
  command_line.add_option("--fixes", fixes_file, "also send these absolute fixes (sss-sim's fixes.nmea)");
  command_line.add_option("--fixes-port", fixes_port, "UDP port of the fixes")->check(CLI::Range(1, 65535))
      ->capture_default_str();
  command_line.add_flag("--tcp,!--udp", tcp, "serve as a TCP server instead of sending UDP datagrams");
  sss::emulators::addStreamOptions(command_line, options);
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  const std::atomic<bool>& stop_requested = sss::emulators::stopOnTerminationSignals();
  sss::core::Result<std::vector<sss::emulators::TimedChunk>> loaded = sss::emulators::loadInsChunks(file);
  if (!loaded || loaded->empty()) {
    std::fprintf(stderr, "sss-ins-emulator: %s\n", loaded ? "no NMEA bursts in the file" : loaded.message().c_str());
    return 1;
  }
  std::vector<sss::emulators::TimedChunk> chunks = std::move(*loaded);
  std::printf("sss-ins-emulator: %zu bursts from %s %s %s:%d at speed %g\n", chunks.size(), file.c_str(),
              tcp ? "served on" : "sent to", options.bind_address.c_str(), options.port, options.speed);
  // Fixes: their own sender, paced from the INS stream's first epoch so both keep the mission's time.
  std::thread fixes_thread;
  std::string fixes_error;
  if (!fixes_file.empty()) {
    sss::core::Result<std::vector<sss::emulators::TimedChunk>> fixes_loaded =
        sss::emulators::loadFixChunks(fixes_file, chunks.front().time_us);
    if (!fixes_loaded) {
      std::fprintf(stderr, "sss-ins-emulator: %s\n", fixes_loaded.message().c_str());
      return 1;
    }
    std::vector<sss::emulators::TimedChunk> fix_chunks = std::move(*fixes_loaded);
    sss::emulators::StreamServerOptions fix_options;
    fix_options.bind_address = options.bind_address;
    fix_options.port = fixes_port;
    fix_options.speed = options.speed;
    fix_options.pacing_origin_us = chunks.front().time_us;
    std::printf("sss-ins-emulator: %zu fixes from %s sent to %s:%d\n", fix_chunks.size(), fixes_file.c_str(),
                options.bind_address.c_str(), fixes_port);
    fixes_thread = std::thread([fix_options, fix_chunks = std::move(fix_chunks), &fixes_error, &stop_requested]() mutable {
      sss::emulators::UdpStreamSender sender(fix_options, std::move(fix_chunks));
      if (const sss::core::Status sent = sender.run(stop_requested); !sent) fixes_error = sent.message;
    });
  }
  std::fflush(stdout);
  sss::emulators::StreamStats stats;
  if (tcp) {
    sss::emulators::TcpStreamServer server(options, std::move(chunks));
    if (const sss::core::Status listening = server.listen(); !listening) {
      std::fprintf(stderr, "sss-ins-emulator: %s\n", listening.message.c_str());
      return 1;
    }
    server.run(stop_requested);
    stats = server.stats();
  } else {
    sss::emulators::UdpStreamSender sender(options, std::move(chunks));
    if (const sss::core::Status sent = sender.run(stop_requested); !sent) {
      std::fprintf(stderr, "sss-ins-emulator: %s\n", sent.message.c_str());
      return 1;
    }
    stats = sender.stats();
  }
  if (fixes_thread.joinable()) fixes_thread.join();
  if (!fixes_error.empty()) std::fprintf(stderr, "sss-ins-emulator: fixes: %s\n", fixes_error.c_str());
  // What was injected, for the fault tests' logs (tools/run-chain).
  std::printf("sss-ins-emulator: sent %llu whole, %llu faulted, %llu garbage runs, %llu connections, %llu drops, "
              "%llu pauses, %llu skipped\n",
              static_cast<unsigned long long>(stats.chunks_sent), static_cast<unsigned long long>(stats.chunks_faulted),
              static_cast<unsigned long long>(stats.garbage_runs), static_cast<unsigned long long>(stats.connections),
              static_cast<unsigned long long>(stats.drops), static_cast<unsigned long long>(stats.pauses),
              static_cast<unsigned long long>(stats.chunks_skipped));
  return 0;
}
