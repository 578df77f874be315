// Triton XTF (eXtended Triton Format) side-scan layout: the file header with its channel-info
// blocks, the 14-byte packet start, the 256-byte sonar ping header and 64-byte channel headers.
//
// Layout (little-endian, packed), verified against two public descriptions that agree byte for
// byte: pyxtf's pyxtf/xtf_ctypes.py (oysstu/pyxtf, ctypes structures with _pack_ = 1, notes
// from the Triton XTF format document rev. 35) and an annotated C transcription of the Triton
// document with the byte offset of every field (XTFFILEHEADER, CHANINFO, XTFPINGHEADER).
//
// File header (1024 bytes, grows by 1024-byte blocks when there are more channels):
//   0 FileFormat u8 (0x7B)   1 SystemType u8   2 RecordingProgramName[8]   10 ..Version[8]
//   18 SonarName[16]   34 SonarType u16   36 NoteString[64]   100 ThisFileName[64]
//   164 NavUnits u16 (0 = metres, projected; 3 = latitude/longitude degrees)
//   166 NumberOfSonarChannels u16 ("if > 6, header grows to 2K")   168 NumberOfBathymetryChannels u16
//   170 NumberOfSnippetChannels u8   171 NumberOfForwardLookArrays u8
//   172 NumberOfEchoStrengthChannels u16   174 NumberOfInterferometryChannels u8
//   256 + 128 i: CHANINFO i (six fit in the first 1024 bytes; further ones continue contiguously
//   in the following 1024-byte blocks)
// CHANINFO (128 bytes):
//   0 TypeOfChannel u8 (0 subbottom, 1 port, 2 starboard, 3 bathymetry)   1 SubChannelNumber u8
//   2 CorrectionFlags u16 (1 slant range, 2 ground range)   4 UniPolar u16 (0 polar, 1 unipolar)
//   6 BytesPerSample u16 (1, 2 or 4)   12 ChannelName[16]   32 Frequency f32 (centre transmit)
//   74 SampleFormat u8 (X41+: 0 legacy, 1 IBM float, 2 u32, 3 u16, 5 IEEE f32, 8 u8)
// Packet start (14 bytes, every packet):
//   0 MagicNumber u16 (0xFACE)   2 HeaderType u8 (0 = sonar: side-scan and sub-bottom)
//   3 SubChannelNumber u8   4 NumChansToFollow u16   6 Reserved u16[2]
//   10 NumBytesThisRecord u32 (whole packet including this header and any padding)
// Sonar ping header XTFPINGHEADER (256 bytes, offsets from the packet start):
//   14 Year u16  16 Month u8  17 Day u8  18 Hour u8  19 Minute u8  20 Second u8
//   21 HSeconds u8 (1/100 s)  22 JulianDay u16  24 EventNumber u32  28 PingNumber u32
//   32 SoundVelocity f32 ("m/s, Isis uses 750 (one way), some XTF files use 1500")
//   128 ShipYcoordinate f64  136 ShipXcoordinate f64 (the vessel's, same units as the sensor's)
//   160 SensorYcoordinate f64 (latitude deg, or northing m)  168 SensorXcoordinate f64 (longitude
//   deg, or easting m)  184 Layback f32 m ("distance over ground from ship to fish. When this
//   value is non-zero, Isis assumes that SensorYcoordinate and SensorXcoordinate need to be
//   adjusted with the Layback", along the sensor heading)  192 SensorDepth f32 m  196 SensorPrimaryAltitude f32 m
//   204 SensorPitch f32 deg (positive nose up)  208 SensorRoll f32 deg (positive: roll to
//   starboard, i.e. starboard down)  212 SensorHeading f32 deg (from true north, clockwise)
// Channel header XTFPINGCHANHEADER (64 bytes, one before each channel's samples):
//   0 ChannelNumber u16 (index of the CHANINFO: typically 0 port low, 1 starboard low, 2 port
//   high, 3 starboard high)  2 DownsampleMethod u16  4 SlantRange f32 m  8 GroundRange f32 m
//   12 TimeDelay f32 s (ping to first sample)  16 TimeDuration f32 s ("range / 750 (one way)", so
//   two-way travel time)  20 SecondsPerPing f32  24 ProcessingFlags u16  26 Frequency u16
//   42 NumSamples u32 (0 in old files: the count was CHANINFO.Reserved at byte 8)
//   58 Weight i16 ("weighting factor passed by some sonars, this value is mandatory for Edgetech
//   digital sonars types 24, 35, 38, 48 and Kongsberg SA type 48": the samples are scaled by
//   2^-Weight, as JSF's weighting factor)
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drivers/sonar/sonar_ping.hpp"
#include "pipeline/core/status.hpp"

