// sss-bench-drivers: runs sss-sonar-driver and sss-ins-bridge as processes against the emulators
// at EdgeTech 2205 rates and prints (1) the latency from a ping's last byte leaving the emulator's
// socket to its SSS_PING arriving on LCM (p50/p99/max) and (2) the CPU use of each process.
//   sss-bench-drivers [--seconds 30] [--ping-rate-hz 10] [--samples 20000] [--ins-rate-hz 20]
#include <nlohmann/json.hpp>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include "pipeline/transport/command_line.hpp"
#include "drivers/edgetech/jsf_format.hpp"
#include "drivers/ins/ixblue_nmea.hpp"
#include "pipeline/core/health.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/transport/lcm_bus.hpp"
#include "sss_msgs/nav_t.hpp"
#include "sss_msgs/ping_t.hpp"
#include "tools/emulators/stream_server.hpp"

extern char** environ;

namespace {

double cpuSeconds(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  std::getline(stat, line);
  // Fields after the ")" of the command name: state is field 3; utime 14, stime 15.
  std::istringstream rest(line.substr(line.rfind(')') + 2));
  std::string field;
  double utime = 0, stime = 0;
  for (int i = 3; i <= 15 && rest >> field; ++i) {
    if (i == 14) utime = std::stod(field);
    if (i == 15) stime = std::stod(field);
  }
  return (utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

pid_t spawn(const char* path, const std::string& config) {
  pid_t pid = 0;
  char* argv[] = {const_cast<char*>(path), const_cast<char*>("--config"), const_cast<char*>(config.c_str()), nullptr};
  if (posix_spawn(&pid, path, nullptr, nullptr, argv, environ) != 0) return -1;
  return pid;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 30.0, ping_rate_hz = 10.0, ins_rate_hz = 20.0;
  size_t samples = 20000;
  sss::cli::CommandLine command_line("sss-bench-drivers",
                                     "the sonar driver and INS bridge on a synthetic stream: throughput and latency");
  command_line.add_option("--seconds", seconds, "stream length")->check(sss::cli::positive())->capture_default_str();
  command_line.add_option("--ping-rate-hz", ping_rate_hz, "ping rate")->check(sss::cli::positive())
      ->capture_default_str();
  command_line.add_option("--samples", samples, "samples per side")->check(sss::cli::positive())->capture_default_str();
  command_line.add_option("--ins-rate-hz", ins_rate_hz, "INS rate")->check(sss::cli::positive())->capture_default_str();
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  const int64_t start_utime = sss::core::nowUtime();
  const int pings = static_cast<int>(seconds * ping_rate_hz);

  // Sonar stream: port then starboard per ping, sonar clock = host clock.
  std::vector<sss::emulators::TimedChunk> sonar_chunks;
  std::vector<float> magnitudes(samples);
  for (size_t i = 0; i < samples; ++i) magnitudes[i] = 100.0f + 50.0f * std::sin(0.001f * static_cast<float>(i));
  for (int p = 0; p < pings; ++p) {
    for (uint8_t channel : {sss::sonar::kChannelPort, sss::sonar::kChannelStarboard}) {
      sss::sonar::SonarChannelRecord record;
      record.channel = channel;
      record.ping_number = static_cast<uint32_t>(p);
      record.ping_time_us = start_utime + static_cast<int64_t>(p * 1e6 / ping_rate_hz);
      record.sample_interval_s = 2.0 * 150.0 / 1500.0 / static_cast<double>(samples);  // 150 m range
      const auto codes = sss::edgetech::quantiseEnvelope(magnitudes, record.weighting_factor);
      sonar_chunks.push_back({record.ping_time_us, sss::edgetech::encodeSonarData(record, codes)});
    }
  }
  // INS stream: one burst per epoch.
  std::vector<sss::emulators::TimedChunk> ins_chunks;
  const int epochs = static_cast<int>(seconds * ins_rate_hz);
  for (int e = 0; e < epochs; ++e) {
    sss::ins::InsState state;
    state.utime_us = start_utime + static_cast<int64_t>(e * 1e6 / ins_rate_hz);
    state.latitude_deg = 59.35 + 1e-6 * e;
    state.longitude_deg = 18.07;
    state.depth_m = 40.0;
    state.altitude_m = 18.0;
    state.velocity_north_m_s = 2.0;
    state.validity = sss::ins::kValidAll;
    const std::string burst = sss::ins::encodeInsState(state);
    ins_chunks.push_back({state.utime_us, std::vector<uint8_t>(burst.begin(), burst.end())});
  }

  sss::emulators::StreamServerOptions sonar_options;
  sonar_options.port = 0;
  sss::emulators::TcpStreamServer sonar_server(sonar_options, sonar_chunks);
  if (const sss::core::Status listening = sonar_server.listen(); !listening) {
    std::fprintf(stderr, "%s\n", listening.message.c_str());
    return 1;
  }
  std::mutex sent_mutex;
  std::map<int64_t, int64_t> last_byte_sent_us;  // ping number -> monotonic time
  sonar_server.setChunkSentCallback([&](size_t index, int64_t when) {
    if (index % 2 == 1) {
      std::lock_guard<std::mutex> lock(sent_mutex);
      last_byte_sent_us[static_cast<int64_t>(index / 2)] = when;
    }
  });
  const int udp_port = 31000 + static_cast<int>(getpid() % 1000);
  const std::string lcm_url =
      "udpm://239.255.76.67:" + std::to_string(32000 + getpid() % 1000) + "?ttl=0&recv_buf_size=16777216";
  const std::string config_path = "/tmp/sss-bench-drivers-" + std::to_string(getpid()) + ".yaml";
  {
    std::ofstream config(config_path);
    config << "sonar_driver:\n  host: 127.0.0.1\n  port: " << sonar_server.port() << "\n  lcm_url: \"" << lcm_url
           << "\"\n  log_level: warn\nins_bridge:\n  source: udp\n  bind_address: 127.0.0.1\n  udp_port: " << udp_port
           << "\n  lcm_url: \"" << lcm_url << "\"\n  log_level: warn\n";
  }
  sss::core::HealthMonitor health(sss::core::monotonicUtime());
  sss::transport::LcmBus bus(lcm_url, health);
  std::map<int64_t, int64_t> received_us;
  int navs = 0;
  bus.subscribe<sss_msgs::ping_t>("SSS_PING", [&](const sss_msgs::ping_t& ping) {
    received_us[ping.ping_number] = sss::core::monotonicUtime();
  });
  bus.subscribe<sss_msgs::nav_t>("SSS_NAV", [&](const sss_msgs::nav_t&) { ++navs; });

  const pid_t driver = spawn(SONAR_DRIVER_PATH, config_path);
  const pid_t bridge = spawn(INS_BRIDGE_PATH, config_path);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const double driver_cpu_start = cpuSeconds(driver), bridge_cpu_start = cpuSeconds(bridge);
  const int64_t run_start = sss::core::monotonicUtime();

  std::atomic<bool> stop{false};
  std::thread sonar_thread([&] { sonar_server.run(stop); });
  sss::emulators::StreamServerOptions ins_options;
  ins_options.bind_address = "127.0.0.1";
  ins_options.port = udp_port;
  sss::emulators::UdpStreamSender ins_sender(ins_options, ins_chunks);
  std::thread ins_thread([&] {
    if (const sss::core::Status sent = ins_sender.run(stop); !sent) std::fprintf(stderr, "%s\n", sent.message.c_str());
  });
  const int64_t end = run_start + static_cast<int64_t>((seconds + 1.0) * 1e6);
  while (sss::core::monotonicUtime() < end) bus.handleTimeout(20);
  sonar_thread.join();
  ins_thread.join();
  const double elapsed_s = static_cast<double>(sss::core::monotonicUtime() - run_start) * 1e-6;
  const double driver_cpu = (cpuSeconds(driver) - driver_cpu_start) / elapsed_s;
  const double bridge_cpu = (cpuSeconds(bridge) - bridge_cpu_start) / elapsed_s;
  for (pid_t pid : {driver, bridge}) {
    ::kill(pid, SIGTERM);
    ::waitpid(pid, nullptr, 0);
  }
  ::unlink(config_path.c_str());

  std::vector<int64_t> latencies;
  for (const auto& [ping, received] : received_us) {
    const auto sent = last_byte_sent_us.find(ping);
    if (sent != last_byte_sent_us.end()) latencies.push_back(received - sent->second);
  }
  const double p50 = sss::core::percentile(latencies, 50.0) * 1e-3;
  const double p99 = sss::core::percentile(latencies, 99.0) * 1e-3;
  const double max = latencies.empty() ? 0.0 : static_cast<double>(latencies.back()) * 1e-3;
  const double mb_per_s = static_cast<double>(samples) * 2 * 2 * ping_rate_hz / 1e6;
  std::printf("sonar: %d pings at %.1f Hz, %zu samples/side (%.1f MB/s of JSF); INS: %d epochs at %.1f Hz\n", pings,
              ping_rate_hz, samples, mb_per_s, epochs, ins_rate_hz);
  std::printf("SSS_PING received %zu / %d (the first pings wait for the clock-offset estimate), SSS_NAV %d / %d\n",
              received_us.size(), pings, navs, epochs);
  std::printf("latency last byte -> SSS_PING: p50 %.2f ms, p99 %.2f ms, max %.2f ms\n", p50, p99, max);
  std::printf("CPU: sss-sonar-driver %.1f %%, sss-ins-bridge %.1f %% of one core\n", 100 * driver_cpu, 100 * bridge_cpu);
  // The machine-readable last line (nlohmann: a figure that is not finite is null, never an invalid nan).
  nlohmann::ordered_json figures;
  figures["pings"] = pings;
  figures["pings_received"] = received_us.size();
  figures["latency_p50_ms"] = p50;
  figures["latency_p99_ms"] = p99;
  figures["latency_max_ms"] = max;
  figures["driver_cpu_percent"] = 100 * driver_cpu;
  figures["ins_bridge_cpu_percent"] = 100 * bridge_cpu;
  figures["navs_received"] = navs;
  std::printf("%s\n", figures.dump().c_str());
  return 0;
}
