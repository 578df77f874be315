// The matcher's state directory: subframe files (binary, exact, checksummed) and the state file
// (versioned text, "%.17g" doubles round-trip exactly, checksum line). See matcher_state.hpp.
#include "pipeline/matcher/matcher_state.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "pipeline/core/state_file.hpp"

namespace sss::matcher {
namespace {

namespace fs = std::filesystem;
using sss::core::Pose;

// Subframe files hold native integers and floats: every target of the project (x86-64, arm64) is
// little-endian, and the magic would not save a big-endian reader anyway.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "subframe files are little-endian");

constexpr char kSubframeMagic[16] = {'s', 's', 's', '-', 's', 'u', 'b', 'f', 'r', 'a', 'm', 'e', ' ', 'v', '1', '\n'};
constexpr const char* kStateMagic = "sss-matcher-state";
constexpr int kStateVersion = 1;
constexpr size_t kPingBytes = 2 * 8 + 7 * 8 + 2 * 8;  // times, pose, altitude, distance
constexpr size_t kHeaderBytes = 8 + 4 * 4 + 2 * 8 + 7 * 8;
constexpr size_t kChecksumBytes = 8;
// Far above any subframe (200 pings x 2 x 3000 bins is 6 MB) and any state (240 subframes with a
// few pairs each is ~100 kB); a larger file is corrupt, and is not read into memory.
constexpr uintmax_t kMaxSubframeFileBytes = uintmax_t{256} << 20;
constexpr uintmax_t kMaxStateFileBytes = uintmax_t{64} << 20;

class Fnv1a {
 public:
  void add(const void* data, size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < size; ++i) {
      hash_ ^= bytes[i];
      hash_ *= 1099511628211ull;
    }
  }
  uint64_t value() const { return hash_; }

 private:
  uint64_t hash_ = 1469598103934665603ull;
};

sss::core::Result<std::string> readWholeFile(const std::string& path, uintmax_t max_bytes) {
  using sss::core::Status;
  std::error_code ec;
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) {
    return Status::error(path + ": cannot read: " + ec.message());
  }
  if (size > max_bytes) {
    return Status::error(path + ": " + std::to_string(size) + " bytes, more than the " + std::to_string(max_bytes) +
                         " limit");
  }
  FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) {
    return Status::error(path + ": cannot open: " + std::strerror(errno));
  }
  std::string contents(static_cast<size_t>(size), '\0');
  const size_t got = std::fread(contents.data(), 1, contents.size(), file);
  std::fclose(file);
  if (got != contents.size()) {
    return Status::error(path + ": read " + std::to_string(got) + " of " + std::to_string(size) + " bytes");
  }
  return contents;
}

// ---- subframe files -------------------------------------------------------------------------------

// Bit for bit as written: Pose's constructor would normalise the quaternion again, and a restored
// pose must equal the saved one exactly (the same matches, no spurious re-association).
Pose exactPose(const double (&v)[7]) {
  Pose p;
  p.rotation = Eigen::Quaterniond(v[0], v[1], v[2], v[3]);
  p.translation = Eigen::Vector3d(v[4], v[5], v[6]);
  return p;
}

class BinaryWriter {
 public:
  explicit BinaryWriter(FILE* file) : file_(file) {}
  void bytes(const void* data, size_t size) {
    if (size == 0) return;
    hash_.add(data, size);
    ok_ = ok_ && std::fwrite(data, 1, size, file_) == size;
  }
  template <typename T>
  void value(T v) {
    bytes(&v, sizeof v);
  }
  void pose(const Pose& p) {
    for (double v : {p.rotation.w(), p.rotation.x(), p.rotation.y(), p.rotation.z(), p.translation.x(),
                     p.translation.y(), p.translation.z()})
      value(v);
  }
  bool finish() {  // the checksum of everything before it, not itself hashed
    const uint64_t checksum = hash_.value();
    ok_ = ok_ && std::fwrite(&checksum, 1, sizeof checksum, file_) == sizeof checksum;
    return ok_;
  }