namespace sss::xtf {

constexpr uint8_t kXtfFileFormat = 0x7B;
constexpr uint16_t kXtfMagic = 0xFACE;
constexpr size_t kFileHeaderBlockBytes = 1024;
constexpr size_t kChannelInfoOffset = 256;
constexpr size_t kChannelInfoBytes = 128;
constexpr size_t kPacketStartBytes = 14;
constexpr size_t kPingHeaderBytes = 256;  // includes the packet start
constexpr size_t kPingChannelHeaderBytes = 64;
// More channels than any real sonar carries; a header claiming more is corrupt.
constexpr size_t kMaxChannels = 64;

enum XtfNavUnits : uint16_t { kNavUnitsMetres = 0, kNavUnitsLatLon = 3 };
enum XtfChannelType : uint8_t { kChannelSubbottom = 0, kChannelPort = 1, kChannelStarboard = 2, kChannelBathymetry = 3 };
enum XtfHeaderType : uint8_t {
  kHeaderSonar = 0,
  kHeaderAttitude = 3,           // XTFATTITUDEDATA: pitch, roll, heave, yaw, heading
  kHeaderNavigation = 42,        // XTFHEADERNAVIGATION: source-time-stamped position and altitude
  kHeaderPosRawNavigation = 107  // XTFPOSRAWNAVIGATION: position, altitude and attitude
};

// Byte offsets of the fields we use, from the packet start (ping header) or the block start.
namespace offset {
constexpr size_t kNavUnits = 164;
constexpr size_t kNumberOfSonarChannels = 166;
constexpr size_t kNumberOfBathymetryChannels = 168;
constexpr size_t kNumberOfSnippetChannels = 170;
constexpr size_t kNumberOfForwardLookArrays = 171;
constexpr size_t kNumberOfEchoStrengthChannels = 172;
constexpr size_t kNumberOfInterferometryChannels = 174;
// CHANINFO
constexpr size_t kTypeOfChannel = 0;
constexpr size_t kSubChannelNumber = 1;
constexpr size_t kCorrectionFlags = 2;
constexpr size_t kUniPolar = 4;
constexpr size_t kBytesPerSample = 6;
constexpr size_t kLegacyNumSamples = 8;
constexpr size_t kChannelName = 12;
constexpr size_t kChannelFrequency = 32;
constexpr size_t kSampleFormat = 74;
// Packet start
constexpr size_t kMagic = 0;
constexpr size_t kHeaderType = 2;
constexpr size_t kPacketSubChannel = 3;
constexpr size_t kNumChansToFollow = 4;
constexpr size_t kNumBytesThisRecord = 10;
// XTFPINGHEADER
constexpr size_t kYear = 14;
constexpr size_t kMonth = 16;
constexpr size_t kDay = 17;
constexpr size_t kHour = 18;
constexpr size_t kMinute = 19;
constexpr size_t kSecond = 20;
constexpr size_t kHSeconds = 21;
constexpr size_t kJulianDay = 22;
constexpr size_t kPingNumber = 28;
constexpr size_t kSoundVelocity = 32;
constexpr size_t kShipY = 128;
constexpr size_t kShipX = 136;
constexpr size_t kSensorY = 160;
constexpr size_t kSensorX = 168;
constexpr size_t kLayback = 184;
constexpr size_t kSensorDepth = 192;
constexpr size_t kSensorPrimaryAltitude = 196;
constexpr size_t kSensorPitch = 204;
constexpr size_t kSensorRoll = 208;
constexpr size_t kSensorHeading = 212;
// XTFPINGCHANHEADER
constexpr size_t kChannelNumber = 0;
constexpr size_t kSlantRange = 4;
constexpr size_t kTimeDelay = 12;
constexpr size_t kTimeDuration = 16;
constexpr size_t kChanFrequency = 26;
constexpr size_t kNumSamples = 42;
constexpr size_t kWeight = 58;
}  // namespace offset

enum class SampleType { kUnsigned8, kUnsigned16, kUnsigned32, kFloat32, kIbmFloat32, kUnsupported };

struct XtfChannelInfo {
  uint8_t type_of_channel = 0;  // XtfChannelType
  uint8_t sub_channel_number = 0;
  uint16_t correction_flags = 0;
  uint16_t uni_polar = 0;
  uint16_t bytes_per_sample = 0;
  uint8_t sample_format = 0;     // as stored (0 = legacy: from bytes_per_sample)
  SampleType sample_type = SampleType::kUnsupported;
  uint32_t legacy_num_samples = 0;
  float frequency = 0.0f;        // as stored (kHz in most files, Hz in some)
  std::string name;
};

struct XtfFileInfo {
  uint8_t system_type = 0;
  std::string recording_program;
  std::string sonar_name;
  uint16_t sonar_type = 0;
  uint16_t nav_units = 0;        // XtfNavUnits
  uint16_t sonar_channels = 0;   // NumberOfSonarChannels
  uint16_t bathymetry_channels = 0;
  size_t header_bytes = kFileHeaderBlockBytes;  // where the first packet is expected
  std::vector<XtfChannelInfo> channels;         // one per declared channel, in CHANINFO order
};

// Decodes the file header. size must cover the whole header (XtfFileInfo::header_bytes; call
// with 1024 bytes first: when more are needed the message says how many and requiredHeaderBytes()
// tells).
sss::core::Result<XtfFileInfo> parseFileHeader(const uint8_t* data, size_t size);
// Bytes the header occupies, from its first 1024 bytes (0 when they are not an XTF header).
size_t requiredHeaderBytes(const uint8_t* data, size_t size);

// Port and starboard CHANINFO indices of one side-scan pair.
struct ChannelPair {
  int port = -1;
  int starboard = -1;
  float frequency = 0.0f;
};
// Side-scan pairs ordered by frequency, lowest first (the k-th port with the k-th starboard,
// each side ordered by CHANINFO frequency, then index). Sub-bottom and bathymetry are ignored.
std::vector<ChannelPair> sideScanPairs(const XtfFileInfo& info);

// Centre frequency in Hz from a stored value: side-scan sonars work from ~50 kHz to ~2 MHz, so a
// value below 10000 can only be kHz (Isis writes kHz) and a larger one is already Hz.
float frequencyHz(float stored);

// The packet start; nullopt unless the magic is 0xFACE.
struct PacketHeader {
  uint8_t header_type = 0;
  uint8_t sub_channel = 0;
  uint16_t num_chans_to_follow = 0;
  uint32_t num_bytes = 0;
};
std::optional<PacketHeader> decodePacketHeader(const uint8_t* bytes);

struct SonarDecodeOptions {
  int port_channel = -1;       // CHANINFO indices to extract (from sideScanPairs)
  int starboard_channel = -1;
  uint8_t subsystem = sss::sonar::kSubsystemSideScanLow;  // stamped on the records
  float fallback_sound_speed_m_s = 1500.0f;
  bool polar_as_signed = false;  // UniPolar = 0 channels carry signed samples (magnitude taken)
  // Layback of a towfish whose SensorY/X are still the ship's: handed on in layback_m (see
  // decodeSonarPacket); false: positions as recorded, Layback ignored.
  bool apply_layback = true;
};

// SonarType values (file header, byte 34) whose channel Weight scales the samples by 2^-Weight:
// EdgeTech's digital sonars (24, 35, 38) and 48 (EdgeTech, or Kongsberg SA, by the format's note).
inline bool sonarTypeUsesWeight(uint16_t sonar_type) {
  return sonar_type == 24 || sonar_type == 35 || sonar_type == 38 || sonar_type == 48;
}

using sss::sonar::kMaxLaybackM;

struct SonarDecodeResult {
  std::optional<sss::sonar::DriverPing> ping;  // empty on error or when no chosen channel
  std::string error;
  bool no_selected_channel = false;  // valid packet without the chosen port or starboard
  bool sound_speed_fallback = false; // SoundVelocity unusable: the fallback was used
  bool ship_coordinates = false;     // SensorY/X unset: the ping has ShipY/X instead
  bool layback_to_apply = false;     // Layback set over the ship's position: handed on in layback_m
  bool layback_in_position = false;  // Layback set, SensorY/X already apart from ShipY/X: not applied again
  bool weight_applied = false;       // a chosen channel's samples scaled by 2^-Weight (sonarTypeUsesWeight)
};
// Decodes one whole sonar packet (header type 0) of `size` bytes (NumBytesThisRecord).
// Layback: Isis, the format's owner, takes a non-zero Layback to mean that SensorY/X are the ship's
// and still need moving back along the sensor heading. Writers that computed the fish's position
// themselves leave SensorY/X apart from ShipY/X; those are used as they are. So the layback is
// handed on (SonarChannelRecord::layback_m) when SensorY/X are unset (ShipY/X used), equal to
// ShipY/X, or the only position there is.
SonarDecodeResult decodeSonarPacket(const XtfFileInfo& info, const SonarDecodeOptions& options, const uint8_t* packet,
                                    size_t size);

// Navigation carried in its own packets (when the pings carry none), offsets from the packet start
// as pyxtf's xtf_ctypes.py lays them out (packed), every packet 64 bytes:
//   3 attitude:  22 EpochMicroseconds u32  26 SourceEpoch u32 (s since 1970)  30 Pitch f32 deg
//     (nose up +)  34 Roll f32 deg (starboard down +)  38 Heave f32  42 Yaw f32  46 TimeTag u32
//     50 Heading f32 deg  54 Year u16  56 Month  57 Day  58 Hour  59 Minute  60 Second
//     61 Millisecond u16
//   42 navigation:  14 Year u16  16 Month  17 Day  18 Hour  19 Minute  20 Second  21 Microsecond
//     u32  25 SourceEpoch u32  29 TimeTag u32  33 RawYcoordinate f64  41 RawXcoordinate f64
//     49 RawAltitude f64  57 TimeFlag u8
//   107 raw position:  14 Year u16  16 Month  17 Day  18 Hour  19 Minute  20 Second
//     21 MicroSecond u16 (0-9999: units of 100 us)  23 RawYcoordinate f64  31 RawXcoordinate f64
//     39 RawAltitude f64  47 Pitch f32  51 Roll f32  55 Heave f32  59 Heading f32
// Coordinates are in the file's NavUnits (degrees, or projected metres). The sonar ping header
// also has ShipY/ShipXcoordinate (f64 at 128/136): the vessel's, used when SensorY/X are unset.
struct XtfNavigationRecord {
  uint8_t header_type = 0;
  int64_t utime_us = 0;
  std::optional<double> y, x;  // latitude/longitude degrees or northing/easting metres
  std::optional<double> altitude_m;
  std::optional<double> pitch_rad, roll_rad, heading_rad;
};
// Decodes a packet of type 3, 42 or 107; nullopt when it is shorter than 64 bytes, of another
// type, or its time is impossible. Zero coordinates and angles out of range are left unset.
std::optional<XtfNavigationRecord> decodeNavigationPacket(const uint8_t* packet, size_t size);

// UTC microseconds from calendar fields; nullopt when a field is out of range.
std::optional<int64_t> utcFromCalendar(int year, int month, int day, int hour, int minute, int second,
                                       int hundredths);

// Little-endian field access (exposed for the writer and the tests).
uint16_t readU16(const uint8_t* bytes, size_t at);
uint32_t readU32(const uint8_t* bytes, size_t at);
float readF32(const uint8_t* bytes, size_t at);
double readF64(const uint8_t* bytes, size_t at);
void writeU16(uint8_t* bytes, size_t at, uint16_t value);
void writeU32(uint8_t* bytes, size_t at, uint32_t value);
void writeF32(uint8_t* bytes, size_t at, float value);
void writeF64(uint8_t* bytes, size_t at, double value);

}  // namespace sss::xtf
