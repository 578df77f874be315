// Logging setup for every process: spdlog to stderr, without timestamps under systemd (the
// journal stamps lines itself), with them otherwise.
#pragma once

#include <spdlog/spdlog.h>

#include <string>

#include "pipeline/core/service_log.hpp"

namespace sss::transport {

// level: trace, debug, info, warn, error, critical, off.
void initLogging(const std::string& process_name, const std::string& level = "info");

// Writes a service's log lines at their levels and clears them.
void writeServiceLog(sss::core::ServiceLog& log);

}  // namespace sss::transport
