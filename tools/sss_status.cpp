// sss-status: a terminal view of every process's SSS_STATUS (state, rates, latencies, drops,
// counters, last error), refreshed once per second: a top for the chain.
//   sss-status [--lcm-url URL] [--channel SSS_STATUS] [--once SECONDS]
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <map>
#include <string>

#include "pipeline/core/time.hpp"
#include "pipeline/transport/command_line.hpp"
#include "pipeline/transport/logging.hpp"
#include "pipeline/transport/process_loop.hpp"

namespace {

const char* stateName(int8_t state) {
  switch (state) {
    case sss_msgs::status_t::STATE_OK: return "OK";
    case sss_msgs::status_t::STATE_WARNING: return "WARN";
    default: return "ERROR";
  }
}

std::string render(const std::map<std::string, sss_msgs::status_t>& latest, int64_t now_utime) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof(line), "sss-status  %s  %zu processes\n\n", sss::core::formatUtimeIso8601(now_utime).c_str(),
                latest.size());
  out += line;
  for (const auto& [name, status] : latest) {
    const double age_s = sss::core::utimeToSeconds(now_utime - status.utime);
    std::snprintf(line, sizeof(line), "%-22s %-5s pid %-7d up %8.1f s  errors %-6lld %s%s\n", name.c_str(),
                  stateName(status.state), status.pid, status.uptime_s, static_cast<long long>(status.errors_total),
                  status.state_text.c_str(), age_s > 3.0 ? "  [SILENT]" : "");
    out += line;
    for (const auto& ch : status.channels) {
      std::snprintf(line, sizeof(line), "    %-3s %-18s %8.2f Hz  %9lld msgs  p50 %7.2f ms  p99 %7.2f ms  queue %4d  drops %lld\n",
                    ch.outgoing ? "out" : "in", ch.channel.c_str(), ch.rate_hz, static_cast<long long>(ch.messages),
                    ch.latency_p50_ms, ch.latency_p99_ms, ch.queue_depth, static_cast<long long>(ch.drops));
      out += line;
    }
    for (int i = 0; i < status.num_counters; ++i) {
      std::snprintf(line, sizeof(line), "    %-40s %g\n", status.counter_name[i].c_str(), status.counter_value[i]);
      out += line;
    }
    if (!status.last_error.empty()) out += "    last error: " + status.last_error + "\n";
    out += "\n";
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  sss::transport::ProcessOptions options;
  options.process_name = "sss-status";
  double once_after_s = 0.0;
  sss::cli::CommandLine command_line("sss-status",
                                     "a terminal view of every process's SSS_STATUS, refreshed once per second");
  command_line.add_option("--lcm-url", options.lcm_url, "LCM URL");
  command_line.add_option("--channel", options.status_channel, "status channel");
  command_line.add_option("--once", once_after_s, "print once after this many seconds and exit (0: refresh forever)")
      ->check(sss::cli::nonNegative());
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  sss::transport::initLogging("sss-status", "warn");
  // The viewer publishes its own status on another channel so it never shows itself.
  const std::string watched_channel = options.status_channel;
  options.status_channel = watched_channel + "_VIEWER";
  sss::transport::ProcessLoop loop(options);
  std::map<std::string, sss_msgs::status_t> latest;
  loop.bus().subscribe<sss_msgs::status_t>(watched_channel,
                                           [&](const sss_msgs::status_t& s) { latest[s.process] = s; });
  const bool tty = isatty(STDOUT_FILENO);
  if (once_after_s > 0.0) {
    loop.addTimer(once_after_s, [&] {
      std::fputs(render(latest, sss::core::nowUtime()).c_str(), stdout);
      loop.stop();
    });
  } else {
    loop.addTimer(1.0, [&] {
      if (tty) std::fputs("\033[H\033[2J", stdout);
      std::fputs(render(latest, sss::core::nowUtime()).c_str(), stdout);
      std::fflush(stdout);
    });
  }
  return loop.run();
}
