// iXblue INS NMEA 0183: encoding of one navigation state into a sentence burst, and typed,
// bounds-checked parsing of each supported sentence (never throws on field data).
#include "drivers/ins/ixblue_nmea.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace sss::ins {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadToDeg = 180.0 / kPi;
constexpr int64_t kMicrosecondsPerDay = 86400LL * 1000000LL;
// A numeric field longer than this is not something an INS writes; refusing it early keeps
// from_chars away from absurd inputs.
constexpr size_t kMaxNumberChars = 32;

// Field ranges: physically possible values with margin; beyond them the sentence is corrupt.
constexpr double kMaxAltitudeM = 20000.0;
constexpr double kMinAltitudeM = -12000.0;  // deeper than the Challenger Deep
constexpr double kMaxSpeedM_s = 100.0;
constexpr double kMaxAngleStdDeg = 360.0;
constexpr double kMaxPositionStdM = 1.0e7;  // unaligned INS report tens of km
constexpr double kMaxSpeedStdM_s = 1000.0;
constexpr double kMaxDvlRangeM = 12000.0;
constexpr int kMinYear = 1980;
constexpr int kMaxYear = 2199;

// ---- encoding ------------------------------------------------------------------------------

void appendFixed(std::string& out, double value, int decimals, double min_value,
                 double max_value) {
  if (!std::isfinite(value)) value = 0.0;
  value = std::clamp(value, min_value, max_value);
  // "-0.000" for tiny negatives is legal but ugly and would change the checksum of a state
  // that is zero in every meaningful digit.
  if (std::round(value * std::pow(10.0, decimals)) == 0.0) value = 0.0;
  std::array<char, 64> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value,
                                    std::chars_format::fixed, decimals);
  out.append(buffer.data(), result.ptr);
}

void appendTwoDigits(std::string& out, int64_t value) {
  out.push_back(static_cast<char>('0' + (value / 10) % 10));
  out.push_back(static_cast<char>('0' + value % 10));
}

void appendHex8(std::string& out, uint32_t value) {
  static const char kHex[] = "0123456789ABCDEF";
  for (int shift = 28; shift >= 0; shift -= 4) out.push_back(kHex[(value >> shift) & 0xF]);
}

// hhmmss.<fraction_digits> from microseconds of the day (fraction truncated, as clocks do).
void appendTimeOfDay(std::string& out, int64_t time_of_day_us, int fraction_digits) {
  const int64_t seconds = time_of_day_us / 1000000;
  appendTwoDigits(out, seconds / 3600);
  appendTwoDigits(out, (seconds / 60) % 60);
  appendTwoDigits(out, seconds % 60);
  out.push_back('.');
  int64_t fraction = time_of_day_us % 1000000;
  for (int i = 6; i > fraction_digits; --i) fraction /= 10;
  std::array<char, 8> digits{};
  for (int i = fraction_digits - 1; i >= 0; --i) {
    digits[static_cast<size_t>(i)] = static_cast<char>('0' + fraction % 10);
    fraction /= 10;
  }
  out.append(digits.data(), static_cast<size_t>(fraction_digits));
}

void appendSentence(std::string& out, const std::string& body) { out += frameSentence(body); }

// ---- field parsing -------------------------------------------------------------------------

struct FieldError {
  SentenceError error = SentenceError::kNone;
  std::string text;
};

// Strict decimal: [+-]digits[.digits] or [+-].digits; no exponent, no inf/nan, no spaces.
SentenceError parseNumber(std::string_view field, double& value) {
  if (field.empty()) return SentenceError::kEmptyField;
  if (field.size() > kMaxNumberChars) return SentenceError::kNotANumber;
  std::string_view digits = field;
  if (digits.front() == '+') digits.remove_prefix(1);  // from_chars refuses a leading '+'
  bool seen_digit = false, seen_point = false;
  for (size_t i = 0; i < digits.size(); ++i) {
    const char c = digits[i];
    if (c >= '0' && c <= '9') {
      seen_digit = true;
    } else if (c == '.' && !seen_point) {
      seen_point = true;
    } else if (c == '-' && i == 0 && field.front() != '+') {
      continue;
    } else {
      return SentenceError::kNotANumber;
    }
  }
  if (!seen_digit) return SentenceError::kNotANumber;
  const auto result = std::from_chars(digits.data(), digits.data() + digits.size(), value,
                                      std::chars_format::fixed);
  if (result.ec != std::errc() || result.ptr != digits.data() + digits.size() ||
      !std::isfinite(value)) {
    return SentenceError::kNotANumber;
  }
  return SentenceError::kNone;
}

