// JSF message header and type 80 sonar data: encode and decode, see jsf_format.hpp.
#include "drivers/edgetech/jsf_format.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <ctime>
#include <type_traits>

namespace sss::edgetech {

namespace {

// Little-endian field access at a byte offset; the host may be of either endianness.
template <typename T>
T readLe(const uint8_t* bytes, size_t offset) {
  using U = std::make_unsigned_t<std::conditional_t<std::is_floating_point_v<T>, uint32_t, T>>;
  U value = 0;
  for (size_t i = 0; i < sizeof(T); ++i) value |= static_cast<U>(static_cast<U>(bytes[offset + i]) << (8 * i));
  T result;
  std::memcpy(&result, &value, sizeof(T));
  return result;
}

template <typename T>
void writeLe(uint8_t* bytes, size_t offset, T value) {
  using U = std::make_unsigned_t<std::conditional_t<std::is_floating_point_v<T>, uint32_t, T>>;
  U raw;
  std::memcpy(&raw, &value, sizeof(T));
  for (size_t i = 0; i < sizeof(T); ++i) bytes[offset + i] = static_cast<uint8_t>(raw >> (8 * i));
}

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr double kDegToRad = M_PI / 180.0;
constexpr double kMinutesX10000PerDegree = 600000.0;  // coordinate units 2
constexpr double kAngleScale = 180.0 / 32768.0;       // pitch/roll degrees per count

double degrees0To360(double degrees) {
  const double wrapped = std::fmod(degrees, 360.0);
  return wrapped < 0.0 ? wrapped + 360.0 : wrapped;
}

int32_t clampToInt32(double value) {
  return static_cast<int32_t>(std::clamp(std::llround(value), static_cast<long long>(INT32_MIN),
                                         static_cast<long long>(INT32_MAX)));
}

int16_t clampToInt16(double value) {
  return static_cast<int16_t>(std::clamp(std::lround(value), -32768L, 32767L));
}

}  // namespace

std::vector<uint16_t> quantiseEnvelope(const std::vector<float>& magnitudes, int16_t& weighting_factor) {
  float largest = 0.0f;
  for (float m : magnitudes) {
    if (std::isfinite(m)) largest = std::max(largest, m);
  }
  // Largest N with largest * 2^N <= 65535, so the loudest sample uses the full 16 bits.
  int n = 0;
  if (largest > 0.0f) n = static_cast<int>(std::floor(std::log2(65535.0 / static_cast<double>(largest))));
  n = std::clamp(n, -15, 30);
  weighting_factor = static_cast<int16_t>(n);
  const double scale = std::ldexp(1.0, n);
  std::vector<uint16_t> codes(magnitudes.size());
  for (size_t i = 0; i < magnitudes.size(); ++i) {
    const double m = std::isfinite(magnitudes[i]) ? std::max(0.0f, magnitudes[i]) : 0.0;
    codes[i] = static_cast<uint16_t>(std::min(65535.0, std::round(m * scale)));
  }
  return codes;
}

namespace {
// Seconds since 1970 of a calendar time given as the day of the year; 0 when it is impossible.
int64_t calendarSeconds(int year, int day_of_year, int hour, int minute, int second) {
  if (!(year >= 1970 && year <= 2200 && day_of_year >= 1 && day_of_year <= 366 && hour >= 0 && hour <= 23 &&
        minute >= 0 && minute <= 59 && second >= 0 && second <= 60))
    return 0;
  tm calendar{};
  calendar.tm_year = year - 1900;
  calendar.tm_mon = 0;
  calendar.tm_mday = day_of_year;  // timegm carries days past January into the right month
  calendar.tm_hour = hour;
  calendar.tm_min = minute;
  calendar.tm_sec = second;
  return static_cast<int64_t>(timegm(&calendar));
}

// Envelope (u16) or I/Q (2 x i16) samples scaled by 2^-weighting_factor (types 80 and 82).
sss::core::Status decodeSamples(const uint8_t* samples, size_t num_samples, uint16_t data_format,
                                int16_t weighting_factor, std::vector<float>& out) {
  // 2^-N; N outside a sane range is corruption, not a gain setting.
  if (weighting_factor < -30 || weighting_factor > 30) {
    return sss::core::Status::error("weighting factor " + std::to_string(weighting_factor) + " is outside [-30, 30]");
  }
  const double scale = std::ldexp(1.0, -weighting_factor);
  out.resize(num_samples);
  if (data_format == 0) {
    for (size_t i = 0; i < num_samples; ++i) out[i] = static_cast<float>(readLe<uint16_t>(samples, 2 * i) * scale);
  } else {
    for (size_t i = 0; i < num_samples; ++i) {
      const double in_phase = readLe<int16_t>(samples, 4 * i);
      const double quadrature = readLe<int16_t>(samples, 4 * i + 2);
      out[i] = static_cast<float>(std::hypot(in_phase, quadrature) * scale);
    }
  }
  return sss::core::Status::success();
}
}  // namespace

void encodeHeader(const JsfMessageHeader& header, uint8_t* bytes) {
  std::memset(bytes, 0, kJsfHeaderSize);
  writeLe<uint16_t>(bytes, 0, kJsfStartMarker);
  bytes[2] = header.protocol_version;
  bytes[3] = header.session_id;
  writeLe<uint16_t>(bytes, 4, header.message_type);
  bytes[6] = header.command_type;
  bytes[7] = header.subsystem;
  bytes[8] = header.channel;
  bytes[9] = header.sequence;
  writeLe<int32_t>(bytes, 12, header.byte_count);
}

std::optional<JsfMessageHeader> decodeHeader(const uint8_t* bytes) {
  if (readLe<uint16_t>(bytes, 0) != kJsfStartMarker) return std::nullopt;
  JsfMessageHeader header;
  header.protocol_version = bytes[2];
  header.session_id = bytes[3];
  header.message_type = readLe<uint16_t>(bytes, 4);
  header.command_type = bytes[6];
  header.subsystem = bytes[7];
  header.channel = bytes[8];
  header.sequence = bytes[9];
  header.byte_count = readLe<int32_t>(bytes, 12);
  return header;
}

void encodeSonarLayback(float layback_m, uint8_t* b) { writeLe<float>(b, 228, layback_m); }

void encodeSonarNavigation(const SonarChannelRecord& record, uint8_t* b) {
  writeLe<uint16_t>(b, 30, record.validity);
  if (record.projected_position) {
    writeLe<int32_t>(b, 80, clampToInt32(record.easting_m * 1000.0));
    writeLe<int32_t>(b, 84, clampToInt32(record.northing_m * 1000.0));
    writeLe<int16_t>(b, 88, 1);  // coordinate units: millimetres
  } else {
    writeLe<int32_t>(b, 80, clampToInt32(record.longitude_deg * kMinutesX10000PerDegree));
    writeLe<int32_t>(b, 84, clampToInt32(record.latitude_deg * kMinutesX10000PerDegree));
    writeLe<int16_t>(b, 88, 2);  // coordinate units: minutes of arc x 10000
  }
  writeLe<int32_t>(b, 136, clampToInt32(record.depth_m * 1000.0));
  writeLe<uint16_t>(b, 172, static_cast<uint16_t>(std::lround(degrees0To360(record.heading_rad * kRadToDeg) * 100.0) % 36000));
  writeLe<int16_t>(b, 192, static_cast<int16_t>(std::lround(degrees0To360(record.course_rad * kRadToDeg)) % 360));
  writeLe<int16_t>(b, 174, clampToInt16(record.pitch_rad * kRadToDeg / kAngleScale));
  writeLe<int16_t>(b, 176, clampToInt16(record.roll_rad * kRadToDeg / kAngleScale));
}

std::vector<uint8_t> encodeSonarData(const SonarChannelRecord& record, const std::vector<uint16_t>& envelope_codes,
                                     uint8_t sequence) {
  const size_t num_samples = std::min<size_t>(envelope_codes.size(), 0xFFFFF);  // 20 bits with the MSBs
  const size_t body_size = kSonarDataHeaderSize + 2 * num_samples;
  std::vector<uint8_t> bytes(kJsfHeaderSize + body_size, 0);

  JsfMessageHeader header;
  header.message_type = kJsfSonarData;
  header.subsystem = record.subsystem;
  header.channel = record.channel;
  header.sequence = sequence;
  header.byte_count = static_cast<int32_t>(body_size);
  encodeHeader(header, bytes.data());

  uint8_t* b = bytes.data() + kJsfHeaderSize;
  const int64_t seconds = record.ping_time_us >= 0 ? record.ping_time_us / 1000000 : (record.ping_time_us - 999999) / 1000000;
  const int64_t micros = record.ping_time_us - seconds * 1000000;
  writeLe<int32_t>(b, 0, static_cast<int32_t>(seconds));
  writeLe<uint32_t>(b, 4, record.start_depth_samples);
  writeLe<uint32_t>(b, 8, record.ping_number);
  const uint16_t start_freq = static_cast<uint16_t>(std::lround(record.start_frequency_hz / 10.0f) & 0xFFFF);
  const uint16_t end_freq = static_cast<uint16_t>(std::lround(record.end_frequency_hz / 10.0f) & 0xFFFF);
  const uint16_t msbs = static_cast<uint16_t>(((std::lround(record.start_frequency_hz / 10.0f) >> 16) & 0xF) |
                                              (((std::lround(record.end_frequency_hz / 10.0f) >> 16) & 0xF) << 4) |
                                              (((num_samples >> 16) & 0xF) << 8));
  writeLe<uint16_t>(b, 16, msbs);
  writeLe<int16_t>(b, 28, 1);  // id code: 1 = seismic/sonar data
  writeLe<int16_t>(b, 34, 0);  // envelope
  writeLe<uint16_t>(b, 114, static_cast<uint16_t>(num_samples & 0xFFFF));
  writeLe<uint32_t>(b, 116, static_cast<uint32_t>(std::llround(record.sample_interval_s * 1e9)));
  writeLe<uint16_t>(b, 126, start_freq);
  writeLe<uint16_t>(b, 128, end_freq);
  writeLe<int32_t>(b, 144, clampToInt32(record.altitude_m * 1000.0));
  writeLe<float>(b, 148, record.sound_speed_m_s);
  // Calendar fields (offsets 156-166) and milliseconds today (200).
  const time_t t = static_cast<time_t>(seconds);
  tm utc{};
  gmtime_r(&t, &utc);
  writeLe<int16_t>(b, 156, static_cast<int16_t>(utc.tm_year + 1900));
  writeLe<int16_t>(b, 158, static_cast<int16_t>(utc.tm_yday + 1));
  writeLe<int16_t>(b, 160, static_cast<int16_t>(utc.tm_hour));
  writeLe<int16_t>(b, 162, static_cast<int16_t>(utc.tm_min));
  writeLe<int16_t>(b, 164, static_cast<int16_t>(utc.tm_sec));
  writeLe<int16_t>(b, 166, 0);
  writeLe<int16_t>(b, 168, record.weighting_factor);
  encodeSonarNavigation(record, b);
  const int64_t ms_today = (static_cast<int64_t>(utc.tm_hour) * 3600 + utc.tm_min * 60 + utc.tm_sec) * 1000 + micros / 1000;
  writeLe<uint32_t>(b, 200, static_cast<uint32_t>(ms_today));
  writeLe<int32_t>(b, 216, -1);  // spherical correction off
  encodeSonarLayback(static_cast<float>(record.layback_m), b);
  uint8_t* samples = b + kSonarDataHeaderSize;
  for (size_t i = 0; i < num_samples; ++i) writeLe<uint16_t>(samples, 2 * i, envelope_codes[i]);
  return bytes;
}

sss::core::Result<SonarChannelRecord> decodeSonarData(const JsfMessageHeader& header, const uint8_t* body,
                                                      size_t body_size) {
  if (body_size < kSonarDataHeaderSize) {
    return sss::core::Status::error("sonar data body of " + std::to_string(body_size) +
                                    " bytes is shorter than its 240-byte header");
  }
  SonarChannelRecord r;
  r.subsystem = header.subsystem;
  r.channel = header.channel;
  int64_t seconds = readLe<int32_t>(body, 0);
  const uint32_t ms_today = readLe<uint32_t>(body, 200);
  if (seconds == 0) {
    // Before protocol 8 bytes 0-3 held a trace sequence number (always 0) and the time was only the
    // calendar: year, day of the year, hour, minute, second (MB-System reads such files so).
    seconds = calendarSeconds(readLe<int16_t>(body, 156), readLe<int16_t>(body, 158), readLe<int16_t>(body, 160),
                              readLe<int16_t>(body, 162), readLe<int16_t>(body, 164));
  }
  r.ping_time_us = seconds * 1000000 + static_cast<int64_t>(ms_today % 1000) * 1000;
  r.start_depth_samples = readLe<uint32_t>(body, 4);
  r.ping_number = readLe<uint32_t>(body, 8);
  const uint16_t msbs = readLe<uint16_t>(body, 16);
  r.validity = readLe<uint16_t>(body, 30);
  r.data_format = static_cast<uint16_t>(readLe<int16_t>(body, 34));
  const int16_t coordinate_units = readLe<int16_t>(body, 88);
  const int32_t x = readLe<int32_t>(body, 80);
  const int32_t y = readLe<int32_t>(body, 84);
  if (coordinate_units == 2) {
    r.longitude_deg = x / kMinutesX10000PerDegree;
    r.latitude_deg = y / kMinutesX10000PerDegree;
  } else {
    // Projected units (1 mm, 3 dm, 4 cm) carry no geodetic position: kept as easting/northing
    // in metres (X east, Y north), the frame the offline runner then works in.
    const bool had_position = (r.validity & kValidLatLon) != 0 && !(x == 0 && y == 0);
    r.validity = static_cast<uint16_t>(r.validity & ~kValidLatLon);
    const double metres_per_unit = coordinate_units == 1 ? 1e-3 : coordinate_units == 3 ? 0.1 : coordinate_units == 4 ? 0.01 : 0.0;
    if (had_position && metres_per_unit > 0.0) {
      r.projected_position = true;
      r.easting_m = x * metres_per_unit;
      r.northing_m = y * metres_per_unit;
    }
  }
  const size_t num_samples = static_cast<size_t>(readLe<uint16_t>(body, 114)) | (static_cast<size_t>((msbs >> 8) & 0xF) << 16);
  r.sample_interval_s = readLe<uint32_t>(body, 116) * 1e-9;
  r.start_frequency_hz = static_cast<float>((readLe<uint16_t>(body, 126) | ((msbs & 0xF) << 16)) * 10.0);
  r.end_frequency_hz = static_cast<float>((readLe<uint16_t>(body, 128) | (((msbs >> 4) & 0xF) << 16)) * 10.0);
  r.depth_m = readLe<int32_t>(body, 136) * 1e-3;
  r.altitude_m = readLe<int32_t>(body, 144) * 1e-3;
  r.sound_speed_m_s = readLe<float>(body, 148);
  if (!std::isfinite(r.sound_speed_m_s) || r.sound_speed_m_s < 1300.0f || r.sound_speed_m_s > 1700.0f) {
    // An unset or corrupt sound speed would scale every range: fall back to the nominal value.
    r.sound_speed_m_s = 1500.0f;
    r.validity = static_cast<uint16_t>(r.validity & ~kValidSoundSpeed);
  }
  r.weighting_factor = readLe<int16_t>(body, 168);
  r.heading_rad = readLe<uint16_t>(body, 172) * 0.01 * kDegToRad;
  r.course_rad = degrees0To360(readLe<int16_t>(body, 192)) * kDegToRad;  // whole degrees
  // Layback (228, f32 m, "distance to the sonar"): as recorded; SonarDriverOptions::apply_layback
  // decides whether it is handed on (the format does not say whose the position is).
  const float layback_m = readLe<float>(body, 228);
  if (std::isfinite(layback_m) && layback_m > 0.0f && layback_m <= sss::sonar::kMaxLaybackM) r.layback_m = layback_m;
  r.pitch_rad = readLe<int16_t>(body, 174) * kAngleScale * kDegToRad;
  r.roll_rad = readLe<int16_t>(body, 176) * kAngleScale * kDegToRad;

  size_t bytes_per_sample = 0;
  if (r.data_format == 0) {
    bytes_per_sample = 2;
  } else if (r.data_format == 1) {
    bytes_per_sample = 4;
  } else {
    return sss::core::Status::error("sonar data format " + std::to_string(r.data_format) +
                                    " is not supported (0 envelope, 1 I/Q)");
  }
  const size_t needed = kSonarDataHeaderSize + num_samples * bytes_per_sample;
  if (needed > body_size) {
    return sss::core::Status::error("sonar data of " + std::to_string(num_samples) + " samples needs " +
                                    std::to_string(needed) + " bytes, the message has " + std::to_string(body_size));
  }
  if (sss::core::Status decoded =
          decodeSamples(body + kSonarDataHeaderSize, num_samples, r.data_format, r.weighting_factor, r.samples);
      !decoded)
    return decoded;
  return r;
}

sss::core::Result<SonarChannelRecord> decodeOldSideScanData(const JsfMessageHeader& header, const uint8_t* body,
                                                            size_t body_size) {
  if (body_size < kOldSideScanHeaderSize) {
    return sss::core::Status::error("side-scan message 82 of " + std::to_string(body_size) +
                                    " bytes is shorter than its 80-byte header");
  }
  SonarChannelRecord r;
  r.subsystem = header.subsystem;
  r.channel = header.channel;
  r.ping_number = readLe<uint32_t>(body, 4);
  const uint64_t num_samples = readLe<uint32_t>(body, 12);
  r.sample_interval_s = readLe<uint32_t>(body, 16) * 1e-9;
  r.start_depth_samples = readLe<uint32_t>(body, 20);
  r.weighting_factor = readLe<int16_t>(body, 24);
  r.data_format = readLe<uint16_t>(body, 36);
  const int64_t seconds = calendarSeconds(readLe<int16_t>(body, 44), readLe<uint16_t>(body, 46),
                                          readLe<uint16_t>(body, 48), readLe<uint16_t>(body, 50), readLe<uint16_t>(body, 52));
  if (seconds == 0) {
    return sss::core::Status::error("side-scan message 82 has an impossible date (year " +
                                    std::to_string(readLe<int16_t>(body, 44)) + ", day " +
                                    std::to_string(readLe<uint16_t>(body, 46)) + ")");
  }
  r.ping_time_us = seconds * 1000000 + static_cast<int64_t>(readLe<uint32_t>(body, 40) % 1000) * 1000;
  constexpr double kMinutesToRad = kDegToRad / 60.0;
  const int16_t heading_minutes = readLe<int16_t>(body, 54);
  if (heading_minutes != 0) {
    r.heading_rad = degrees0To360(heading_minutes / 60.0) * kDegToRad;
    r.validity |= kValidHeading;
  }
  r.pitch_rad = readLe<int16_t>(body, 56) * kMinutesToRad;
  r.roll_rad = readLe<int16_t>(body, 58) * kMinutesToRad;
  r.validity |= kValidPitchRoll;
  const uint32_t depth_cm = readLe<uint32_t>(body, 64);
  if (depth_cm > 0 && depth_cm < 1200000) {  // within 12 km
    r.depth_m = depth_cm * 0.01;
    r.validity |= kValidDepth;
  }
  if (r.data_format != 0 && r.data_format != 1) {
    return sss::core::Status::error("side-scan message 82 data format " + std::to_string(r.data_format) +
                                    " is not supported (0 envelope, 1 I/Q)");
  }
  const uint64_t needed = kOldSideScanHeaderSize + num_samples * (r.data_format == 1 ? 4 : 2);
  if (needed > body_size) {
    return sss::core::Status::error("side-scan message 82 of " + std::to_string(num_samples) + " samples needs " +
                                    std::to_string(needed) + " bytes, the message has " + std::to_string(body_size));
  }
  if (sss::core::Status decoded = decodeSamples(body + kOldSideScanHeaderSize, static_cast<size_t>(num_samples),
                                                r.data_format, r.weighting_factor, r.samples);
      !decoded)
    return decoded;
  return r;
}

std::vector<uint8_t> encodeOldSideScanData(const SonarChannelRecord& record, const std::vector<uint16_t>& envelope_codes,
                                           uint8_t sequence) {
  const size_t body_size = kOldSideScanHeaderSize + 2 * envelope_codes.size();
  std::vector<uint8_t> bytes(kJsfHeaderSize + body_size, 0);
  JsfMessageHeader header;
  header.message_type = kJsfOldSideScanData;
  header.subsystem = record.subsystem;
  header.channel = record.channel;
  header.sequence = sequence;
  header.byte_count = static_cast<int32_t>(body_size);
  encodeHeader(header, bytes.data());
  uint8_t* b = bytes.data() + kJsfHeaderSize;
  writeLe<uint16_t>(b, 0, record.subsystem);
  writeLe<uint16_t>(b, 2, record.channel);
  writeLe<uint32_t>(b, 4, record.ping_number);
  writeLe<uint16_t>(b, 8, 1);  // packet 1
  writeLe<uint32_t>(b, 12, static_cast<uint32_t>(envelope_codes.size()));
  writeLe<uint32_t>(b, 16, static_cast<uint32_t>(std::llround(record.sample_interval_s * 1e9)));
  writeLe<uint32_t>(b, 20, record.start_depth_samples);
  writeLe<int16_t>(b, 24, record.weighting_factor);
  writeLe<uint16_t>(b, 36, 0);  // envelope
  const int64_t seconds = record.ping_time_us >= 0 ? record.ping_time_us / 1000000 : (record.ping_time_us - 999999) / 1000000;
  const int64_t millis = (record.ping_time_us - seconds * 1000000) / 1000;
  const time_t t = static_cast<time_t>(seconds);
  tm utc{};
  gmtime_r(&t, &utc);
  writeLe<uint32_t>(b, 40, static_cast<uint32_t>(((utc.tm_hour * 60 + utc.tm_min) * 60 + utc.tm_sec) * 1000 + millis));
  writeLe<int16_t>(b, 44, static_cast<int16_t>(utc.tm_year + 1900));
  writeLe<uint16_t>(b, 46, static_cast<uint16_t>(utc.tm_yday + 1));
  writeLe<uint16_t>(b, 48, static_cast<uint16_t>(utc.tm_hour));
  writeLe<uint16_t>(b, 50, static_cast<uint16_t>(utc.tm_min));
  writeLe<uint16_t>(b, 52, static_cast<uint16_t>(utc.tm_sec));
  writeLe<int16_t>(b, 54, clampToInt16(degrees0To360(record.heading_rad * kRadToDeg) * 60.0));
  writeLe<int16_t>(b, 56, clampToInt16(record.pitch_rad * kRadToDeg * 60.0));
  writeLe<int16_t>(b, 58, clampToInt16(record.roll_rad * kRadToDeg * 60.0));
  writeLe<uint32_t>(b, 64, static_cast<uint32_t>(std::max(0.0, std::round(record.depth_m * 100.0))));
  uint8_t* samples = b + kOldSideScanHeaderSize;
  for (size_t i = 0; i < envelope_codes.size(); ++i) writeLe<uint16_t>(samples, 2 * i, envelope_codes[i]);
  return bytes;
}

}  // namespace sss::edgetech
