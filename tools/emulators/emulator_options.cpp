// Shared emulator options, see emulator_options.hpp.
#include "tools/emulators/emulator_options.hpp"

#include <cstdlib>

namespace sss::emulators {

namespace {
bool number(const char* text, double& value) {
  char* end = nullptr;
  value = std::strtod(text, &end);
  return end != text && *end == '\0';
}
}  // namespace

bool parseStreamOption(int argc, char** argv, int& i, StreamServerOptions& options, std::string& error) {
  const std::string arg = argv[i];
  auto value = [&](double& out) {
    if (i + 1 >= argc || !number(argv[i + 1], out) || out < 0) {
      error = arg + " needs a non-negative number";
      return false;
    }
    ++i;
    return true;
  };
  double v = 0.0;
  if (arg == "--bind" || arg == "--host") {
    if (i + 1 >= argc) {
      error = arg + " needs an address";
      return true;
    }
    options.bind_address = argv[++i];
  } else if (arg == "--port") {
    if (value(v)) options.port = static_cast<int>(v);
  } else if (arg == "--speed") {
    if (value(v)) options.speed = v;
  } else if (arg == "--corrupt-every") {
    if (value(v)) options.faults.corrupt_every = static_cast<int>(v);
  } else if (arg == "--garbage-bytes") {
    if (value(v)) options.faults.garbage_bytes = static_cast<int>(v);
  } else if (arg == "--flip-every") {
    if (value(v)) options.faults.flip_every = static_cast<int>(v);
  } else if (arg == "--truncate-every") {
    if (value(v)) options.faults.truncate_every = static_cast<int>(v);
  } else if (arg == "--drop-every") {
    if (value(v)) options.faults.drop_connection_every = static_cast<int>(v);
  } else if (arg == "--pause-every") {
    if (value(v)) options.faults.pause_every = static_cast<int>(v);
  } else if (arg == "--pause-s") {
    if (value(v)) options.faults.pause_s = v;
  } else if (arg == "--pause-skip") {
    options.faults.pause_skips = true;
  } else if (arg == "--seed") {
    if (value(v)) options.faults.seed = static_cast<uint32_t>(v);
  } else {
    return false;
  }
  return true;
}

const char* streamOptionsHelp() {
  return "  --speed X           1 = real time (default), 10 = ten times faster, 0 = as fast as possible\n"
         "  --corrupt-every K   send garbage bytes before every Kth message (--garbage-bytes N, default 64)\n"
         "  --flip-every K      flip a byte inside every Kth message\n"
         "  --truncate-every K  send only the first half of every Kth message\n"
         "  --drop-every K      close the connection after every Kth message (TCP)\n"
         "  --pause-every K     pause --pause-s seconds after every Kth message (then send what fell due)\n"
         "  --pause-skip        a pause is an outage: what falls due meanwhile is never sent\n"
         "  --seed N            seed of the fault randomness\n";
}

}  // namespace sss::emulators