// Collects the first error of a sentence with its field name, so the caller gets one message.
class FieldReader {
 public:
  FieldReader(std::string_view sentence_name, const std::vector<std::string_view>& fields)
      : name_(sentence_name), fields_(fields) {}

  double number(size_t index, const char* what, double min_value, double max_value) {
    if (failed()) return 0.0;
    if (index >= fields_.size()) {
      fail(SentenceError::kWrongFieldCount, what, "");
      return 0.0;
    }
    double value = 0.0;
    const SentenceError error = parseNumber(fields_[index], value);
    if (error != SentenceError::kNone) {
      fail(error, what, fields_[index]);
      return 0.0;
    }
    if (value < min_value || value > max_value) {
      fail(SentenceError::kOutOfRange, what, fields_[index]);
      return 0.0;
    }
    return value;
  }

  int integer(size_t index, const char* what, int min_value, int max_value) {
    if (failed()) return 0;
    if (index >= fields_.size()) {
      fail(SentenceError::kWrongFieldCount, what, "");
      return 0;
    }
    const std::string_view field = fields_[index];
    if (field.empty()) {
      fail(SentenceError::kEmptyField, what, field);
      return 0;
    }
    if (field.size() > 9 || !std::all_of(field.begin(), field.end(),
                                         [](char c) { return c >= '0' && c <= '9'; })) {
      fail(SentenceError::kNotANumber, what, field);
      return 0;
    }
    int value = 0;
    std::from_chars(field.data(), field.data() + field.size(), value);
    if (value < min_value || value > max_value) {
      fail(SentenceError::kOutOfRange, what, field);
      return 0;
    }
    return value;
  }

  uint32_t hexWord(size_t index, const char* what) {
    if (failed()) return 0;
    if (index >= fields_.size()) {
      fail(SentenceError::kWrongFieldCount, what, "");
      return 0;
    }
    const std::string_view field = fields_[index];
    if (field.empty()) {
      fail(SentenceError::kEmptyField, what, field);
      return 0;
    }
    uint32_t value = 0;
    const auto result = std::from_chars(field.data(), field.data() + field.size(), value, 16);
    if (field.size() > 8 || result.ec != std::errc() ||
        result.ptr != field.data() + field.size()) {
      fail(SentenceError::kNotANumber, what, field);
      return 0;
    }
    return value;
  }

  // hhmmss[.s...]: microseconds of the day; fraction digits beyond 6 are dropped.
  int64_t timeOfDay(size_t index, const char* what) {
    if (failed()) return 0;
    if (index >= fields_.size()) {
      fail(SentenceError::kWrongFieldCount, what, "");
      return 0;
    }
    const std::string_view field = fields_[index];
    if (field.empty()) {
      fail(SentenceError::kEmptyField, what, field);
      return 0;
    }
    auto isDigit = [](char c) { return c >= '0' && c <= '9'; };
    if (field.size() < 6 || field.size() > 16 ||
        !std::all_of(field.begin(), field.begin() + 6, isDigit) ||
        (field.size() > 6 &&
         (field[6] != '.' || !std::all_of(field.begin() + 7, field.end(), isDigit)))) {
      fail(SentenceError::kNotANumber, what, field);
      return 0;
    }
    auto two = [&](size_t at) { return (field[at] - '0') * 10 + (field[at + 1] - '0'); };
    const int hours = two(0), minutes = two(2), seconds = two(4);
    // 60 s allows a leap second.
    if (hours > 23 || minutes > 59 || seconds > 60) {
      fail(SentenceError::kOutOfRange, what, field);
      return 0;
    }
    int64_t micros = 0;
    int64_t scale = 100000;
    for (size_t i = 7; i < field.size() && scale > 0; ++i, scale /= 10) {
      micros += (field[i] - '0') * scale;
    }
    return ((hours * 60LL + minutes) * 60LL + seconds) * 1000000LL + micros;
  }

