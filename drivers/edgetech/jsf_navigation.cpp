// JSF navigation messages, see jsf_navigation.hpp.
#include "drivers/edgetech/jsf_navigation.hpp"

#include <cmath>
#include <cstring>

namespace sss::edgetech {

namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kAngleScaleDeg = 180.0 / 32768.0;

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "JSF navigation decoding reads little-endian fields directly");

template <typename T>
T le(const uint8_t* bytes, size_t offset) {
  T value;
  std::memcpy(&value, bytes + offset, sizeof(T));
  return value;
}

bool bit(uint32_t flags, int index) { return (flags >> index) & 1u; }

// Seconds + milliseconds at the start of every navigation body.
int64_t bodyTimeUs(const uint8_t* body) {
  return static_cast<int64_t>(le<int32_t>(body, 0)) * 1000000 + static_cast<int64_t>(le<int32_t>(body, 4)) * 1000;
}

size_t minimumBodySize(uint16_t type) {
  switch (type) {
    case kJsfNmea: return 12;
    case kJsfPitchRoll: return 40;
    case kJsfDvl: return 58;
    case kJsfSituation: return 244;
    case kJsfSituation2: return 88;
    default: return 0;
  }
}

}  // namespace

bool isNavigationType(uint16_t message_type) { return minimumBodySize(message_type) > 0; }

