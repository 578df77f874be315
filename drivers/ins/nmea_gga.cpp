// GGA parsing, see nmea_gga.hpp.
#include "drivers/ins/nmea_gga.hpp"

#include "drivers/ins/ixblue_nmea.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string_view>
#include <vector>

namespace sss::ins {

namespace {

bool parseNumber(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(value);
}

// ddmm.mmmm (degrees_digits = 2) or dddmm.mmmm (3) with its hemisphere letter.
bool parseAngle(const std::string& text, const std::string& hemisphere, int degrees_digits, char positive,
                char negative, double limit, double& degrees) {
  if (text.size() < static_cast<size_t>(degrees_digits) + 2 || hemisphere.size() != 1) return false;
  double whole = 0.0, minutes = 0.0;
  if (!parseNumber(text.substr(0, static_cast<size_t>(degrees_digits)), whole) ||
      !parseNumber(text.substr(static_cast<size_t>(degrees_digits)), minutes) || minutes < 0.0 || minutes >= 60.0) {
    return false;
  }
  degrees = whole + minutes / 60.0;
  if (hemisphere[0] == negative) degrees = -degrees;
  else if (hemisphere[0] != positive) return false;
  return std::abs(degrees) <= limit;
}

// The sentence's fields without '$', CR/LF and a checksum, which must match when present.
std::optional<std::vector<std::string>> nmeaFields(const std::string& sentence) {
  std::string_view body = sentence;
  while (!body.empty() && (body.back() == '\r' || body.back() == '\n')) body.remove_suffix(1);
  if (!body.empty() && body.front() == '$') body.remove_prefix(1);
  const size_t star = body.find('*');
  if (star != std::string_view::npos) {
    char expected[3];
    std::snprintf(expected, sizeof expected, "%02X", nmeaChecksum(body.substr(0, star)));
    const std::string_view given = body.substr(star + 1);
    if (given.size() != 2 || std::toupper(given[0]) != expected[0] || std::toupper(given[1]) != expected[1]) {
      return std::nullopt;
    }
    body = body.substr(0, star);
  }
  const std::vector<std::string_view> view = splitFields(body);
  return std::vector<std::string>(view.begin(), view.end());
}

bool isSentence(const std::vector<std::string>& fields, const char* type) {
  return !fields.empty() && fields[0].size() == 5 && fields[0].compare(2, 3, type) == 0;
}

}  // namespace

bool parseNmeaTimeOfDay(std::string_view text, double& seconds_of_day) {
  double time = 0.0;
  // Below 24 h before the casts: a corrupt field holds any number (fuzzed: 1e69).
  if (text.size() < 6 || !parseNumber(std::string(text), time) || time < 0.0 || time >= 240000.0) return false;
  const int hh = static_cast<int>(time / 10000), mm = static_cast<int>(std::fmod(time / 100, 100));
  const double ss = std::fmod(time, 100.0);
  if (hh > 23 || mm > 59 || ss >= 61.0) return false;
  seconds_of_day = hh * 3600.0 + mm * 60.0 + ss;
  return true;
}

std::optional<GgaFix> parseNmeaPosition(const std::string& sentence) {
  const std::optional<std::vector<std::string>> parsed = nmeaFields(sentence);
  if (!parsed) return std::nullopt;
  const std::vector<std::string>& fields = *parsed;
  GgaFix fix;
  fix.quality = 1;
  if (isSentence(fields, "GGA")) return parseGga(sentence);
  if (isSentence(fields, "RMC")) {  // time, status, lat, N/S, lon, E/W, speed, course, date, ...
    if (fields.size() < 7 || fields[2] != "A" || !parseNmeaTimeOfDay(fields[1], fix.seconds_of_day) ||
        !parseAngle(fields[3], fields[4], 2, 'N', 'S', 90.0, fix.latitude_deg) ||
        !parseAngle(fields[5], fields[6], 3, 'E', 'W', 180.0, fix.longitude_deg)) {
      return std::nullopt;
    }
    return fix;
  }
  if (isSentence(fields, "GLL")) {  // lat, N/S, lon, E/W, time, status[, mode]
    if (fields.size() < 7 || fields[6] != "A" || !parseNmeaTimeOfDay(fields[5], fix.seconds_of_day) ||
        !parseAngle(fields[1], fields[2], 2, 'N', 'S', 90.0, fix.latitude_deg) ||
        !parseAngle(fields[3], fields[4], 3, 'E', 'W', 180.0, fix.longitude_deg)) {
      return std::nullopt;
    }
    return fix;
  }
  return std::nullopt;
}

std::optional<GgaFix> parseGga(const std::string& sentence) {
  const std::optional<std::vector<std::string>> parsed = nmeaFields(sentence);
  if (!parsed) return std::nullopt;
  const std::vector<std::string>& fields = *parsed;
  if (fields.size() < 10 || !isSentence(fields, "GGA")) return std::nullopt;
  GgaFix fix;
  double quality = 0.0;
  if (!parseNmeaTimeOfDay(fields[1], fix.seconds_of_day)) return std::nullopt;
  if (!parseAngle(fields[2], fields[3], 2, 'N', 'S', 90.0, fix.latitude_deg) ||
      !parseAngle(fields[4], fields[5], 3, 'E', 'W', 180.0, fix.longitude_deg) || !parseNumber(fields[6], quality)) {
    return std::nullopt;
  }
  fix.quality = static_cast<int>(quality);
  if (fix.quality <= 0) return std::nullopt;
  double number = 0.0;
  if (parseNumber(fields[7], number)) fix.satellites = static_cast<int>(number);
  if (parseNumber(fields[8], number)) fix.hdop = number;
  if (parseNumber(fields[9], number)) fix.altitude_m = number;
  return fix;
}

}  // namespace sss::ins
