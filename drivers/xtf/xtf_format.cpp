// XTF file header, packet start and sonar packet decoding, see xtf_format.hpp for the layout and
// its sources.
#include "drivers/xtf/xtf_format.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace sss::xtf {

using sss::sonar::DriverPing;
using sss::sonar::SonarChannelRecord;

namespace {

constexpr double kDegToRad = M_PI / 180.0;

std::string fixedString(const uint8_t* bytes, size_t size) {
  size_t length = 0;
  while (length < size && bytes[length] != 0) ++length;
  std::string text(reinterpret_cast<const char*>(bytes), length);
  // Names only go to logs: keep them printable whatever the file holds.
  for (char& c : text) {
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  }
  return text;
}

SampleType sampleTypeOf(uint8_t sample_format, uint16_t bytes_per_sample) {
  // SampleFormat (X41) wins when it agrees with BytesPerSample; otherwise (legacy files leave it 0)
  // the sample size decides, as unsigned integers.
  if (sample_format == 2 && bytes_per_sample == 4) return SampleType::kUnsigned32;
  if (sample_format == 3 && bytes_per_sample == 2) return SampleType::kUnsigned16;
  if (sample_format == 5 && bytes_per_sample == 4) return SampleType::kFloat32;
  if (sample_format == 1 && bytes_per_sample == 4) return SampleType::kIbmFloat32;
  if (sample_format == 8 && bytes_per_sample == 1) return SampleType::kUnsigned8;
  switch (bytes_per_sample) {
    case 1: return SampleType::kUnsigned8;
    case 2: return SampleType::kUnsigned16;
    case 4: return SampleType::kUnsigned32;
    default: return SampleType::kUnsupported;
  }
}

size_t declaredChannels(const uint8_t* data) {
  // pyxtf's channel_count(): every kind of channel has a CHANINFO block.
  return static_cast<size_t>(readU16(data, offset::kNumberOfSonarChannels)) + readU16(data, offset::kNumberOfBathymetryChannels) +
         data[offset::kNumberOfSnippetChannels] + data[offset::kNumberOfForwardLookArrays] +
         readU16(data, offset::kNumberOfEchoStrengthChannels) + data[offset::kNumberOfInterferometryChannels];
}

float ibmToFloat(uint32_t raw) {
  // IBM System/360 single: sign, 7-bit excess-64 exponent of 16, 24-bit fraction 0.f.
  const uint32_t fraction = raw & 0x00FFFFFFu;
  if (fraction == 0) return 0.0f;
  const int exponent = static_cast<int>((raw >> 24) & 0x7F) - 64;
  const double value = std::ldexp(static_cast<double>(fraction) / 16777216.0, 4 * exponent);
  return static_cast<float>((raw & 0x80000000u) ? -value : value);
}

float sampleMagnitude(const uint8_t* bytes, SampleType type, bool as_signed) {
  switch (type) {
    case SampleType::kUnsigned8:
      return as_signed ? std::fabs(static_cast<float>(static_cast<int8_t>(bytes[0]))) : static_cast<float>(bytes[0]);
    case SampleType::kUnsigned16: {
      const uint16_t v = readU16(bytes, 0);
      return as_signed ? std::fabs(static_cast<float>(static_cast<int16_t>(v))) : static_cast<float>(v);
    }
    case SampleType::kUnsigned32: {
      const uint32_t v = readU32(bytes, 0);
      return as_signed ? std::fabs(static_cast<float>(static_cast<int32_t>(v))) : static_cast<float>(v);
    }
    case SampleType::kFloat32: {
      const float v = readF32(bytes, 0);
      return std::isfinite(v) ? std::fabs(v) : 0.0f;
    }
    case SampleType::kIbmFloat32: {
      const float v = ibmToFloat(readU32(bytes, 0));
      return std::isfinite(v) ? std::fabs(v) : 0.0f;
    }
    case SampleType::kUnsupported: break;
  }
  return 0.0f;
}

}  // namespace

