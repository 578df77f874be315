// sss-subframe-tool: runs the subframe buffer offline over a .jsf and an iXblue NMEA file (the
// same decoding as the live drivers), writes waterfall and mosaic PNGs and prints the figures.
//   sss-subframe-tool --sonar sonar.jsf --ins ins.nmea --out DIR [--config FILE]
#include <sys/stat.h>
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "drivers/edgetech/ping_message.hpp"
#include "drivers/edgetech/sonar_driver.hpp"
#include "drivers/ins/ins_bridge.hpp"
#include "drivers/ins/nav_message.hpp"
#include "pipeline/core/health.hpp"
#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/subframe/pictures.hpp"
#include "pipeline/transport/command_line.hpp"
#include "pipeline/subframe/subframe_buffer.hpp"
#include "pipeline/messages/subframe_messages.hpp"
#include "pipeline/messages/sensor_messages.hpp"

namespace {

int64_t threadCpuUs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000 + ts.tv_nsec / 1000;
}

}  // namespace

int main(int argc, char** argv) {
  std::string sonar_path, ins_path, out_dir, config_path;
  sss::cli::CommandLine command_line("sss-subframe-tool",
                                     "runs the subframe buffer offline over a .jsf and an iXblue NMEA file, writes "
                                     "waterfall and mosaic PNGs and prints the figures");
  command_line.add_option("--sonar", sonar_path, "the JSF file")->required();
  command_line.add_option("--ins", ins_path, "the iXblue NMEA file")->required();
  command_line.add_option("--out", out_dir, "output folder")->required();
  command_line.add_option("--config", config_path, "YAML configuration (subframe_buffer section)");
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  sss::subframe::SubframeBufferOptions options;
  sss::ins::InsBridgeOptions bridge_options;
  if (!config_path.empty()) {
    using namespace sss::core;
    Config config = Config::fromFile(config_path);
    ConfigSection mission = config.section("mission");
    bridge_options.origin = sss::core::readMissionOrigin(mission);
    ConfigSection section = config.section("subframe_buffer");
    sss::subframe::readSubframeBufferOptions(section, options);
    if (!config.ok()) {
      std::fprintf(stderr, "sss-subframe-tool: invalid configuration:\n%s", config.problemReport().c_str());
      return 2;
    }
  }
  ::mkdir(out_dir.c_str(), 0755);

  // Navigation: the whole file (small: ~200 bytes per sample), through the INS bridge and SSS_NAV.
  std::vector<sss::subframe::NavInput> nav;
  {
    std::ifstream file(ins_path, std::ios::binary);
    if (!file) {
      std::fprintf(stderr, "cannot open INS file '%s'\n", ins_path.c_str());
      return 1;
    }
    const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    sss::ins::InsBridge bridge(bridge_options);
    std::vector<sss::ins::NavSample> samples;
    bridge.onBytes(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), 0, samples);
    bridge.finish(0, samples);
    for (const auto& s : samples) nav.push_back(sss::messages::fromNavMessage(sss::ins::toNavMessage(s)));
  }
  // Pings: streamed through the sonar driver (sonar clock, as in replay) and SSS_PING.
  std::FILE* jsf = std::fopen(sonar_path.c_str(), "rb");
  if (!jsf) {
    std::fprintf(stderr, "cannot open sonar file '%s'\n", sonar_path.c_str());
    return 1;
  }
  sss::edgetech::SonarDriverOptions driver_options;
  driver_options.time_source = sss::edgetech::TimeSource::kSonarClock;
  sss::edgetech::SonarDriver driver(driver_options);

  sss::subframe::SubframeBuffer buffer(options);
  std::vector<sss::core::Subframe> all, out;
  std::vector<int64_t> latency_us;
  int64_t cpu_us = 0;
  size_t max_memory = 0, nav_index = 0, message_bytes = 0;
  auto collect = [&] {
    for (sss::core::Subframe& s : out) {
      const sss_msgs::subframe_t message = sss::messages::toSubframeMessage(s, options.subframes.intensity_bits,
                                                                            options.subframes.max_intensity);
      std::vector<uint8_t> encoded(static_cast<size_t>(message.getEncodedSize()));
      message.encode(encoded.data(), 0, static_cast<int>(encoded.size()));
      message_bytes = std::max(message_bytes, encoded.size());
      latency_us.push_back(sss::core::monotonicUtime() - s.last_ping_arrival_monotonic_us);
      all.push_back(std::move(s));
    }
    out.clear();
  };
  std::vector<sss::sonar::DriverPing> pings;
  std::vector<char> chunk(1 << 20);
  bool eof = false;
  while (!eof) {
    const size_t n = std::fread(chunk.data(), 1, chunk.size(), jsf);
    if (n > 0) driver.onBytes(reinterpret_cast<const uint8_t*>(chunk.data()), n, 0, sss::core::monotonicUtime(), pings);
    if (n < chunk.size()) {
      driver.finish(0, sss::core::monotonicUtime(), pings);
      eof = true;
    }
    for (const auto& driver_ping : pings) {
      const sss_msgs::ping_t message = sss::edgetech::toPingMessage(driver_ping);
      // Nav up to 1 s past the ping first, as it would have arrived live.
      const int64_t cpu0 = threadCpuUs();
      while (nav_index < nav.size() && nav[nav_index].utime_us <= message.utime + 1000000) {
        buffer.addNav(nav[nav_index++], out);
      }
      buffer.addPing(sss::messages::fromPingMessage(message, sss::core::monotonicUtime()), out);
      collect();
      cpu_us += threadCpuUs() - cpu0;
      max_memory = std::max(max_memory, buffer.memoryBytes());
    }
    pings.clear();
  }
  std::fclose(jsf);
  while (nav_index < nav.size()) buffer.addNav(nav[nav_index++], out);
  buffer.finish(out);
  collect();

  const sss::subframe::SubframeBufferCounters c = buffer.counters();
  sss::subframe::PictureOptions picture_options;
  const auto waterfalls = sss::subframe::writeWaterfalls(all, out_dir, picture_options);
  const sss::core::Status mosaic_ok = sss::subframe::writeMosaic(all, {}, out_dir + "/mosaic.png", picture_options);
  if (!waterfalls) std::fprintf(stderr, "%s\n", waterfalls.message().c_str());
  if (!mosaic_ok) std::fprintf(stderr, "%s\n", mosaic_ok.message.c_str());
  const std::vector<std::string> files = waterfalls ? waterfalls.value() : std::vector<std::string>{};

  std::printf("pings in %llu, fused %llu, dropped without nav %llu, out of order %llu, duplicates %llu, "
              "altitude from ping %llu, dropped no altitude %llu, turn rows %llu\n",
              (unsigned long long)c.fusion.pings_in, (unsigned long long)c.fusion.pings_out,
              (unsigned long long)c.fusion.droppedWithoutNav(), (unsigned long long)c.fusion.pings_out_of_order,
              (unsigned long long)c.fusion.pings_duplicate, (unsigned long long)c.fusion.altitude_from_ping,
              (unsigned long long)c.fusion.dropped_no_altitude, (unsigned long long)c.turn_rows);
  std::printf("lines %llu, subframes %llu (partial %llu), short tails dropped %llu (%llu pings)\n",
              (unsigned long long)c.builder.lines, (unsigned long long)c.builder.subframes,
              (unsigned long long)c.builder.partial_subframes, (unsigned long long)c.builder.dropped_short_tails,
              (unsigned long long)c.builder.dropped_tail_pings);
  for (const auto& s : all) {
    std::printf("  subframe %lld line %d pings %lld..%lld (%d) centre %lld\n", (long long)s.id, s.line_id,
                (long long)s.pings.front().ping_number, (long long)s.pings.back().ping_number, s.rows(),
                (long long)s.centre().ping_number);
  }
  std::vector<int64_t> lat = latency_us;
  std::printf("latency last ping -> subframe encoded: p50 %.2f ms, p99 %.2f ms (%zu subframes)\n",
              sss::core::percentile(lat, 50) / 1000.0, sss::core::percentile(lat, 99) / 1000.0, latency_us.size());
  std::printf("CPU per ping: %.3f ms (%llu pings, incl. nav handling)\n",
              c.fusion.pings_in ? cpu_us / 1000.0 / c.fusion.pings_in : 0.0, (unsigned long long)c.fusion.pings_in);
  std::printf("memory held by the buffer: max %.2f MiB; largest encoded SSS_SUBFRAME %.2f MiB\n",
              max_memory / 1048576.0, message_bytes / 1048576.0);
  for (const auto& f : files) std::printf("wrote %s\n", f.c_str());
  if (mosaic_ok) std::printf("wrote %s/mosaic.png\n", out_dir.c_str());
  return 0;
}
