// Test XTF data written with the public-layout writer: file headers of N channels and pings with
// known samples and navigation, so every decoded field can be checked against its input.
#pragma once

#include <cstdint>
#include <vector>

#include "drivers/xtf/xtf_writer.hpp"

namespace sss::test {

// Port/starboard pairs (frequency_khz per pair), bytes per sample and nav units.
inline xtf::XtfWriterOptions makeXtfOptions(const std::vector<float>& pair_frequencies_khz, uint16_t bytes_per_sample,
                                            uint16_t nav_units = xtf::kNavUnitsLatLon) {
  xtf::XtfWriterOptions options;
  options.nav_units = nav_units;
  for (const float frequency : pair_frequencies_khz) {
    for (const uint8_t type : {xtf::kChannelPort, xtf::kChannelStarboard}) {
      xtf::XtfWriterChannel channel;
      channel.type_of_channel = type;
      channel.bytes_per_sample = bytes_per_sample;
      channel.frequency = frequency;
      channel.name = type == xtf::kChannelPort ? "Port" : "Stbd";
      options.channels.push_back(channel);
    }
  }
  return options;
}

// Sample value of channel c, sample s, ping p: distinct per channel so a swapped side shows.
inline float xtfSample(size_t channel, size_t sample, uint32_t ping, uint16_t bytes_per_sample) {
  const uint32_t range = bytes_per_sample == 1 ? 256u : 65536u;
  return static_cast<float>((channel * 37u + sample * 11u + ping * 5u) % range);
}

constexpr int64_t kXtfFirstPingUs = 1700000000000000;  // 2023-11-14T22:13:20Z
constexpr int64_t kXtfPingPeriodUs = 250000;            // 4 pings/s, a multiple of 1/100 s

inline xtf::XtfPingInput makeXtfPing(const xtf::XtfWriterOptions& options, uint32_t ping_number,
                                     size_t samples = 200) {
  xtf::XtfPingInput ping;
  ping.ping_number = ping_number;
  ping.ping_time_us = kXtfFirstPingUs + kXtfPingPeriodUs * ping_number;
  ping.sound_velocity = 750.0f;
  ping.sensor_y = options.nav_units == xtf::kNavUnitsLatLon ? 59.9 + 1e-5 * ping_number : 6642000.0 + ping_number;
  ping.sensor_x = options.nav_units == xtf::kNavUnitsLatLon ? 10.7 + 2e-5 * ping_number : 597000.0 + ping_number;
  ping.depth_m = 80.0f;
  ping.altitude_m = 18.0f;
  ping.pitch_deg = 2.0f;
  ping.roll_deg = -1.5f;
  ping.heading_deg = 350.0f;
  for (size_t c = 0; c < options.channels.size(); ++c) {
    xtf::XtfChannelData channel;
    channel.channel_number = static_cast<uint16_t>(c);
    channel.slant_range_m = 75.0f;
    for (size_t s = 0; s < samples; ++s) {
      channel.samples.push_back(xtfSample(c, s, ping_number, options.channels[c].bytes_per_sample));
    }
    ping.channels.push_back(channel);
  }
  return ping;
}

inline void appendBytes(std::vector<uint8_t>& to, const std::vector<uint8_t>& bytes) {
  to.insert(to.end(), bytes.begin(), bytes.end());
}

// Header + `pings` sonar packets in memory.
inline std::vector<uint8_t> makeXtfFile(const xtf::XtfWriterOptions& options, uint32_t pings, size_t samples = 200) {
  std::vector<uint8_t> bytes = xtf::encodeFileHeader(options);
  for (uint32_t p = 0; p < pings; ++p) appendBytes(bytes, xtf::encodeSonarPacket(options, makeXtfPing(options, p, samples)));
  return bytes;
}

}  // namespace sss::test