uint16_t readU16(const uint8_t* bytes, size_t at) {
  return static_cast<uint16_t>(bytes[at] | (bytes[at + 1] << 8));
}

uint32_t readU32(const uint8_t* bytes, size_t at) {
  return static_cast<uint32_t>(bytes[at]) | (static_cast<uint32_t>(bytes[at + 1]) << 8) |
         (static_cast<uint32_t>(bytes[at + 2]) << 16) | (static_cast<uint32_t>(bytes[at + 3]) << 24);
}

float readF32(const uint8_t* bytes, size_t at) {
  const uint32_t raw = readU32(bytes, at);
  float value;
  std::memcpy(&value, &raw, sizeof(value));
  return value;
}

double readF64(const uint8_t* bytes, size_t at) {
  const uint64_t raw = static_cast<uint64_t>(readU32(bytes, at)) | (static_cast<uint64_t>(readU32(bytes, at + 4)) << 32);
  double value;
  std::memcpy(&value, &raw, sizeof(value));
  return value;
}

void writeU16(uint8_t* bytes, size_t at, uint16_t value) {
  bytes[at] = static_cast<uint8_t>(value);
  bytes[at + 1] = static_cast<uint8_t>(value >> 8);
}

void writeU32(uint8_t* bytes, size_t at, uint32_t value) {
  for (size_t i = 0; i < 4; ++i) bytes[at + i] = static_cast<uint8_t>(value >> (8 * i));
}

void writeF32(uint8_t* bytes, size_t at, float value) {
  uint32_t raw;
  std::memcpy(&raw, &value, sizeof(raw));
  writeU32(bytes, at, raw);
}

void writeF64(uint8_t* bytes, size_t at, double value) {
  uint64_t raw;
  std::memcpy(&raw, &value, sizeof(raw));
  writeU32(bytes, at, static_cast<uint32_t>(raw));
  writeU32(bytes, at + 4, static_cast<uint32_t>(raw >> 32));
}

size_t requiredHeaderBytes(const uint8_t* data, size_t size) {
  if (size < kFileHeaderBlockBytes || data[0] != kXtfFileFormat) return 0;
  const size_t channels = declaredChannels(data);
  const size_t end = kChannelInfoOffset + kChannelInfoBytes * channels;
  return std::max(kFileHeaderBlockBytes, (end + kFileHeaderBlockBytes - 1) / kFileHeaderBlockBytes * kFileHeaderBlockBytes);
}

sss::core::Result<XtfFileInfo> parseFileHeader(const uint8_t* data, size_t size) {
  using sss::core::Status;
  XtfFileInfo info;
  if (size < kFileHeaderBlockBytes) {
    return Status::error("XTF file header: " + std::to_string(size) + " bytes, a header needs 1024; not an XTF file");
  }
  if (data[0] != kXtfFileFormat) {
    return Status::error("XTF file header: FileFormat byte is " + std::to_string(data[0]) +
                         ", expected 123 (0x7B); not an XTF file");
  }
  const size_t channels = declaredChannels(data);
  if (channels > kMaxChannels) {
    return Status::error("XTF file header declares " + std::to_string(channels) + " channels (limit " +
                         std::to_string(kMaxChannels) + "); the header is corrupt");
  }
  info.header_bytes = requiredHeaderBytes(data, size);
  if (size < info.header_bytes) {
    return Status::error("XTF file header with " + std::to_string(channels) + " channels needs " +
                         std::to_string(info.header_bytes) + " bytes, have " + std::to_string(size));
  }
  info.system_type = data[1];
  info.recording_program = fixedString(data + 2, 8);
  info.sonar_name = fixedString(data + 18, 16);
  info.sonar_type = readU16(data, 34);
  info.nav_units = readU16(data, offset::kNavUnits);
  info.sonar_channels = readU16(data, offset::kNumberOfSonarChannels);
  info.bathymetry_channels = readU16(data, offset::kNumberOfBathymetryChannels);
  info.channels.resize(channels);
  for (size_t i = 0; i < channels; ++i) {
    const uint8_t* block = data + kChannelInfoOffset + kChannelInfoBytes * i;
    XtfChannelInfo& c = info.channels[i];
    c.type_of_channel = block[offset::kTypeOfChannel];
    c.sub_channel_number = block[offset::kSubChannelNumber];
    c.correction_flags = readU16(block, offset::kCorrectionFlags);
    c.uni_polar = readU16(block, offset::kUniPolar);
    c.bytes_per_sample = readU16(block, offset::kBytesPerSample);
    c.legacy_num_samples = readU32(block, offset::kLegacyNumSamples);
    c.name = fixedString(block + offset::kChannelName, 16);
    c.frequency = readF32(block, offset::kChannelFrequency);
    c.sample_format = block[offset::kSampleFormat];
    c.sample_type = sampleTypeOf(c.sample_format, c.bytes_per_sample);
  }
  return info;
}

