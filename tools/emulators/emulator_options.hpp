// Command-line options shared by the emulators: address, pacing and fault injection.
#pragma once

#include <atomic>

#include "pipeline/transport/command_line.hpp"
#include "tools/emulators/stream_server.hpp"

namespace sss::emulators {

// Declares --bind/--host, --port, --speed and the fault flags on an emulator's command line; the
// values land in options (its current values are the defaults).
void addStreamOptions(sss::cli::CommandLine& command_line, StreamServerOptions& options);

// Installs SIGINT/SIGTERM handlers; the flag they set, which the servers' run() polls to stop.
const std::atomic<bool>& stopOnTerminationSignals();

}  // namespace sss::emulators
