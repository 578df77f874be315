// Shared emulator options, see emulator_options.hpp.
#include "tools/emulators/emulator_options.hpp"

#include <csignal>

namespace sss::emulators {

namespace {
std::atomic<bool> g_stop_requested{false};
void onTerminationSignal(int) { g_stop_requested = true; }
}  // namespace

const std::atomic<bool>& stopOnTerminationSignals() {
  std::signal(SIGINT, onTerminationSignal);
  std::signal(SIGTERM, onTerminationSignal);
  return g_stop_requested;
}

void addStreamOptions(sss::cli::CommandLine& command_line, StreamServerOptions& options) {
  command_line.add_option("--bind,--host", options.bind_address, "address: TCP listens on it, UDP sends to it")
      ->capture_default_str();
  command_line.add_option("--port", options.port, "port")->check(CLI::Range(0, 65535))->capture_default_str();
  command_line.add_option("--speed", options.speed, "1 = real time, 10 = ten times faster, 0 = as fast as possible")
      ->check(sss::cli::nonNegative())
      ->capture_default_str();
  command_line.add_option("--corrupt-every", options.faults.corrupt_every,
                          "send garbage bytes before every Kth message (--garbage-bytes N)")
      ->check(sss::cli::nonNegative());
  command_line.add_option("--garbage-bytes", options.faults.garbage_bytes, "garbage bytes per corruption")
      ->check(sss::cli::nonNegative())
      ->capture_default_str();
  command_line.add_option("--flip-every", options.faults.flip_every, "flip a byte inside every Kth message")
      ->check(sss::cli::nonNegative());
  command_line.add_option("--truncate-every", options.faults.truncate_every,
                          "send only the first half of every Kth message")
      ->check(sss::cli::nonNegative());
  command_line.add_option("--drop-every", options.faults.drop_connection_every,
                          "close the connection after every Kth message (TCP)")
      ->check(sss::cli::nonNegative());
  command_line.add_option("--pause-every", options.faults.pause_every,
                          "pause --pause-s seconds after every Kth message (then send what fell due)")
      ->check(sss::cli::nonNegative());
  command_line.add_option("--pause-s", options.faults.pause_s, "length of a pause")
      ->check(sss::cli::nonNegative())
      ->capture_default_str();
  command_line.add_flag("--pause-skip", options.faults.pause_skips,
                        "a pause is an outage: what falls due meanwhile is never sent");
  command_line.add_option("--seed", options.faults.seed, "seed of the fault randomness")->capture_default_str();
}

}  // namespace sss::emulators