float frequencyHz(float stored) {
  if (!std::isfinite(stored) || stored <= 0.0f) return 0.0f;
  return stored < 10000.0f ? stored * 1000.0f : stored;
}

std::vector<ChannelPair> sideScanPairs(const XtfFileInfo& info) {
  std::vector<int> port;
  std::vector<int> starboard;
  for (size_t i = 0; i < info.channels.size(); ++i) {
    if (info.channels[i].type_of_channel == kChannelPort) port.push_back(static_cast<int>(i));
    if (info.channels[i].type_of_channel == kChannelStarboard) starboard.push_back(static_cast<int>(i));
  }
  const auto by_frequency = [&info](int a, int b) {
    const float fa = frequencyHz(info.channels[static_cast<size_t>(a)].frequency);
    const float fb = frequencyHz(info.channels[static_cast<size_t>(b)].frequency);
    return fa != fb ? fa < fb : a < b;
  };
  std::stable_sort(port.begin(), port.end(), by_frequency);
  std::stable_sort(starboard.begin(), starboard.end(), by_frequency);
  std::vector<ChannelPair> pairs;
  for (size_t k = 0; k < std::max(port.size(), starboard.size()); ++k) {
    ChannelPair pair;
    if (k < port.size()) pair.port = port[k];
    if (k < starboard.size()) pair.starboard = starboard[k];
    pair.frequency = info.channels[static_cast<size_t>(pair.port >= 0 ? pair.port : pair.starboard)].frequency;
    pairs.push_back(pair);
  }
  return pairs;
}

std::optional<PacketHeader> decodePacketHeader(const uint8_t* bytes) {
  if (readU16(bytes, offset::kMagic) != kXtfMagic) return std::nullopt;
  PacketHeader header;
  header.header_type = bytes[offset::kHeaderType];
  header.sub_channel = bytes[offset::kPacketSubChannel];
  header.num_chans_to_follow = readU16(bytes, offset::kNumChansToFollow);
  header.num_bytes = readU32(bytes, offset::kNumBytesThisRecord);
  return header;
}

