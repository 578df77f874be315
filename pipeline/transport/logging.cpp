// Logging setup, see logging.hpp.
#include "pipeline/transport/logging.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>

#include <cstdlib>

namespace sss::transport {

void initLogging(const std::string& process_name, const std::string& level) {
  auto logger = spdlog::stderr_color_mt(process_name);
  const bool under_systemd = std::getenv("JOURNAL_STREAM") != nullptr;
  logger->set_pattern(under_systemd ? "<%l> %v" : "%Y-%m-%dT%H:%M:%S.%e %n [%^%l%$] %v");
  logger->set_level(spdlog::level::from_str(level));
  spdlog::set_default_logger(logger);
}

void writeServiceLog(sss::core::ServiceLog& log) {
  if (log.empty()) return;  // the usual case, after every nav sample (200 Hz)
  for (const std::string& line : log.info) spdlog::info("{}", line);
  for (const std::string& line : log.warnings) spdlog::warn("{}", line);
  for (const std::string& line : log.errors) spdlog::error("{}", line);
  log = {};
}

}  // namespace sss::transport