sss::core::Result<JsfNavigationRecord> decodeNavigation(const JsfMessageHeader& header, const uint8_t* body,
                                                        size_t body_size) {
  const uint16_t type = header.message_type;
  if (!isNavigationType(type)) {
    return sss::core::Status::error("message type " + std::to_string(type) + " is not a navigation type");
  }
  if (body_size < minimumBodySize(type)) {
    return sss::core::Status::error("navigation message type " + std::to_string(type) + " of " +
                                    std::to_string(body_size) + " bytes is shorter than its " +
                                    std::to_string(minimumBodySize(type)) + "-byte layout");
  }
  JsfNavigationRecord r;
  r.message_type = type;
  r.time_us = bodyTimeUs(body);
  switch (type) {
    case kJsfNmea: {
      std::string sentence(reinterpret_cast<const char*>(body + 12), body_size - 12);
      const size_t end = sentence.find_first_of(std::string("\0\r\n", 3));
      if (end != std::string::npos) sentence.resize(end);
      r.nmea = sentence;
      break;
    }
    case kJsfPitchRoll: {
      const uint32_t valid = static_cast<uint32_t>(le<int32_t>(body, 36));
      // Pitch bow up +; roll port up + (= starboard down +, our convention).
      if (bit(valid, 6)) r.pitch_rad = le<int16_t>(body, 24) * kAngleScaleDeg * kDegToRad;
      if (bit(valid, 7)) r.roll_rad = le<int16_t>(body, 26) * kAngleScaleDeg * kDegToRad;
      if (bit(valid, 8)) r.heave_m = le<int16_t>(body, 32) * 1e-3;
      if (bit(valid, 9)) r.heading_rad = le<uint16_t>(body, 34) * 0.01 * kDegToRad;
      break;
    }
    case kJsfDvl: {
      const uint32_t valid = le<uint32_t>(body, 12);
      if (bit(valid, 31)) break;  // the DVL reports an error: time only
      if (bit(valid, 5)) {
        double sum = 0.0;
        int count = 0;
        for (int beam = 0; beam < 4; ++beam) {
          const int32_t range_cm = le<int32_t>(body, 16 + 4 * beam);
          if (range_cm > 0) {
            sum += range_cm * 0.01;
            ++count;
          }
        }
        // Slant beam ranges, not corrected for the Janus angle (unknown here): an upper bound.
        if (count > 0) r.altitude_m = sum / count;
      }
      if (bit(valid, 0)) {
        const double x = le<int16_t>(body, 32) * 1e-3;  // starboard or east
        const double y = le<int16_t>(body, 34) * 1e-3;  // forward or north
        if (bit(valid, 1)) {
          r.velocity_starboard_m_s = x;
          r.velocity_forward_m_s = y;
        } else {
          r.velocity_east_m_s = x;
          r.velocity_north_m_s = y;
        }
      }
      if (bit(valid, 2)) r.velocity_down_m_s = -le<int16_t>(body, 36) * 1e-3;  // sent positive up
      if (bit(valid, 10)) r.depth_m = le<uint16_t>(body, 44) * 0.1;
      if (bit(valid, 7)) r.pitch_rad = le<int16_t>(body, 46) * 0.01 * kDegToRad;
      if (bit(valid, 8)) r.roll_rad = le<int16_t>(body, 48) * 0.01 * kDegToRad;
      if (bit(valid, 6)) r.heading_rad = le<uint16_t>(body, 50) * 0.01 * kDegToRad;
      break;
    }
    case kJsfSituation: {
      const uint32_t valid = le<uint32_t>(body, 12);
      if (bit(valid, 0)) r.time_us = static_cast<int64_t>(le<uint64_t>(body, 20));
      if (bit(valid, 1)) r.latitude_deg = le<double>(body, 28);
      if (bit(valid, 2)) r.longitude_deg = le<double>(body, 36);
      if (bit(valid, 3)) r.depth_m = le<double>(body, 44);
      if (bit(valid, 4)) r.heading_rad = le<double>(body, 52) * kDegToRad;
      if (bit(valid, 5)) r.pitch_rad = le<double>(body, 60) * kDegToRad;
      if (bit(valid, 6)) r.roll_rad = le<double>(body, 68) * kDegToRad;
      if (bit(valid, 13)) r.velocity_north_m_s = le<double>(body, 124);
      if (bit(valid, 14)) r.velocity_east_m_s = le<double>(body, 132);
      if (bit(valid, 15)) r.velocity_down_m_s = le<double>(body, 140);
      break;
    }
    case kJsfSituation2: {
      const uint32_t valid = le<uint32_t>(body, 12);
      // 0.01 us units per the layout; the spec also says "divide by 1e7": the same thing.
      if (bit(valid, 0)) r.time_us = static_cast<int64_t>(le<uint64_t>(body, 20) / 100);
      if (bit(valid, 1)) r.longitude_deg = le<double>(body, 36);
      if (bit(valid, 2)) r.latitude_deg = le<double>(body, 28);
      if (bit(valid, 3)) r.depth_m = le<float>(body, 44);
      if (bit(valid, 4)) r.altitude_m = le<float>(body, 48);
      if (bit(valid, 5)) r.heave_m = le<float>(body, 52);
      if (bit(valid, 6)) {
        const double v1 = le<float>(body, 56), v2 = le<float>(body, 60);
        if (body[16] == 0) {
          r.velocity_north_m_s = v1;
          r.velocity_east_m_s = v2;
        } else if (body[16] == 1) {
          r.velocity_forward_m_s = v1;
          r.velocity_starboard_m_s = v2;
        }  // 2: rotated 45 degrees; no use to us
      }
      if (bit(valid, 7)) r.velocity_down_m_s = le<float>(body, 64);
      if (bit(valid, 8)) r.pitch_rad = le<float>(body, 68) * kDegToRad;
      if (bit(valid, 9)) r.roll_rad = le<float>(body, 72) * kDegToRad;
      if (bit(valid, 10)) r.heading_rad = le<float>(body, 76) * kDegToRad;
      break;
    }
    default:
      break;
  }
  // Reject values no vehicle can have: corrupt bytes that passed the framing.
  auto sane = [](std::optional<double>& value, double limit) {
    if (value && (!std::isfinite(*value) || std::abs(*value) > limit)) value.reset();
  };
  sane(r.latitude_deg, 90.0);
  sane(r.longitude_deg, 180.0);
  sane(r.depth_m, 12000.0);
  sane(r.altitude_m, 10000.0);
  sane(r.heading_rad, 2.0 * M_PI + 1e-6);
  sane(r.pitch_rad, M_PI);
  sane(r.roll_rad, M_PI);
  return r;
}

}  // namespace sss::edgetech
