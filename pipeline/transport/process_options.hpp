// Options every process shares: its name, the LCM URL, the status channel and period, logging.
#pragma once

#include <optional>
#include <string>

#include "pipeline/core/config.hpp"
#include "pipeline/transport/command_line.hpp"

namespace sss::transport {

// Multicast on the local host only (ttl=0), with a receive buffer that holds a burst of
// multi-megabyte subframes: LCM drops fragmented messages that overflow the socket buffer.
// The kernel caps it at net.core.rmem_max (raise it on the vehicle, see systemd/).
inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216";

struct ProcessOptions {
  std::string process_name = "sss";
  std::string lcm_url = kDefaultLcmUrl;
  std::string status_channel = "SSS_STATUS";
  double status_period_s = 1.0;
  std::string log_level = "info";
};

// Reads the "process" keys of a process's section (lcm_url, status_channel, status_period_s,
// log_level); process_name is set by the program.
void readProcessOptions(sss::core::ConfigSection& section, ProcessOptions& options);

// The flags every pipeline process takes: NAME [--config FILE [--check-config]] [--lcm-url URL].
struct NodeArguments {
  std::string config_path;
  std::string lcm_url_override;
  bool check_config_only = false;
};
// The command line of a process that takes only those flags. -1 to go on; otherwise the exit code
// to return (command_line.hpp: 0 for --help, 2 for bad flags).
int parseNodeArguments(const std::string& process_name, const std::string& description, int argc, char** argv,
                       NodeArguments& arguments);

// The drivers' replay flags, --file FILE and --speed X (0: as fast as possible). Set only when
// given: they win over the configuration file's keys, which are still read (and so still known).
struct ReplayFlags {
  std::optional<std::string> file;
  std::optional<double> speed;
};
// The command line of a driver: the flags above and the replay flags (file_help: what --file
// replays). Returns as parseNodeArguments.
int parseNodeArguments(const std::string& process_name, const std::string& description, const std::string& file_help,
                       int argc, char** argv, NodeArguments& arguments, ReplayFlags& replay_flags);

// The end of every process's configuration step. problems: Config::problemReport() (empty when
// valid). Prints them and returns 2 when there are any; with --check-config says the file is valid
// and returns 0. Otherwise the process will run: --lcm-url replaces the configured URL, logging is
// set up as configured (logging.hpp) and it returns -1.
int finishConfiguration(const std::string& problems, const NodeArguments& arguments, ProcessOptions& process);

}  // namespace sss::transport
