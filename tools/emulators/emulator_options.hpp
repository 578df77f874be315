// Command-line options shared by the emulators: pacing and fault injection.
#pragma once

#include <string>

#include "tools/emulators/stream_server.hpp"

namespace sss::emulators {

// Parses one option (and its value) at argv[i]; advances i. Returns false if argv[i] is not a
// stream option, and sets error when its value is bad.
bool parseStreamOption(int argc, char** argv, int& i, StreamServerOptions& options, std::string& error);
// The help lines for those options.
const char* streamOptionsHelp();

}  // namespace sss::emulators