  void expectLiteral(size_t index, std::string_view literal, const char* what) {
    if (failed()) return;
    if (index >= fields_.size()) {
      fail(SentenceError::kWrongFieldCount, what, "");
      return;
    }
    if (fields_[index] != literal) fail(SentenceError::kOutOfRange, what, fields_[index]);
  }

  void expectFieldCount(size_t min_count, size_t max_count) {
    if (failed()) return;
    if (fields_.size() < min_count || fields_.size() > max_count) {
      error_ = SentenceError::kWrongFieldCount;
      text_ = std::string(name_) + ": " + std::to_string(fields_.size()) +
              " fields, expected " + std::to_string(min_count) +
              (min_count == max_count ? "" : ".." + std::to_string(max_count)) +
              "; sentence dropped";
    }
  }

  bool failed() const { return error_ != SentenceError::kNone; }
  SentenceError error() const { return error_; }
  const std::string& text() const { return text_; }

 private:
  void fail(SentenceError error, const char* what, std::string_view value) {
    error_ = error;
    text_ = std::string(name_) + ": " + what + " field \"" +
            std::string(value.substr(0, kMaxNumberChars)) + "\" is " +
            sentenceErrorName(error) + "; sentence dropped";
  }

  std::string_view name_;
  const std::vector<std::string_view>& fields_;
  SentenceError error_ = SentenceError::kNone;
  std::string text_;
};

bool isLeapYear(int year) { return (year % 4 == 0 && year % 100 != 0) || year % 400 == 0; }

int daysInMonth(int year, int month) {
  static const int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  return month == 2 && isLeapYear(year) ? 29 : kDays[month - 1];
}

template <typename T>
SentenceParseResult finish(const FieldReader& reader, T sentence) {
  SentenceParseResult result;
  if (reader.failed()) {
    result.error = reader.error();
    result.error_text = reader.text();
  } else {
    result.sentence = sentence;
  }
  return result;
}

SentenceParseResult parsePixse(const std::vector<std::string_view>& fields) {
  SentenceParseResult result;
  if (fields.size() < 2) {
    result.error = SentenceError::kWrongFieldCount;
    result.error_text = "PIXSE: no sentence type field; sentence dropped";
    return result;
  }
  const std::string_view type = fields[1];
  const std::string name = "PIXSE," + std::string(type.substr(0, 8));
  FieldReader reader(name, fields);
  if (type == "ATITUD") {
    reader.expectFieldCount(4, 4);
    AttitudeSentence s;
    s.roll_deg = reader.number(2, "roll", -180.0, 180.0);
    s.pitch_deg = reader.number(3, "pitch", -90.0, 90.0);
    return finish(reader, s);
  }
  if (type == "POSITI") {
    reader.expectFieldCount(5, 5);
    PositionSentence s;
    s.latitude_deg = reader.number(2, "latitude", -90.0, 90.0);
    // iXblue binary output uses [0, 360) east; NMEA readers see either convention.
    s.longitude_deg = reader.number(3, "longitude", -180.0, 360.0);
    s.altitude_m = reader.number(4, "altitude", kMinAltitudeM, kMaxAltitudeM);
    if (s.longitude_deg >= 180.0) s.longitude_deg -= 360.0;
    return finish(reader, s);
  }
  if (type == "SPEED_") {
    reader.expectFieldCount(5, 5);
    SpeedSentence s;
    s.east_m_s = reader.number(2, "east speed", -kMaxSpeedM_s, kMaxSpeedM_s);
    s.north_m_s = reader.number(3, "north speed", -kMaxSpeedM_s, kMaxSpeedM_s);
    s.up_m_s = reader.number(4, "up speed", -kMaxSpeedM_s, kMaxSpeedM_s);
    return finish(reader, s);
  }
  if (type == "TIME__") {
    reader.expectFieldCount(3, 3);
    TimeSentence s;
    s.time_of_day_us = reader.timeOfDay(2, "time");
    return finish(reader, s);
  }
  if (type == "STDHRP") {
    reader.expectFieldCount(5, 5);
    AttitudeStdSentence s;
    s.heading_std_deg = reader.number(2, "heading std", 0.0, kMaxAngleStdDeg);
    s.roll_std_deg = reader.number(3, "roll std", 0.0, kMaxAngleStdDeg);
    s.pitch_std_deg = reader.number(4, "pitch std", 0.0, kMaxAngleStdDeg);
    return finish(reader, s);
  }
  if (type == "STDPOS") {
    reader.expectFieldCount(5, 5);
    PositionStdSentence s;
    s.latitude_std_m = reader.number(2, "latitude std", 0.0, kMaxPositionStdM);
    s.longitude_std_m = reader.number(3, "longitude std", 0.0, kMaxPositionStdM);
    s.altitude_std_m = reader.number(4, "altitude std", 0.0, kMaxPositionStdM);
    return finish(reader, s);
  }
  if (type == "STDSPD") {
    reader.expectFieldCount(5, 5);
    SpeedStdSentence s;
    s.east_std_m_s = reader.number(2, "east speed std", 0.0, kMaxSpeedStdM_s);
    s.north_std_m_s = reader.number(3, "north speed std", 0.0, kMaxSpeedStdM_s);
    s.up_std_m_s = reader.number(4, "up speed std", 0.0, kMaxSpeedStdM_s);
    return finish(reader, s);
  }
  if (type == "ALGSTS" || type == "STATUS") {
    reader.expectFieldCount(4, 4);
    StatusSentence s;
    s.algorithm = type == "ALGSTS";
    s.word_lsb = reader.hexWord(2, "status LSB");
    s.word_msb = reader.hexWord(3, "status MSB");
    return finish(reader, s);
  }
  if (type == "UTMWGS" || type == "HEAVE_" || type == "HT_STS") {
    result.sentence = IgnoredSentence{};
    return result;
  }
  result.error = SentenceError::kUnsupported;
  result.error_text = name + ": unsupported sentence; ignored";
  return result;
}

}  // namespace

