// Hand-built JSF records and streams for the edgetech tests.
#pragma once

#include <cmath>
#include <vector>

#include "drivers/edgetech/jsf_format.hpp"

namespace sss::test {

inline sonar::SonarChannelRecord makeRecord(uint32_t ping_number, uint8_t channel) {
  sonar::SonarChannelRecord r;
  r.subsystem = sonar::kSubsystemSideScanLow;
  r.channel = channel;
  r.ping_time_us = 1780300800123000LL + static_cast<int64_t>(ping_number) * 250000;  // 2026-06-01T08:00:00.123Z
  r.ping_number = ping_number;
  r.start_depth_samples = 0;
  r.sample_interval_s = 20e-6;
  r.sound_speed_m_s = 1500.0f;
  r.start_frequency_hz = 390000.0f;
  r.end_frequency_hz = 420000.0f;
  r.validity = sonar::kValidLatLon | sonar::kValidHeading | sonar::kValidPitchRoll | sonar::kValidAltitude |
               sonar::kValidDepth;
  r.latitude_deg = 59.351234;
  r.longitude_deg = 18.071234;
  r.depth_m = 42.125;
  r.altitude_m = 18.25;
  r.heading_rad = 1.2345;
  r.pitch_rad = 0.02;
  r.roll_rad = -0.03;
  return r;
}

inline std::vector<float> makeMagnitudes(size_t count, uint32_t seed) {
  std::vector<float> magnitudes(count);
  for (size_t i = 0; i < count; ++i) magnitudes[i] = 100.0f + 50.0f * std::sin(0.01f * static_cast<float>(i + seed));
  return magnitudes;
}

inline std::vector<uint8_t> encodeRecord(sonar::SonarChannelRecord record, size_t samples) {
  const std::vector<uint16_t> codes = edgetech::quantiseEnvelope(makeMagnitudes(samples, record.ping_number), record.weighting_factor);
  return edgetech::encodeSonarData(record, codes);
}

// A stream of pings (port and starboard each) with sample counts varying per ping.
inline std::vector<std::vector<uint8_t>> makeMessages(int pings, size_t samples = 500) {
  std::vector<std::vector<uint8_t>> messages;
  for (int p = 0; p < pings; ++p) {
    for (uint8_t channel : {sonar::kChannelPort, sonar::kChannelStarboard}) {
      messages.push_back(encodeRecord(makeRecord(static_cast<uint32_t>(1000 + p), channel), samples + static_cast<size_t>(p)));
    }
  }
  return messages;
}

inline std::vector<uint8_t> concatenate(const std::vector<std::vector<uint8_t>>& parts) {
  std::vector<uint8_t> all;
  for (const auto& part : parts) all.insert(all.end(), part.begin(), part.end());
  return all;
}

}  // namespace sss::test
