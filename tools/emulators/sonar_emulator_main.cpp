// sss-sonar-emulator: serves a .jsf file over TCP as an EdgeTech 2205 sonar processor's data
// port does, paced by the ping times, with optional fault injection.
//   sss-sonar-emulator --file sonar.jsf [--bind 127.0.0.1] [--port 1701] [--speed 1] [faults]
#include <cstdio>
#include <string>

#include "tools/emulators/emulator_options.hpp"
#include "tools/emulators/recorded_streams.hpp"

int main(int argc, char** argv) {
  sss::emulators::StreamServerOptions options;
  std::string file;
  bool repeat = false;
  sss::cli::CommandLine command_line("sss-sonar-emulator",
                                     "serves a .jsf file over TCP as an EdgeTech 2205 sonar processor's data port does, "
                                     "paced by the ping times, with optional fault injection");
  command_line.add_option("--file", file, "the JSF file to serve")->required();
  command_line.add_flag("--repeat", repeat, "serve the file again after every pass");
  sss::emulators::addStreamOptions(command_line, options);
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  const std::atomic<bool>& stop_requested = sss::emulators::stopOnTerminationSignals();
  const sss::core::Result<std::vector<sss::emulators::TimedChunk>> loaded = sss::emulators::loadJsfChunks(file);
  if (!loaded || loaded->empty()) {
    std::fprintf(stderr, "sss-sonar-emulator: %s\n", loaded ? "no JSF messages in the file" : loaded.message().c_str());
    return 1;
  }
  const std::vector<sss::emulators::TimedChunk>& chunks = *loaded;
  do {
    sss::emulators::TcpStreamServer server(options, chunks);
    if (const sss::core::Status listening = server.listen(); !listening) {
      std::fprintf(stderr, "sss-sonar-emulator: %s\n", listening.message.c_str());
      return 1;
    }
    std::printf("sss-sonar-emulator: %zu messages from %s on %s:%d at speed %g\n", chunks.size(), file.c_str(),
                options.bind_address.c_str(), server.port(), options.speed);
    std::fflush(stdout);
    server.run(stop_requested);
    const auto& s = server.stats();
    std::printf("sss-sonar-emulator: sent %llu whole, %llu faulted, %llu garbage runs, %llu connections, %llu drops, "
                "%llu pauses, %llu skipped\n",
                static_cast<unsigned long long>(s.chunks_sent), static_cast<unsigned long long>(s.chunks_faulted),
                static_cast<unsigned long long>(s.garbage_runs), static_cast<unsigned long long>(s.connections),
                static_cast<unsigned long long>(s.drops), static_cast<unsigned long long>(s.pauses),
                static_cast<unsigned long long>(s.chunks_skipped));
    std::fflush(stdout);
  } while (repeat && !stop_requested);
  return 0;
}