std::optional<XtfNavigationRecord> decodeNavigationPacket(const uint8_t* p, size_t size) {
  constexpr size_t kNavigationPacketBytes = 64;
  if (size < kNavigationPacketBytes || readU16(p, 0) != kXtfMagic) return std::nullopt;
  XtfNavigationRecord r;
  r.header_type = p[2];
  auto angle = [](float degrees, float limit) -> std::optional<double> {
    if (!std::isfinite(degrees) || std::fabs(degrees) > limit) return std::nullopt;
    return static_cast<double>(degrees) * kDegToRad;
  };
  auto heading = [](float degrees) -> std::optional<double> {
    if (!std::isfinite(degrees) || std::fabs(degrees) > 720.0f) return std::nullopt;
    double wrapped = std::fmod(static_cast<double>(degrees), 360.0);
    if (wrapped < 0.0) wrapped += 360.0;
    return wrapped * kDegToRad;
  };
  auto position = [&](size_t y_at, size_t x_at, size_t altitude_at) {
    const double y = readF64(p, y_at), x = readF64(p, x_at), altitude = readF64(p, altitude_at);
    if (std::isfinite(y) && std::isfinite(x) && !(y == 0.0 && x == 0.0) && std::fabs(y) < 1e8 && std::fabs(x) < 1e8) {
      r.y = y;
      r.x = x;
    }
    if (std::isfinite(altitude) && altitude > 0.0 && altitude < 1e4) r.altitude_m = altitude;
  };
  std::optional<int64_t> seconds_us;
  int64_t sub_second_us = 0;
  switch (r.header_type) {
    case kHeaderAttitude: {
      const uint32_t epoch_s = readU32(p, 26);
      if (epoch_s > 0) {
        seconds_us = static_cast<int64_t>(epoch_s) * 1000000;
        sub_second_us = std::min<uint32_t>(readU32(p, 22), 999999);
      } else {
        seconds_us = utcFromCalendar(readU16(p, 54), p[56], p[57], p[58], p[59], p[60], 0);
        sub_second_us = 1000 * std::min<uint16_t>(readU16(p, 61), 999);
      }
      r.pitch_rad = angle(readF32(p, 30), 90.0f);
      r.roll_rad = angle(readF32(p, 34), 180.0f);
      r.heading_rad = heading(readF32(p, 50));
      break;
    }
    case kHeaderNavigation:
      seconds_us = utcFromCalendar(readU16(p, 14), p[16], p[17], p[18], p[19], p[20], 0);
      sub_second_us = std::min<uint32_t>(readU32(p, 21), 999999);
      position(33, 41, 49);
      break;
    case kHeaderPosRawNavigation:
      seconds_us = utcFromCalendar(readU16(p, 14), p[16], p[17], p[18], p[19], p[20], 0);
      sub_second_us = 100 * std::min<uint16_t>(readU16(p, 21), 9999);
      position(23, 31, 39);
      r.pitch_rad = angle(readF32(p, 47), 90.0f);
      r.roll_rad = angle(readF32(p, 51), 180.0f);
      r.heading_rad = heading(readF32(p, 59));
      break;
    default:
      return std::nullopt;
  }
  if (!seconds_us) return std::nullopt;
  r.utime_us = *seconds_us + sub_second_us;
  return r;
}

std::optional<int64_t> utcFromCalendar(int year, int month, int day, int hour, int minute, int second,
                                       int hundredths) {
  if (year < 1970 || year > 2200 || month < 1 || month > 12 || day < 1 || hour > 23 || minute > 59 || second > 60 ||
      hundredths > 99 || hour < 0 || minute < 0 || second < 0 || hundredths < 0) {
    return std::nullopt;
  }
  static constexpr int kDaysInMonth[12] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (day > kDaysInMonth[month - 1]) return std::nullopt;
  // Days from civil (proleptic Gregorian), H. Hinnant's algorithm.
  const int y = year - (month <= 2 ? 1 : 0);
  const int era = y / 400;
  const int yoe = y - era * 400;
  const int mp = (month + 9) % 12;
  const int doy = (153 * mp + 2) / 5 + day - 1;
  const int doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  const int64_t days = static_cast<int64_t>(era) * 146097 + doe - 719468;
  const int64_t seconds = days * 86400 + hour * 3600 + minute * 60 + second;
  return seconds * 1000000 + static_cast<int64_t>(hundredths) * 10000;
}