 private:
  FILE* file_;
  Fnv1a hash_;
  bool ok_ = true;
};

class BinaryReader {
 public:
  BinaryReader(const char* data, size_t size) : data_(data), left_(size) {}
  void bytes(void* out, size_t size) {
    if (size > left_) throw std::out_of_range("past the end");  // sizes are checked first: a bug
    std::memcpy(out, data_, size);
    data_ += size;
    left_ -= size;
  }
  template <typename T>
  T value() {
    T v;
    bytes(&v, sizeof v);
    return v;
  }
  Pose pose() {
    double v[7];
    for (double& x : v) x = value<double>();
    return exactPose(v);
  }

 private:
  const char* data_;
  size_t left_;
};

sss::core::Result<sss::core::Subframe> parseSubframeFile(const std::string& contents, const std::string& path,
                                                        int64_t expected_id) {
  using sss::core::Status;
  const size_t size = contents.size();
  if (size < sizeof kSubframeMagic + kHeaderBytes + kChecksumBytes ||
      std::memcmp(contents.data(), kSubframeMagic, sizeof kSubframeMagic) != 0) {
    return Status::error(path + ": not a subframe file (" + std::to_string(size) +
                         " bytes, magic 'sss-subframe v1' expected)");
  }
  BinaryReader in(contents.data() + sizeof kSubframeMagic, size - sizeof kSubframeMagic);
  sss::core::Subframe subframe;
  subframe.id = in.value<int64_t>();
  subframe.line_id = in.value<int32_t>();
  subframe.centre_ping_index = in.value<int32_t>();
  const int32_t rows = in.value<int32_t>();
  subframe.geometry.bins_per_side = in.value<int32_t>();
  subframe.geometry.bin_size_m = in.value<double>();
  subframe.geometry.first_bin_range_m = in.value<double>();
  subframe.geometry.T_body_sonar = in.pose();
  // Sizes before allocating: a flipped size must not ask for gigabytes.
  const int32_t bins = subframe.geometry.bins_per_side;
  if (rows < 2 || rows > 1000000 || bins < 1 || bins > 1000000) {
    return Status::error(path + ": implausible sizes (" + std::to_string(rows) + " pings, " + std::to_string(bins) +
                         " bins per side)");
  }
  const size_t pixels = static_cast<size_t>(rows) * 2 * static_cast<size_t>(bins);
  const size_t expected_size = sizeof kSubframeMagic + kHeaderBytes + static_cast<size_t>(rows) * kPingBytes +
                               pixels * (sizeof(float) + 1) + kChecksumBytes;
  if (size != expected_size) {
    return Status::error(path + ": " + std::to_string(size) + " bytes where its header (" + std::to_string(rows) +
                         " pings, " + std::to_string(bins) + " bins per side) needs " + std::to_string(expected_size) +
                         " (truncated?)");
  }
  Fnv1a hash;
  hash.add(contents.data(), size - kChecksumBytes);
  uint64_t stored_checksum = 0;
  std::memcpy(&stored_checksum, contents.data() + size - kChecksumBytes, kChecksumBytes);
  if (hash.value() != stored_checksum) {
    return Status::error(path + ": checksum mismatch (corrupt bytes)");
  }
  if (subframe.id != expected_id || subframe.centre_ping_index < 0 || subframe.centre_ping_index >= rows) {
    return Status::error(path + ": holds subframe " + std::to_string(subframe.id) + " with centre ping " +
                         std::to_string(subframe.centre_ping_index) + " of " + std::to_string(rows));
  }
  subframe.pings.resize(static_cast<size_t>(rows));
  for (sss::core::SubframePing& ping : subframe.pings) {
    ping.utime_us = in.value<int64_t>();
    ping.ping_number = in.value<int64_t>();
    ping.T_world_body = in.pose();
    ping.altitude_m = in.value<double>();
    ping.distance_travelled_m = in.value<double>();
  }
  subframe.image.resize(pixels);
  in.bytes(subframe.image.data(), pixels * sizeof(float));
  subframe.mask.resize(pixels);
  in.bytes(subframe.mask.data(), pixels);
  return subframe;
}

