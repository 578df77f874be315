// TUM trajectory reading and writing. See trajectory_io.hpp.
#include "tools/eval/trajectory_io.hpp"

#include "tools/eval/frame_alignment.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace sss::eval {
namespace {

// Largest |seconds| whose microseconds fit in int64 with room to spare.
constexpr int64_t kMaxSeconds = 9'000'000'000'000LL;

std::vector<std::string> splitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  for (char c : line) {
    if (c == ' ' || c == '\t' || c == ',' || c == '\r') {
      if (!field.empty()) fields.push_back(field);
      field.clear();
    } else {
      field += c;
    }
  }
  if (!field.empty()) fields.push_back(field);
  return fields;
}

bool parseDouble(const std::string& text, double& value) {
  char* end = nullptr;
  errno = 0;
  value = std::strtod(text.c_str(), &end);
  return end != text.c_str() && *end == '\0' && errno != ERANGE && std::isfinite(value);
}

std::string shorten(const std::string& line) {
  std::string shown = line.size() > 80 ? line.substr(0, 77) + "..." : line;
  for (char& c : shown) {
    const unsigned char byte = static_cast<unsigned char>(c);
    if (byte < 32) c = ' ';
    if (byte >= 127) c = '?';  // keep the message printable whatever the file holds
  }
  return shown;
}

std::string secondsText(int64_t utime_us) {
  char text[48];
  const long long whole = utime_us / 1000000;
  const long long fraction = std::llabs(utime_us % 1000000);
  std::snprintf(text, sizeof text, "%s%lld.%06lld", (utime_us < 0 && whole == 0) ? "-" : "", whole, fraction);
  return text;
}

}  // namespace

bool parseTumTimestamp(const std::string& text, int64_t& utime_us) {
  // Exact path for plain decimals: [-+]digits[.digits].
  size_t i = 0;
  bool negative = false;
  if (i < text.size() && (text[i] == '-' || text[i] == '+')) negative = text[i++] == '-';
  int64_t seconds = 0;
  size_t integer_digits = 0;
  while (i < text.size() && text[i] >= '0' && text[i] <= '9') {
    if (seconds > kMaxSeconds) return false;
    seconds = seconds * 10 + (text[i++] - '0');
    ++integer_digits;
  }
  int64_t micros = 0;
  size_t fraction_digits = 0;
  bool round_up = false;
  bool plain = true;
  if (i < text.size() && text[i] == '.') {
    ++i;
    while (i < text.size() && text[i] >= '0' && text[i] <= '9') {
      if (fraction_digits < 6) micros = micros * 10 + (text[i] - '0');
      if (fraction_digits == 6) round_up = text[i] >= '5';
      ++fraction_digits;
      ++i;
    }
  }
  if (i != text.size() || integer_digits + fraction_digits == 0) plain = false;
  if (plain) {
    if (seconds > kMaxSeconds) return false;
    for (size_t k = fraction_digits; k < 6; ++k) micros *= 10;
    const int64_t magnitude = seconds * 1000000 + micros + (round_up ? 1 : 0);
    utime_us = negative ? -magnitude : magnitude;
    return true;
  }
  double value = 0.0;
  if (!parseDouble(text, value) || std::abs(value) > static_cast<double>(kMaxSeconds)) return false;
  utime_us = std::llround(value * 1e6);
  return true;
}

TumReadResult parseTum(const std::string& text, const std::string& name, const TumReadOptions& options) {
  TumReadResult result;
  std::istringstream in(text);
  std::string line;
  size_t line_number = 0;
  size_t previous_line = 0;
  const auto fail = [&](const std::string& message) {
    result.ok = false;
    result.error = name + ":" + std::to_string(line_number) + ": " + message;
    result.poses.clear();
    return result;
  };
  while (std::getline(in, line)) {
    ++line_number;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) {
      ++result.blank_lines;
      continue;
    }
    if (line[first] == '#') {
      ++result.comment_lines;
      if (!result.origin) result.origin = sss::core::parseOriginCommentLine(line);
      continue;
    }
    const std::vector<std::string> fields = splitFields(line);
    if (fields.size() != 8) {
      return fail("expected 8 fields 'timestamp x y z qx qy qz qw', found " + std::to_string(fields.size()) +
                  " in '" + shorten(line) + "'; fix or comment out the line with '#'");
    }
    StampedPose pose;
    if (!parseTumTimestamp(fields[0], pose.utime_us)) {
      return fail("timestamp '" + shorten(fields[0]) + "' is not a finite number of seconds");
    }
    double values[7];
    for (int k = 0; k < 7; ++k) {
      if (!parseDouble(fields[k + 1], values[k])) {
        static const char* kNames[7] = {"x", "y", "z", "qx", "qy", "qz", "qw"};
        return fail(std::string("field ") + kNames[k] + " '" + shorten(fields[k + 1]) + "' is not a finite number");
      }
    }
    const Eigen::Quaterniond q(values[6], values[3], values[4], values[5]);
    const double norm = q.norm();
    if (!(std::abs(norm - 1.0) <= options.max_quaternion_norm_error)) {
      return fail("quaternion (qx qy qz qw) has norm " + std::to_string(norm) +
                  ", not 1; check the column order is 'timestamp x y z qx qy qz qw'");
    }
    pose.T_world_body = sss::core::Pose(q, Eigen::Vector3d(values[0], values[1], values[2]));
    if (!result.poses.empty() && pose.utime_us <= result.poses.back().utime_us) {
      return fail("timestamp " + secondsText(pose.utime_us) + " is not after " +
                  secondsText(result.poses.back().utime_us) + " on line " + std::to_string(previous_line) +
                  "; TUM poses must be in strictly increasing time order");
    }
    previous_line = line_number;
    result.poses.push_back(pose);
  }
  if (result.poses.empty()) {
    line_number = std::max<size_t>(line_number, 1);
    return fail("no poses (only comments or blank lines)");
  }
  if (options.target_origin && result.origin && !sameOrigin(*result.origin, *options.target_origin)) {
    reexpressTrajectory(result.poses, *result.origin, *options.target_origin);
    result.reexpressed = true;
  }
  result.ok = true;
  return result;
}

TumReadResult readTum(const std::string& path, const TumReadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    TumReadResult result;
    result.error = path + ": cannot open; check the path";
    return result;
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) {
    TumReadResult result;
    result.error = path + ": read error";
    return result;
  }
  return parseTum(text.str(), path, options);
}

std::string tumLine(const StampedPose& pose) {
  char line[256];
  const Eigen::Quaterniond& q = pose.T_world_body.rotation;
  const Eigen::Vector3d& t = pose.T_world_body.translation;
  std::snprintf(line, sizeof line, "%s %.6f %.6f %.6f %.9f %.9f %.9f %.9f\n", secondsText(pose.utime_us).c_str(), t.x(),
                t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  return line;
}

sss::core::Status writeTum(const std::string& path, const Trajectory& poses, const std::string& comment,
                           const std::optional<sss::core::MissionOrigin>& origin) {
  std::ofstream out(path, std::ios::binary);
  if (!out) return sss::core::Status::error("cannot write " + path + "; check the directory exists and is writable");
  if (!comment.empty()) {
    std::istringstream lines(comment);
    for (std::string line; std::getline(lines, line);) out << "# " << line << "\n";
  }
  if (origin) out << sss::core::originCommentLine(*origin) << "\n";
  for (const StampedPose& pose : poses) out << tumLine(pose);
  out.close();
  if (!out) return sss::core::Status::error("cannot write " + path + " (disk full?)");
  return sss::core::Status::success();
}

}  // namespace sss::eval
