// Writes XTF side-scan files byte for byte after the public layout (see xtf_format.hpp), so the
// reader is tested against bytes laid out from the specification; also makes the fuzz seeds.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "drivers/xtf/xtf_format.hpp"

namespace sss::xtf {

struct XtfWriterChannel {
  uint8_t type_of_channel = kChannelPort;  // XtfChannelType
  uint16_t bytes_per_sample = 2;           // 1 or 2 (unsigned), or 4 (u32)
  uint16_t uni_polar = 1;
  uint8_t sample_format = 0;               // 0 legacy (from bytes_per_sample)
  float frequency = 100.0f;                // as stored (kHz, like Isis)
  std::string name = "Port";
};

struct XtfWriterOptions {
  std::vector<XtfWriterChannel> channels;  // CHANINFO order; more than 6 grow the header
  uint16_t nav_units = kNavUnitsLatLon;
  std::string recording_program = "sss-slam";
  std::string sonar_name = "simulated";
  uint16_t sonar_type = 0;  // SonarType (byte 34); EdgeTech types use each channel's Weight
};

// One channel of one ping as stored: samples are rounded and clamped to the channel's sample size.
struct XtfChannelData {
  uint16_t channel_number = 0;  // CHANINFO index
  float slant_range_m = 50.0f;
  float time_delay_s = 0.0f;
  float time_duration_s = 0.0f;  // 0: written as slant range / (SoundVelocity as stored)
  int16_t weight = 0;            // Weight (byte 58): samples stand for sample x 2^-weight (sonarTypeUsesWeight)
  std::vector<float> samples;
};

// A DriverPing-like ping as the writer stores it: the ping header fields in XTF units.
struct XtfPingInput {
  uint32_t ping_number = 0;
  int64_t ping_time_us = 0;      // UTC; written to the 1/100 s
  float sound_velocity = 750.0f; // as stored: Isis writes half the speed of sound
  double sensor_y = 0.0;         // latitude deg (nav units 3) or northing m
  double sensor_x = 0.0;         // longitude deg or easting m
  float depth_m = 0.0f;
  float altitude_m = 0.0f;
  float pitch_deg = 0.0f;        // XTF: nose up positive
  float roll_deg = 0.0f;         // XTF: starboard down positive
  float heading_deg = 0.0f;      // clockwise from north
  double ship_y = 0.0;           // ShipY/Xcoordinate: the vessel's position (0: unset)
  double ship_x = 0.0;
  float layback_m = 0.0f;        // Layback: a towfish's distance behind the ship (0: none)
  std::vector<XtfChannelData> channels;
};

// The file header block(s): 1024 bytes, or a multiple when there are more than 6 channels.
std::vector<uint8_t> encodeFileHeader(const XtfWriterOptions& options);
// One sonar packet (header type 0): ping header, then per channel a channel header and samples.
std::vector<uint8_t> encodeSonarPacket(const XtfWriterOptions& options, const XtfPingInput& ping);
// Writes the ping header's navigation in place (packet = the packet start): SensorY/X, depth,
// pitch, roll, heading; nothing else (the altitude is the sonar's own measurement).
void encodePingNavigation(const XtfPingInput& ping, uint8_t* packet);
// Writes the ping header's Layback in place.
void encodePingLayback(float layback_m, uint8_t* packet);
// A packet of another type (notes, attitude, ...) of total_bytes zero-filled bytes (>= 14).
std::vector<uint8_t> encodeOtherPacket(uint8_t header_type, size_t total_bytes);

class XtfWriter {
 public:
  XtfWriter(const std::string& path, XtfWriterOptions options);
  bool isOpen() const { return file_ != nullptr; }
  bool write(const XtfPingInput& ping);
  bool writeBytes(const std::vector<uint8_t>& bytes);

 private:
  struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  XtfWriterOptions options_;
  std::unique_ptr<std::FILE, FileCloser> file_;
};

}  // namespace sss::xtf