// ---- state file ------------------------------------------------------------------------------------

void appendPose(std::string& text, const Pose& p) {
  char buffer[48];
  for (double v : {p.rotation.w(), p.rotation.x(), p.rotation.y(), p.rotation.z(), p.translation.x(),
                   p.translation.y(), p.translation.z()}) {
    std::snprintf(buffer, sizeof buffer, " %.17g", v);
    text += buffer;
  }
}

bool parsePose(std::istringstream& in, Pose& p) {
  double v[7];
  for (double& x : v) in >> x;  // fails on nan, inf and anything not a number
  if (in.fail()) return false;
  p = exactPose(v);
  return true;
}

}  // namespace

MatcherStateStore::MatcherStateStore(std::string directory) : directory_(std::move(directory)) {}

std::string MatcherStateStore::subframePath(int64_t subframe_id) const {
  return directory_ + "/subframes/" + std::to_string(subframe_id) + ".subframe";
}

std::string MatcherStateStore::statePath() const { return directory_ + "/matcher.state"; }

sss::core::Status MatcherStateStore::open() {
  std::error_code ec;
  fs::create_directories(directory_ + "/subframes", ec);
  if (ec) return sss::core::Status::error(directory_ + "/subframes: cannot create: " + ec.message());
  for (const std::string& folder : {directory_, directory_ + "/subframes"}) {
    for (const auto& entry : fs::directory_iterator(folder, ec)) {
      if (entry.path().extension() == ".tmp") fs::remove(entry.path(), ec);
    }
  }
  return sss::core::Status::success();
}

sss::core::Status MatcherStateStore::writeSubframe(const sss::core::Subframe& s) {
  return sss::core::writeFileAtomically(
      subframePath(s.id),
      [&](FILE* file) {
        BinaryWriter out(file);
        out.bytes(kSubframeMagic, sizeof kSubframeMagic);
        out.value<int64_t>(s.id);
        out.value<int32_t>(s.line_id);
        out.value<int32_t>(s.centre_ping_index);
        out.value<int32_t>(s.rows());
        out.value<int32_t>(s.geometry.bins_per_side);
        out.value<double>(s.geometry.bin_size_m);
        out.value<double>(s.geometry.first_bin_range_m);
        out.pose(s.geometry.T_body_sonar);
        for (const sss::core::SubframePing& ping : s.pings) {
          out.value<int64_t>(ping.utime_us);
          out.value<int64_t>(ping.ping_number);
          out.pose(ping.T_world_body);
          out.value<double>(ping.altitude_m);
          out.value<double>(ping.distance_travelled_m);
        }
        out.bytes(s.image.data(), s.image.size() * sizeof(float));
        out.bytes(s.mask.data(), s.mask.size());
        return out.finish();
      });
}

sss::core::Status MatcherStateStore::removeSubframe(int64_t subframe_id) {
  const std::string path = subframePath(subframe_id);
  std::error_code ec;
  fs::remove(path, ec);  // false without error when there was no file
  if (ec) return sss::core::Status::error(path + ": cannot remove: " + ec.message());
  return sss::core::Status::success();
}

sss::core::Status MatcherStateStore::writeState(const MatcherState& state) {
  std::string text = std::string(kStateMagic) + " " + std::to_string(kStateVersion) + "\n";
  for (const SubframeCorrection& c : state.corrections) {
    text += "subframe " + std::to_string(c.subframe_id);
    appendPose(text, c.correction);
    text += '\n';
  }
  for (const PairRecord& p : state.pairs) {
    text += "pair " + std::to_string(p.subframe_id_a) + " " + std::to_string(p.subframe_id_b) + " " +
            std::to_string(p.rounds_done);
    appendPose(text, p.relative_at_match);
    text += '\n';
  }
  Fnv1a hash;
  hash.add(text.data(), text.size());
  char checksum[40];
  std::snprintf(checksum, sizeof checksum, "checksum %016" PRIx64 "\n", hash.value());
  text += checksum;
  return sss::core::writeFileAtomically(
      statePath(), [&](FILE* file) { return std::fwrite(text.data(), 1, text.size(), file) == text.size(); });
}