// ---- public --------------------------------------------------------------------------------

uint8_t nmeaChecksum(std::string_view body) {
  uint8_t checksum = 0;
  for (const char c : body) checksum ^= static_cast<uint8_t>(c);
  return checksum;
}

std::string frameSentence(std::string_view body) {
  static const char kHex[] = "0123456789ABCDEF";
  const uint8_t checksum = nmeaChecksum(body);
  std::string out;
  out.reserve(body.size() + 6);
  out.push_back('$');
  out.append(body);
  out.push_back('*');
  out.push_back(kHex[checksum >> 4]);
  out.push_back(kHex[checksum & 0xF]);
  out += "\r\n";
  return out;
}

const char* sentenceErrorName(SentenceError error) {
  switch (error) {
    case SentenceError::kNone: return "ok";
    case SentenceError::kUnsupported: return "unsupported";
    case SentenceError::kWrongFieldCount: return "wrong field count";
    case SentenceError::kEmptyField: return "empty";
    case SentenceError::kNotANumber: return "not a number";
    case SentenceError::kOutOfRange: return "out of range";
  }
  return "unknown";
}

std::vector<std::string_view> splitFields(std::string_view body) {
  std::vector<std::string_view> fields;
  size_t start = 0;
  while (true) {
    const size_t comma = body.find(',', start);
    if (comma == std::string_view::npos) {
      fields.push_back(body.substr(start));
      return fields;
    }
    fields.push_back(body.substr(start, comma - start));
    start = comma + 1;
  }
}

int64_t daysFromCivil(int year, int month, int day) {
  // Era-based day count (400-year cycles), valid for any year; March is month 0 so the leap
  // day falls at the end of the counting year.
  const int64_t y = static_cast<int64_t>(year) - (month <= 2 ? 1 : 0);
  const int64_t era = (y >= 0 ? y : y - 399) / 400;
  const int64_t year_of_era = y - era * 400;
  const int64_t shifted_month = month > 2 ? month - 3 : month + 9;
  const int64_t day_of_year = (153 * shifted_month + 2) / 5 + day - 1;
  const int64_t day_of_era =
      year_of_era * 365 + year_of_era / 4 - year_of_era / 100 + day_of_year;
  return era * 146097 + day_of_era - 719468;
}

