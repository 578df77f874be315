// A side-scan ping as every sonar reader hands it on, whatever the file or stream it came from:
// its port and starboard channels with the samples and the header fields (timing, the sonar's own
// navigation and attitude) decoded into plain units. The EdgeTech JSF driver (drivers/edgetech) and
// the XTF reader (drivers/xtf) both produce it, so neither includes the other; the field names and
// validity bits follow JSF's type 80 header, to which the XTF reader maps its ping header.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace sss::sonar {

// Which side-scan frequency a channel belongs to (JSF subsystem numbers; the XTF reader stamps its
// first port/starboard pair as low, the second as high).
constexpr uint8_t kSubsystemSideScanLow = 20;
constexpr uint8_t kSubsystemSideScanHigh = 21;
// Which side a channel is.
constexpr uint8_t kChannelPort = 0;
constexpr uint8_t kChannelStarboard = 1;

// Validity bits of a channel's header fields (JSF's sonar data header, offset 30).
constexpr uint16_t kValidLatLon = 1u << 0;
constexpr uint16_t kValidCourse = 1u << 1;
constexpr uint16_t kValidSpeed = 1u << 2;
constexpr uint16_t kValidHeading = 1u << 3;
constexpr uint16_t kValidPressure = 1u << 4;
constexpr uint16_t kValidPitchRoll = 1u << 5;
constexpr uint16_t kValidAltitude = 1u << 6;
constexpr uint16_t kValidDepth = 1u << 9;
constexpr uint16_t kValidSoundSpeed = 1u << 14;

// Larger laybacks are not a tow cable's (deep tows run out a few km): readers ignore them.
constexpr float kMaxLaybackM = 10000.0f;

// One channel (port or starboard) of one ping.
struct SonarChannelRecord {
  uint8_t subsystem = kSubsystemSideScanLow;
  uint8_t channel = kChannelPort;
  int64_t ping_time_us = 0;        // the sonar's clock
  uint32_t ping_number = 0;
  uint32_t start_depth_samples = 0;  // window offset: sample 0 is at this many samples of range
  double sample_interval_s = 0.0;
  float sound_speed_m_s = 1500.0f;
  float start_frequency_hz = 0.0f;
  float end_frequency_hz = 0.0f;
  uint16_t data_format = 0;        // JSF: 0 envelope u16, 1 analytic I/Q (2 x i16)
  int16_t weighting_factor = 0;    // JSF: samples are scaled by 2^-N
  uint16_t validity = 0;           // kValid* bits
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
  // A position in projected metres instead (XTF NavUnits 0: the file's grid, its CRS not
  // recorded); JSF never sets it.
  bool projected_position = false;
  double easting_m = 0.0;
  double northing_m = 0.0;
  double depth_m = 0.0;
  double altitude_m = 0.0;
  double heading_rad = 0.0;        // [0, 2 pi)
  double course_rad = 0.0;         // course over ground [0, 2 pi), with kValidCourse (JSF)
  // A towed sensor whose recorded position is the ship's: it trails that position by this many
  // metres over the ground, along its heading (XTF Layback, JSF layback with jsf_layback: apply;
  // 0: the position is the sensor's).
  double layback_m = 0.0;
  double pitch_rad = 0.0;          // bow up positive
  double roll_rad = 0.0;           // port up positive
  std::vector<float> samples;      // envelope magnitude (JSF: 2^-N applied; I/Q: sqrt(I^2 + Q^2))

  // Slant range of sample i: (start_depth_samples + i) * sample_interval_s * c / 2.
  double slantRangeM(size_t sample_index) const {
    return (static_cast<double>(start_depth_samples) + static_cast<double>(sample_index)) * sample_interval_s *
           static_cast<double>(sound_speed_m_s) * 0.5;
  }
};

// The two channels of one ping, joined by ping number; a side may be missing.
struct AssembledPing {
  uint32_t ping_number = 0;
  std::optional<SonarChannelRecord> port;
  std::optional<SonarChannelRecord> starboard;
  int64_t last_arrival_us = 0;  // monotonic arrival of the last channel (latency reference)
  bool complete() const { return port && starboard; }
  // The sonar's ping time (both sides carry the same one).
  int64_t pingTimeUs() const { return port ? port->ping_time_us : starboard->ping_time_us; }
};

// A ping as a reader hands it out, with its time in the vehicle's time base.
struct DriverPing {
  AssembledPing ping;
  int64_t utime_us = 0;     // ping time in the vehicle's time base
  int64_t sonar_utime_us = 0;
};

}  // namespace sss::sonar
