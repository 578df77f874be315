// EdgeTech JSF: the 16-byte message header and type 80 sonar data (one channel of one ping),
// decoded into plain records and encoded back to the exact wire bytes. Little-endian throughout.
// Layout from EdgeTech's public JSF description (0023492) as collected in
// shared/reference/sonar-formats.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/status.hpp"

namespace sss::edgetech {

constexpr uint16_t kJsfStartMarker = 0x1601;
constexpr size_t kJsfHeaderSize = 16;
constexpr size_t kSonarDataHeaderSize = 240;
// No 2205 message comes near this: 2 channels are separate messages, 65535 samples of I/Q are
// 256 KiB. A larger byte count is corrupt and must not make us allocate.
constexpr int32_t kMaxJsfBodyBytes = 4 * 1024 * 1024;

enum JsfMessageType : uint16_t {
  kJsfSonarData = 80,
  kJsfNmea = 2002,
  kJsfPitchRoll = 2020,
  kJsfPressure = 2060,
  kJsfDvl = 2080,
  kJsfSituation = 2090,
  kJsfSituation2 = 2091,
};

// Side-scan subsystems and channels.
constexpr uint8_t kSubsystemSideScanLow = 20;
constexpr uint8_t kSubsystemSideScanHigh = 21;
constexpr uint8_t kChannelPort = 0;
constexpr uint8_t kChannelStarboard = 1;

struct JsfMessageHeader {
  uint8_t protocol_version = 0x0D;
  uint8_t session_id = 0;
  uint16_t message_type = kJsfSonarData;
  uint8_t command_type = 2;  // normal data
  uint8_t subsystem = kSubsystemSideScanLow;
  uint8_t channel = kChannelPort;
  uint8_t sequence = 0;
  int32_t byte_count = 0;  // body bytes after the header
};

// Validity bits of the sonar data header (offset 30).
constexpr uint16_t kValidLatLon = 1u << 0;
constexpr uint16_t kValidCourse = 1u << 1;
constexpr uint16_t kValidSpeed = 1u << 2;
constexpr uint16_t kValidHeading = 1u << 3;
constexpr uint16_t kValidPressure = 1u << 4;
constexpr uint16_t kValidPitchRoll = 1u << 5;
constexpr uint16_t kValidAltitude = 1u << 6;
constexpr uint16_t kValidDepth = 1u << 9;
constexpr uint16_t kValidSoundSpeed = 1u << 14;

// One type 80 message: one channel (port or starboard) of one ping.
struct SonarChannelRecord {
  uint8_t subsystem = kSubsystemSideScanLow;
  uint8_t channel = kChannelPort;
  int64_t ping_time_us = 0;        // seconds (offset 0) + milliseconds (offset 200), sonar clock
  uint32_t ping_number = 0;
  uint32_t start_depth_samples = 0;  // window offset: sample 0 is at this many samples of range
  double sample_interval_s = 0.0;  // stored in ns (offset 116)
  float sound_speed_m_s = 1500.0f;
  float start_frequency_hz = 0.0f;  // stored in units of 10 Hz
  float end_frequency_hz = 0.0f;
  uint16_t data_format = 0;        // 0 envelope u16, 1 analytic I/Q (2 x i16)
  int16_t weighting_factor = 0;    // samples are scaled by 2^-N
  uint16_t validity = 0;           // kValid* bits
  double latitude_deg = 0.0;       // stored as minutes of arc x 10000 (coordinate units 2)
  double longitude_deg = 0.0;
  // A position in projected metres instead (XTF NavUnits 0: the file's grid, its CRS not
  // recorded); JSF never sets it.
  bool projected_position = false;
  double easting_m = 0.0;
  double northing_m = 0.0;
  double depth_m = 0.0;            // stored in mm
  double altitude_m = 0.0;         // stored in mm
  double heading_rad = 0.0;        // stored in 0.01 degree, [0, 360)
  double pitch_rad = 0.0;          // bow up positive, stored x 180/32768 degree
  double roll_rad = 0.0;           // port up positive
  std::vector<float> samples;      // envelope magnitude, 2^-N applied (I/Q: sqrt(I^2 + Q^2))

  // Slant range of sample i: (start_depth_samples + i) * sample_interval_s * c / 2.
  double slantRangeM(size_t sample_index) const;
};

// Quantises magnitudes to the u16 envelope codes a sonar would send, choosing the weighting
// factor N so the largest sample fits (sample = code * 2^-N). Sets record.weighting_factor.
std::vector<uint16_t> quantiseEnvelope(const std::vector<float>& magnitudes, int16_t& weighting_factor);

// The exact wire bytes of one type 80 message (16-byte header + 240-byte header + samples),
// envelope format, from u16 codes. record.samples is ignored; record.weighting_factor is used.
std::vector<uint8_t> encodeSonarData(const SonarChannelRecord& record, const std::vector<uint16_t>& envelope_codes,
                                     uint8_t sequence = 0);

// Writes the navigation fields of a type 80 body's 240-byte header in place: validity (30),
// position (80, 84; coordinate units 88: 2 = minutes x 10000, or 1 = mm when projected_position),
// depth (136), heading (172), pitch (174), roll (176). Nothing else is touched.
void encodeSonarNavigation(const SonarChannelRecord& record, uint8_t* body);

// Header from 16 bytes; nullopt when the start marker is wrong.
std::optional<JsfMessageHeader> decodeHeader(const uint8_t* bytes);
void encodeHeader(const JsfMessageHeader& header, uint8_t* bytes);

// Decodes a type 80 body (everything after the 16-byte header). Fails with the reason when the
// body is too short for its header or its samples, or the data format is unknown.
sss::core::Result<SonarChannelRecord> decodeSonarData(const JsfMessageHeader& header, const uint8_t* body,
                                                      size_t body_size);

}  // namespace sss::edgetech