void civilFromDays(int64_t days, int& year, int& month, int& day) {
  days += 719468;
  const int64_t era = (days >= 0 ? days : days - 146096) / 146097;
  const int64_t day_of_era = days - era * 146097;
  const int64_t year_of_era =
      (day_of_era - day_of_era / 1460 + day_of_era / 36524 - day_of_era / 146096) / 365;
  const int64_t day_of_year =
      day_of_era - (365 * year_of_era + year_of_era / 4 - year_of_era / 100);
  const int64_t shifted_month = (5 * day_of_year + 2) / 153;
  day = static_cast<int>(day_of_year - (153 * shifted_month + 2) / 5 + 1);
  month = static_cast<int>(shifted_month < 10 ? shifted_month + 3 : shifted_month - 9);
  year = static_cast<int>(year_of_era + era * 400 + (month <= 2 ? 1 : 0));
}

SentenceParseResult parseSentence(std::string_view body) {
  const std::vector<std::string_view> fields = splitFields(body);
  const std::string_view address = fields.front();
  if (address == "PIXSE") return parsePixse(fields);

  SentenceParseResult result;
  // Standard sentences: 2-character talker + 3-character formatter; the talker varies by
  // installation (HE for a gyro, IN for an INS, SD for a sounder, GP...), so it is not checked.
  if (address.size() == 5) {
    const std::string_view formatter = address.substr(2);
    const std::string name(address);
    FieldReader reader(name, fields);
    if (formatter == "HDT") {
      reader.expectFieldCount(3, 3);
      HeadingSentence s;
      s.heading_deg = reader.number(1, "heading", 0.0, 360.0);
      reader.expectLiteral(2, "T", "true-heading flag");
      if (s.heading_deg >= 360.0) s.heading_deg = 0.0;
      return finish(reader, s);
    }
    if (formatter == "ZDA") {
      reader.expectFieldCount(7, 7);
      DateTimeSentence s;
      s.time_of_day_us = reader.timeOfDay(1, "time");
      s.day = reader.integer(2, "day", 1, 31);
      s.month = reader.integer(3, "month", 1, 12);
      s.year = reader.integer(4, "year", kMinYear, kMaxYear);
      if (!reader.failed() && s.day > daysInMonth(s.year, s.month)) {
        SentenceParseResult bad;
        bad.error = SentenceError::kOutOfRange;
        bad.error_text = name + ": day " + std::to_string(s.day) + " does not exist in " +
                         std::to_string(s.year) + "-" + std::to_string(s.month) +
                         "; sentence dropped";
        return bad;
      }
      return finish(reader, s);  // local zone fields (5, 6) are informative only
    }
    if (formatter == "DPT") {
      // NMEA 2.x has depth and offset; 3.0 adds the maximum range.
      reader.expectFieldCount(3, 4);
      DepthBelowTransducerSentence s;
      if (!reader.failed() && fields[1].empty()) return finish(reader, s);
      s.has_depth = true;
      s.depth_m = reader.number(1, "depth below transducer", 0.0, kMaxDvlRangeM);
      return finish(reader, s);
    }
  }
  result.error = SentenceError::kUnsupported;
  result.error_text = std::string(address.substr(0, 16)) + ": unsupported sentence; ignored";
  return result;
}