std::vector<int64_t> MatcherStateStore::subframeIds() const {
  std::vector<int64_t> ids;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(directory_ + "/subframes", ec)) {
    const fs::path& path = entry.path();
    if (path.extension() != ".subframe") continue;
    const std::string stem = path.stem().string();
    char* end = nullptr;
    errno = 0;
    const long long id = std::strtoll(stem.c_str(), &end, 10);
    // Only the names writeSubframe makes: "<id>.subframe" with the id in canonical form.
    if (errno == 0 && !stem.empty() && *end == '\0' && std::to_string(id) == stem) ids.push_back(id);
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

sss::core::Result<std::optional<sss::core::Subframe>> MatcherStateStore::readSubframe(int64_t subframe_id) const {
  const std::string path = subframePath(subframe_id);
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::optional<sss::core::Subframe>{};
  const sss::core::Result<std::string> contents = readWholeFile(path, kMaxSubframeFileBytes);
  if (!contents) return contents.status();
  sss::core::Result<sss::core::Subframe> subframe = parseSubframeFile(*contents, path, subframe_id);
  if (!subframe) return subframe.status();
  return std::optional<sss::core::Subframe>(std::move(*subframe));
}

sss::core::Result<std::optional<MatcherState>> MatcherStateStore::readState() const {
  using sss::core::Status;
  const std::string path = statePath();
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::optional<MatcherState>{};
  const sss::core::Result<std::string> read = readWholeFile(path, kMaxStateFileBytes);
  if (!read) return read.status();
  const std::string& text = *read;
  // The checksum line is the last one and covers every byte before it.
  const size_t checksum_at = text.rfind("checksum ");
  unsigned long long stored_checksum = 0;
  char tail = '\0';
  if (checksum_at == std::string::npos || (checksum_at > 0 && text[checksum_at - 1] != '\n') ||
      std::sscanf(text.c_str() + checksum_at, "checksum %16llx%c", &stored_checksum, &tail) != 2 || tail != '\n' ||
      checksum_at + 26 != text.size()) {
    return Status::error(path + ": no checksum line at the end (truncated?)");
  }
  Fnv1a hash;
  hash.add(text.data(), checksum_at);
  if (hash.value() != stored_checksum) {
    return Status::error(path + ": checksum mismatch (corrupt bytes)");
  }
  std::istringstream lines(text.substr(0, checksum_at));
  std::string line;
  std::getline(lines, line);
  if (line != std::string(kStateMagic) + " " + std::to_string(kStateVersion)) {
    return Status::error(path + ": first line '" + line.substr(0, 40) + "', expected '" + kStateMagic + " " +
                         std::to_string(kStateVersion) + "'");
  }
  MatcherState state;
  for (int number = 2; std::getline(lines, line); ++number) {
    std::istringstream in(line);
    std::string keyword;
    in >> keyword;
    bool ok = false;
    if (keyword == "subframe") {
      SubframeCorrection c;
      in >> c.subframe_id;
      ok = parsePose(in, c.correction);
      if (ok) state.corrections.push_back(c);
    } else if (keyword == "pair") {
      PairRecord p;
      in >> p.subframe_id_a >> p.subframe_id_b >> p.rounds_done;
      ok = parsePose(in, p.relative_at_match) && p.rounds_done >= 0;
      if (ok) state.pairs.push_back(p);
    }
    in >> std::ws;
    if (!ok || !in.eof()) {
      return Status::error(path + ": line " + std::to_string(number) + " not understood: '" + line.substr(0, 80) + "'");
    }
  }
  return std::optional<MatcherState>(std::move(state));
}

}  // namespace sss::matcher