SonarDecodeResult decodeSonarPacket(const XtfFileInfo& info, const SonarDecodeOptions& options, const uint8_t* p,
                                    size_t size) {
  SonarDecodeResult result;
  if (size < kPingHeaderBytes) {
    result.error = "sonar packet of " + std::to_string(size) + " bytes is shorter than its 256-byte ping header";
    return result;
  }
  const std::optional<int64_t> ping_time_us =
      utcFromCalendar(readU16(p, offset::kYear), p[offset::kMonth], p[offset::kDay], p[offset::kHour], p[offset::kMinute],
                      p[offset::kSecond], p[offset::kHSeconds]);
  if (!ping_time_us) {
    result.error = "sonar ping " + std::to_string(readU32(p, offset::kPingNumber)) + ": impossible date/time " +
                   std::to_string(readU16(p, offset::kYear)) + "-" + std::to_string(p[offset::kMonth]) + "-" +
                   std::to_string(p[offset::kDay]) + " " + std::to_string(p[offset::kHour]) + ":" +
                   std::to_string(p[offset::kMinute]) + ":" + std::to_string(p[offset::kSecond]) + "." +
                   std::to_string(p[offset::kHSeconds]);
    return result;
  }

  // Common to both sides: time, sound speed, navigation and attitude from the ping header.
  SonarChannelRecord common;
  common.subsystem = options.subsystem;
  common.ping_time_us = *ping_time_us;
  common.ping_number = readU32(p, offset::kPingNumber);
  // SoundVelocity: Triton's document says "Isis uses 750 (one way), some XTF files use 1500": the
  // field is either half the speed of sound (so range = time x 750) or the speed itself. Our
  // records carry the true speed (slantRangeM uses c/2), so 600-900 is doubled, 1300-1700 kept.
  const float stored_speed = readF32(p, offset::kSoundVelocity);
  if (stored_speed >= 600.0f && stored_speed <= 900.0f) {
    common.sound_speed_m_s = 2.0f * stored_speed;
    common.validity |= sss::sonar::kValidSoundSpeed;
  } else if (stored_speed >= 1300.0f && stored_speed <= 1700.0f) {
    common.sound_speed_m_s = stored_speed;
    common.validity |= sss::sonar::kValidSoundSpeed;
  } else {
    common.sound_speed_m_s = options.fallback_sound_speed_m_s;
    result.sound_speed_fallback = true;
  }
  double sensor_y = readF64(p, offset::kSensorY);
  double sensor_x = readF64(p, offset::kSensorX);
  const double ship_y = readF64(p, offset::kShipY);
  const double ship_x = readF64(p, offset::kShipX);
  // SensorY/X that are the ship's own (a writer copying the GPS without applying the layback).
  const bool sensor_is_ship = sensor_y == ship_y && sensor_x == ship_x;
  const bool ship_unset = ship_y == 0.0 && ship_x == 0.0;
  if (sensor_y == 0.0 && sensor_x == 0.0) {
    // No sensor position: the vessel's (a hull-mounted sonar, or a tow without layback).
    sensor_y = readF64(p, offset::kShipY);
    sensor_x = readF64(p, offset::kShipX);
    if (std::isfinite(sensor_y) && std::isfinite(sensor_x) && !(sensor_y == 0.0 && sensor_x == 0.0)) {
      result.ship_coordinates = true;
    }
  }
  // Geographic coordinates (NavUnits 3) or projected metres (NavUnits 0, kept as easting and
  // northing without kValidLatLon). XTF has no validity flags: 0/0 is how writers leave it unset.
  if (info.nav_units == kNavUnitsLatLon && std::isfinite(sensor_y) && std::isfinite(sensor_x) &&
      std::fabs(sensor_y) <= 90.0 && std::fabs(sensor_x) <= 180.0 && !(sensor_y == 0.0 && sensor_x == 0.0)) {
    common.latitude_deg = sensor_y;
    common.longitude_deg = sensor_x;
    common.validity |= sss::sonar::kValidLatLon;
  } else if (info.nav_units == kNavUnitsMetres && std::isfinite(sensor_y) && std::isfinite(sensor_x) &&
             !(sensor_y == 0.0 && sensor_x == 0.0) && std::fabs(sensor_y) < 1e8 && std::fabs(sensor_x) < 1e8) {
    common.projected_position = true;
    common.northing_m = sensor_y;
    common.easting_m = sensor_x;
  }
  const float layback_m = readF32(p, offset::kLayback);
  if (std::isfinite(layback_m) && layback_m > 0.0f && layback_m <= kMaxLaybackM &&
      (common.validity & sss::sonar::kValidLatLon || common.projected_position)) {
    if (result.ship_coordinates || sensor_is_ship || ship_unset) {
      result.layback_to_apply = options.apply_layback;
      if (options.apply_layback) common.layback_m = layback_m;
    } else {
      result.layback_in_position = true;
    }
  }
  const float depth_m = readF32(p, offset::kSensorDepth);
  if (std::isfinite(depth_m)) {
    common.depth_m = depth_m;
    common.validity |= sss::sonar::kValidDepth;
  }
  const float altitude_m = readF32(p, offset::kSensorPrimaryAltitude);
  if (std::isfinite(altitude_m) && altitude_m > 0.0f) {  // 0 is "no altitude" in practice
    common.altitude_m = altitude_m;
    common.validity |= sss::sonar::kValidAltitude;
  }
  // XTF: pitch positive nose up, roll positive to starboard (starboard down), heading degrees
  // clockwise from north: the same senses as ours, only units change.
  const float pitch_deg = readF32(p, offset::kSensorPitch);
  const float roll_deg = readF32(p, offset::kSensorRoll);
  if (std::isfinite(pitch_deg) && std::isfinite(roll_deg) && std::fabs(pitch_deg) <= 180.0f &&
      std::fabs(roll_deg) <= 180.0f) {
    common.pitch_rad = pitch_deg * kDegToRad;
    common.roll_rad = roll_deg * kDegToRad;
    common.validity |= sss::sonar::kValidPitchRoll;
  }
  // XTF has no validity flags: a towfish without a compass writes 0 in every ping. Exactly 0 is
  // taken as no heading (the course over ground stands in, offline_inputs.hpp); a compass reading
  // north to the last bit loses only the crab angle by it.
  const float heading_deg = readF32(p, offset::kSensorHeading);
  if (std::isfinite(heading_deg) && std::fabs(heading_deg) <= 720.0f && heading_deg != 0.0f) {
    double wrapped = std::fmod(static_cast<double>(heading_deg), 360.0);
    if (wrapped < 0.0) wrapped += 360.0;
    common.heading_rad = wrapped * kDegToRad;
    common.validity |= sss::sonar::kValidHeading;
  }

  DriverPing out;
  out.ping.ping_number = common.ping_number;
  out.utime_us = common.ping_time_us;
  out.sonar_utime_us = common.ping_time_us;

  const size_t channels = readU16(p, offset::kNumChansToFollow);
  size_t at = kPingHeaderBytes;
  for (size_t i = 0; i < channels; ++i) {
    if (size - at < kPingChannelHeaderBytes) {
      result.error = "sonar ping " + std::to_string(common.ping_number) + ": channel " + std::to_string(i) + " of " +
                     std::to_string(channels) + " starts beyond the " + std::to_string(size) + "-byte record";
      return result;
    }
    const uint8_t* header = p + at;
    // ChannelNumber indexes the CHANINFO; files that leave it out of range are read in packet
    // order, as pyxtf does.
    const size_t channel_number = readU16(header, offset::kChannelNumber);
    const size_t index = channel_number < info.channels.size() ? channel_number : i;
    if (index >= info.channels.size()) {
      result.error = "sonar ping " + std::to_string(common.ping_number) + ": channel " + std::to_string(i) +
                     " has no CHANINFO (file header declares " + std::to_string(info.channels.size()) + ")";
      return result;
    }
    const XtfChannelInfo& channel = info.channels[index];
    uint64_t num_samples = readU32(header, offset::kNumSamples);
    if (num_samples == 0) num_samples = channel.legacy_num_samples;  // before NumSamples existed
    const uint64_t bytes_per_sample = channel.bytes_per_sample;
    const uint64_t data_bytes = num_samples * bytes_per_sample;
    if (bytes_per_sample == 0 || data_bytes > size - at - kPingChannelHeaderBytes) {
      result.error = "sonar ping " + std::to_string(common.ping_number) + ": channel " + std::to_string(index) + " with " +
                     std::to_string(num_samples) + " samples of " + std::to_string(bytes_per_sample) +
                     " bytes does not fit its " + std::to_string(size) + "-byte record";
      return result;
    }
    const bool is_port = static_cast<int>(index) == options.port_channel;
    const bool is_starboard = static_cast<int>(index) == options.starboard_channel;
    std::optional<SonarChannelRecord>& side = is_port ? out.ping.port : out.ping.starboard;
    if ((is_port || is_starboard) && !side) {
      if (channel.sample_type == SampleType::kUnsupported) {
        result.error = "sonar ping " + std::to_string(common.ping_number) + ": channel " + std::to_string(index) +
                       " has an unsupported sample layout (" + std::to_string(bytes_per_sample) + " bytes, format " +
                       std::to_string(channel.sample_format) + ")";
        return result;
      }
      SonarChannelRecord record = common;
      record.channel = is_port ? sss::sonar::kChannelPort : sss::sonar::kChannelStarboard;
      record.start_frequency_hz = record.end_frequency_hz = frequencyHz(channel.frequency);
      // Sample spacing from the recorded slant range (range = i x SlantRange / NumSamples), or
      // else from the two-way TimeDuration; stored as two-way time so slantRangeM() agrees. When
      // the data starts after a TimeDelay, SlantRange is the far range while the samples span only
      // TimeDuration ("time from the start of the data to its end"): the spacing is that over N.
      const float slant_range_m = readF32(header, offset::kSlantRange);
      const float duration_s = readF32(header, offset::kTimeDuration);
      const float delay_s = readF32(header, offset::kTimeDelay);
      const bool delayed = std::isfinite(delay_s) && delay_s > 0.0f;
      if (num_samples > 0) {
        if (delayed && std::isfinite(duration_s) && duration_s > 0.0f) {
          record.sample_interval_s = static_cast<double>(duration_s) / static_cast<double>(num_samples);
        } else if (std::isfinite(slant_range_m) && slant_range_m > 0.0f) {
          record.sample_interval_s = 2.0 * slant_range_m / (static_cast<double>(record.sound_speed_m_s) * num_samples);
        } else if (std::isfinite(duration_s) && duration_s > 0.0f) {
          record.sample_interval_s = static_cast<double>(duration_s) / static_cast<double>(num_samples);
        } else {
          result.error = "sonar ping " + std::to_string(common.ping_number) + ": channel " + std::to_string(index) +
                         " has neither a slant range nor a time duration; its samples have no range";
          return result;
        }
      }
      if (record.sample_interval_s > 0.0 && delayed) {
        const double start = static_cast<double>(delay_s) / record.sample_interval_s;
        record.start_depth_samples = static_cast<uint32_t>(std::min(std::round(start), 1e9));
      }
      const bool as_signed = options.polar_as_signed && channel.uni_polar == 0;
      record.samples.resize(static_cast<size_t>(num_samples));
      const uint8_t* data = header + kPingChannelHeaderBytes;
      for (size_t s = 0; s < record.samples.size(); ++s) {
        record.samples[s] = sampleMagnitude(data + s * bytes_per_sample, channel.sample_type, as_signed);
      }
      // EdgeTech (and Kongsberg SA) sonar types: the ADC's block floating point exponent, which
      // changes with the gain from ping to ping; unscaled, the image has steps of powers of two.
      const int16_t weight = static_cast<int16_t>(readU16(header, offset::kWeight));
      if (sonarTypeUsesWeight(info.sonar_type) && weight != 0 && weight >= -30 && weight <= 30) {
        const float scale = static_cast<float>(std::ldexp(1.0, -weight));
        for (float& sample : record.samples) sample *= scale;
        record.weighting_factor = weight;
        result.weight_applied = true;
      }
      side = std::move(record);
    }
    at += kPingChannelHeaderBytes + static_cast<size_t>(data_bytes);
  }
  if (!out.ping.port && !out.ping.starboard) {
    result.no_selected_channel = true;
    return result;
  }
  result.ping = std::move(out);
  return result;
}

}  // namespace sss::xtf
