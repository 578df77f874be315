// EdgeTech JSF: the 16-byte message header and type 80 sonar data (one channel of one ping; the
// older side-scan message 82 as well), decoded into plain records and encoded back to the exact
// wire bytes. Little-endian throughout.
// Layout from EdgeTech's public JSF description (0023492) as collected in
// shared/reference/sonar-formats.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drivers/sonar/sonar_ping.hpp"
#include "pipeline/core/status.hpp"

namespace sss::edgetech {

// Type 80 messages decode into the ping every sonar reader hands on (drivers/sonar/sonar_ping.hpp):
// one SonarChannelRecord per message, its subsystem, channel and validity bits JSF's own.
using sss::sonar::kChannelPort;
using sss::sonar::kChannelStarboard;
using sss::sonar::kSubsystemSideScanHigh;
using sss::sonar::kSubsystemSideScanLow;
using sss::sonar::kValidAltitude;
using sss::sonar::kValidCourse;
using sss::sonar::kValidDepth;
using sss::sonar::kValidHeading;
using sss::sonar::kValidLatLon;
using sss::sonar::kValidPitchRoll;
using sss::sonar::kValidPressure;
using sss::sonar::kValidSoundSpeed;
using sss::sonar::kValidSpeed;
using sss::sonar::SonarChannelRecord;

constexpr uint16_t kJsfStartMarker = 0x1601;
constexpr size_t kJsfHeaderSize = 16;
constexpr size_t kSonarDataHeaderSize = 240;
// Message 82, the side-scan data message of older EdgeTech systems: an 80-byte header, then the
// samples as in type 80.
constexpr size_t kOldSideScanHeaderSize = 80;
// No 2205 message comes near this: 2 channels are separate messages, 65535 samples of I/Q are
// 256 KiB. A larger byte count is corrupt and must not make us allocate.
constexpr int32_t kMaxJsfBodyBytes = 4 * 1024 * 1024;

enum JsfMessageType : uint16_t {
  kJsfSonarData = 80,
  kJsfOldSideScanData = 82,
  kJsfNmea = 2002,
  kJsfPitchRoll = 2020,
  kJsfPressure = 2060,
  kJsfDvl = 2080,
  kJsfSituation = 2090,
  kJsfSituation2 = 2091,
};

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

// Writes the layback (228, f32 m) of a type 80 body's header in place.
void encodeSonarLayback(float layback_m, uint8_t* body);

// Header from 16 bytes; nullopt when the start marker is wrong.
std::optional<JsfMessageHeader> decodeHeader(const uint8_t* bytes);
void encodeHeader(const JsfMessageHeader& header, uint8_t* bytes);

// On the wire a type 80 header stores the ping time as seconds (offset 0) + milliseconds (200),
// the sample interval in ns (116), frequencies in 10 Hz, the position in minutes of arc x 10000
// (coordinate units 2) or mm (1), depth and altitude in mm, heading in 0.01 degree, pitch and roll
// in 180/32768 degree; SonarChannelRecord holds them in plain units. The layback (228, f32 m, kept
// when within (0, 10 km]) goes to layback_m as recorded.
// Decodes a type 80 body (everything after the 16-byte header). Fails with the reason when the
// body is too short for its header or its samples, or the data format is unknown.
sss::core::Result<SonarChannelRecord> decodeSonarData(const JsfMessageHeader& header, const uint8_t* body,
                                                      size_t body_size);

// Message 82 (older side-scan systems), header laid out as MB-System's mbsys_jstar.h reads it
// (EdgeTech's public description of the older protocol): 0 subsystem u16  2 channel u16  4 ping
// number u32  8 packet number u16  10 trigger source u16  12 samples u32  16 sample interval ns u32
// 20 start depth (window offset) in samples u32  24 weighting factor i16 (samples x 2^-N)  26 ADC
// gain  28 ADC max  30 range setting (m x 10)  32 pulse id  34 mark number  36 data format u16 (0
// envelope, 1 I/Q)  38 reserved  40 milliseconds today u32  44 year i16  46 day of the year u16
// 48 hour  50 minute  52 second  54 heading i16 (minutes of arc)  56 pitch i16 (minutes, bow up +)
// 58 roll i16 (minutes, port up +)  60 heave i16 cm  62 yaw i16 minutes  64 vehicle depth u32 cm
// 68 temperature  70-79 reserved. No position, altitude, sound speed or frequency: the position
// comes from the file's NMEA (2002) or situation (2090/2091) messages, the altitude from the bottom
// track. A heading of exactly 0 is taken as none (no validity flags), as in XTF.
sss::core::Result<SonarChannelRecord> decodeOldSideScanData(const JsfMessageHeader& header, const uint8_t* body,
                                                            size_t body_size);
// The exact wire bytes of one message 82 (envelope format) from u16 codes, for tests and the
// emulators: time, ping number, sample interval, start depth, weighting factor, heading, pitch, roll
// (rounded to minutes of arc) and depth (to cm) from the record.
std::vector<uint8_t> encodeOldSideScanData(const SonarChannelRecord& record, const std::vector<uint16_t>& envelope_codes,
                                           uint8_t sequence = 0);

}  // namespace sss::edgetech