std::string encodeInsState(const InsState& state) {
  const uint32_t valid = state.validity;
  std::string out;
  out.reserve(640);
  std::string body;

  if (valid & kValidHeading) {
    double heading_deg = std::fmod(state.heading_rad * kRadToDeg, 360.0);
    if (!std::isfinite(heading_deg)) heading_deg = 0.0;
    if (heading_deg < 0.0) heading_deg += 360.0;
    if (std::round(heading_deg * 1000.0) >= 360000.0) heading_deg = 0.0;
    body = "HEHDT,";
    appendFixed(body, heading_deg, 3, 0.0, 359.999);
    body += ",T";
    appendSentence(out, body);
  }
  if (valid & kValidAttitude) {
    body = "PIXSE,ATITUD,";
    appendFixed(body, state.roll_rad * kRadToDeg, 3, -180.0, 180.0);  // + port up = FRD roll
    body += ',';
    appendFixed(body, -state.pitch_rad * kRadToDeg, 3, -90.0, 90.0);  // + bow down = -FRD pitch
    appendSentence(out, body);
  }
  if (valid & (kValidPosition | kValidDepth)) {
    body = "PIXSE,POSITI,";
    appendFixed(body, state.latitude_deg, 8, -90.0, 90.0);
    body += ',';
    appendFixed(body, state.longitude_deg, 8, -180.0, 180.0);
    body += ',';
    appendFixed(body, -state.depth_m, 3, kMinAltitudeM, kMaxAltitudeM);
    appendSentence(out, body);
  }
  if (valid & kValidVelocity) {
    body = "PIXSE,SPEED_,";
    appendFixed(body, state.velocity_east_m_s, 3, -kMaxSpeedM_s, kMaxSpeedM_s);
    body += ',';
    appendFixed(body, state.velocity_north_m_s, 3, -kMaxSpeedM_s, kMaxSpeedM_s);
    body += ',';
    appendFixed(body, -state.velocity_down_m_s, 3, -kMaxSpeedM_s, kMaxSpeedM_s);
    appendSentence(out, body);
  }

  // Floor division so times before 1970 still give a time of day in [0, 24 h).
  int64_t days = state.utime_us / kMicrosecondsPerDay;
  int64_t time_of_day_us = state.utime_us % kMicrosecondsPerDay;
  if (time_of_day_us < 0) {
    time_of_day_us += kMicrosecondsPerDay;
    --days;
  }
  body = "PIXSE,TIME__,";
  appendTimeOfDay(body, time_of_day_us, 6);
  appendSentence(out, body);

  if (valid & kValidAttitudeStd) {
    body = "PIXSE,STDHRP,";
    appendFixed(body, state.heading_std_rad * kRadToDeg, 3, 0.0, kMaxAngleStdDeg);
    body += ',';
    appendFixed(body, state.roll_std_rad * kRadToDeg, 3, 0.0, kMaxAngleStdDeg);
    body += ',';
    appendFixed(body, state.pitch_std_rad * kRadToDeg, 3, 0.0, kMaxAngleStdDeg);
    appendSentence(out, body);
  }
  if (valid & kValidPositionStd) {
    body = "PIXSE,STDPOS,";
    appendFixed(body, state.latitude_std_m, 2, 0.0, kMaxPositionStdM);
    body += ',';
    appendFixed(body, state.longitude_std_m, 2, 0.0, kMaxPositionStdM);
    body += ',';
    appendFixed(body, state.depth_std_m, 2, 0.0, kMaxPositionStdM);
    appendSentence(out, body);
  }
  if (valid & kValidVelocityStd) {
    body = "PIXSE,STDSPD,";
    appendFixed(body, state.velocity_east_std_m_s, 3, 0.0, kMaxSpeedStdM_s);
    body += ',';
    appendFixed(body, state.velocity_north_std_m_s, 3, 0.0, kMaxSpeedStdM_s);
    body += ',';
    appendFixed(body, state.velocity_down_std_m_s, 3, 0.0, kMaxSpeedStdM_s);
    appendSentence(out, body);
  }
  if ((valid & kValidAltitude) && state.altitude_m >= 0.0) {
    body = "SDDPT,";
    appendFixed(body, state.altitude_m, 3, 0.0, kMaxDvlRangeM);
    body += ",0.000";
    appendSentence(out, body);
  }

  int year = 0, month = 0, day = 0;
  civilFromDays(days, year, month, day);
  year = std::clamp(year, kMinYear, kMaxYear);  // a garbage utime must still give a valid ZDA
  body = "INZDA,";
  appendTimeOfDay(body, time_of_day_us, 2);
  body += ',';
  appendTwoDigits(body, day);
  body += ',';
  appendTwoDigits(body, month);
  body += ',';
  body += std::to_string(year);
  body += ",00,00";
  appendSentence(out, body);

  body = "PIXSE,ALGSTS,";
  appendHex8(body, 0);
  body += ',';
  appendHex8(body, 0);
  appendSentence(out, body);
  body = "PIXSE,STATUS,";
  appendHex8(body, 0);
  body += ',';
  appendHex8(body, 0);
  appendSentence(out, body);
  return out;
}

}  // namespace sss::ins
