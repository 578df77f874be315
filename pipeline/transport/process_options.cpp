// Shared process options, see process_options.hpp.
#include "pipeline/transport/process_options.hpp"

#include <cstdio>

namespace sss::transport {

void readProcessOptions(sss::core::ConfigSection& section, ProcessOptions& options) {
  using namespace sss::core;
  section.optional("lcm_url", options.lcm_url,
                   {satisfies<std::string>(
                       [](const std::string& url) {
                         return url.rfind("udpm://", 0) == 0 || url.rfind("memq://", 0) == 0 ||
                                url.rfind("file://", 0) == 0 || url.rfind("tcpq://", 0) == 0;
                       },
                       "an LCM URL: udpm://, memq://, file:// or tcpq://")});
  section.optional("status_channel", options.status_channel, {nonEmpty()});
  section.optional("status_period_s", options.status_period_s, {inRange(0.05, 60.0)});
  section.optional("log_level", options.log_level,
                   {oneOf({"trace", "debug", "info", "warn", "error", "critical", "off"})});
}

int parseNodeArguments(int argc, char** argv, NodeArguments& arguments) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--config" && i + 1 < argc) {
      arguments.config_path = argv[++i];
    } else if (arg == "--check-config") {
      arguments.check_config_only = true;
    } else if (arg == "--lcm-url" && i + 1 < argc) {
      arguments.lcm_url_override = argv[++i];
    } else {
      std::fprintf(stderr, "usage: %s [--config FILE [--check-config]] [--lcm-url URL]\n", argv[0]);
      return arg == "--help" ? 0 : 2;
    }
  }
  return -1;
}

int configVerdict(const std::string& process_name, const std::string& problems, const std::string& config_path,
                  bool check_config_only) {
  if (!problems.empty()) {
    std::fprintf(stderr, "%s: invalid configuration:\n%s", process_name.c_str(), problems.c_str());
    return 2;
  }
  if (check_config_only) {
    std::printf("%s: configuration '%s' is valid\n", process_name.c_str(), config_path.c_str());
    return 0;
  }
  return -1;
}

}  // namespace sss::transport
