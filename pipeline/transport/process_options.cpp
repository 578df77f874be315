// Shared process options, see process_options.hpp.
#include "pipeline/transport/process_options.hpp"

#include <cstdio>
#include <string>

#include "pipeline/transport/logging.hpp"

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

namespace {

void addNodeFlags(sss::cli::CommandLine& command_line, NodeArguments& arguments) {
  command_line.add_option("--config", arguments.config_path, "YAML configuration (every key optional; see config/sss-slam.yaml)");
  command_line.add_flag("--check-config", arguments.check_config_only, "validate the configuration, print the verdict and exit");
  command_line.add_option("--lcm-url", arguments.lcm_url_override, "LCM URL instead of the configured one (udpm://, memq://, ...)");
}

}  // namespace

int parseNodeArguments(const std::string& process_name, const std::string& description, int argc, char** argv,
                       NodeArguments& arguments) {
  sss::cli::CommandLine command_line(process_name, description);
  addNodeFlags(command_line, arguments);
  return sss::cli::parseCommandLine(command_line, argc, argv);
}

int parseNodeArguments(const std::string& process_name, const std::string& description, const std::string& file_help,
                       int argc, char** argv, NodeArguments& arguments, ReplayFlags& replay_flags) {
  sss::cli::CommandLine command_line(process_name, description);
  addNodeFlags(command_line, arguments);
  command_line.add_option("--file", replay_flags.file, file_help);
  command_line.add_option("--speed", replay_flags.speed, "replay speed (0: as fast as possible)")->check(CLI::Range(0.0, 1000.0));
  return sss::cli::parseCommandLine(command_line, argc, argv);
}

int finishConfiguration(const std::string& problems, const NodeArguments& arguments, ProcessOptions& process) {
  const char* name = process.process_name.c_str();
  if (!problems.empty()) {
    std::fprintf(stderr, "%s: invalid configuration:\n%s", name, problems.c_str());
    return 2;
  }
  if (arguments.check_config_only) {
    std::printf("%s: configuration '%s' is valid\n", name, arguments.config_path.c_str());
    return 0;
  }
  if (!arguments.lcm_url_override.empty()) process.lcm_url = arguments.lcm_url_override;
  initLogging(process.process_name, process.log_level);
  return -1;
}

}  // namespace sss::transport
