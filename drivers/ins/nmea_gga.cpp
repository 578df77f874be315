// GGA parsing, see nmea_gga.hpp.
#include "drivers/ins/nmea_gga.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
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

}  // namespace

std::optional<GgaFix> parseGga(const std::string& sentence) {
  std::string body = sentence;
  while (!body.empty() && (body.back() == '\r' || body.back() == '\n')) body.pop_back();
  if (!body.empty() && body[0] == '$') body.erase(0, 1);
  const size_t star = body.find('*');
  if (star != std::string::npos) {
    unsigned checksum = 0;
    for (size_t i = 0; i < star; ++i) checksum ^= static_cast<unsigned char>(body[i]);
    char expected[3];
    std::snprintf(expected, sizeof expected, "%02X", checksum);
    const std::string given = body.substr(star + 1);
    if (given.size() != 2 || std::toupper(given[0]) != expected[0] || std::toupper(given[1]) != expected[1]) {
      return std::nullopt;
    }
    body.resize(star);
  }
  std::vector<std::string> fields;
  for (size_t start = 0;;) {
    const size_t comma = body.find(',', start);
    fields.push_back(body.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (fields.size() < 10 || fields[0].size() != 5 || fields[0].compare(2, 3, "GGA") != 0) return std::nullopt;
  GgaFix fix;
  double time = 0.0, quality = 0.0;
  if (!parseNumber(fields[1], time) || fields[1].size() < 6) return std::nullopt;
  const int hh = static_cast<int>(time / 10000), mm = static_cast<int>(std::fmod(time / 100, 100));
  const double ss = std::fmod(time, 100.0);
  if (hh > 23 || mm > 59 || ss >= 61.0) return std::nullopt;
  fix.seconds_of_day = hh * 3600.0 + mm * 60.0 + ss;
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
