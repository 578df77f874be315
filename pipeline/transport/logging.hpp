// Logging setup for every process: spdlog to stderr, without timestamps under systemd (the
// journal stamps lines itself), with them otherwise.
#pragma once

#include <spdlog/spdlog.h>

#include <string>

namespace sss::transport {

// level: trace, debug, info, warn, error, critical, off.
void initLogging(const std::string& process_name, const std::string& level = "info");

}  // namespace sss::transport
