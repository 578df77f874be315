// Checkpoint text, checksums and atomic file writes, see checkpoint_io.hpp.
#include "pipeline/optimiser/checkpoint_io.hpp"

#include <unistd.h>

#include <charconv>
#include <cctype>
#include <cerrno>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include "pipeline/optimiser/pose_manifold.hpp"

namespace sss::optimiser::checkpoint {

uint64_t fnv1a(const void* data, size_t size, uint64_t hash) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    hash ^= bytes[i];
    hash *= 1099511628211ull;
  }
  return hash;
}

// ---- TextWriter ----------------------------------------------------------------------------------

void TextWriter::separate() {
  if (!at_line_start_) text_ += ' ';
  at_line_start_ = false;
}
void TextWriter::word(const char* w) {
  separate();
  text_ += w;
}
void TextWriter::integer(int64_t v) {
  separate();
  text_ += std::to_string(v);
}
void TextWriter::unsignedInteger(uint64_t v) {
  separate();
  text_ += std::to_string(v);
}
// Shortest text that reads back to the same bits (std::to_chars): exact like "%.17g", several
// times faster and shorter, which is most of a checkpoint save's time. NaN and inf as strtod reads them.
template <typename T>
void appendShortest(std::string& text, T v) {
  char buffer[64];
  const std::to_chars_result result = std::to_chars(buffer, buffer + sizeof(buffer), v);
  text.append(buffer, result.ptr);
}
void TextWriter::real(double v) {
  separate();
  appendShortest(text_, v);
}
void TextWriter::single(float v) {
  separate();
  appendShortest(text_, v);
}
void TextWriter::pose(const sss::core::Pose& p) {
  for (double v : toParameters(p)) real(v);
}
void TextWriter::matrix(const Eigen::MatrixXd& m) {
  for (int r = 0; r < m.rows(); ++r)
    for (int c = 0; c < m.cols(); ++c) real(m(r, c));
}
void TextWriter::endLine() {
  text_ += '\n';
  at_line_start_ = true;
}
void TextWriter::raw(const std::string& bytes) {
  text_ += bytes;
  at_line_start_ = true;
}

// ---- TextReader ----------------------------------------------------------------------------------

bool TextReader::token(std::string& out) {
  while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  if (pos_ >= text_.size()) return false;
  const size_t start = pos_;
  while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  out.assign(text_, start, pos_ - start);
  return true;
}
bool TextReader::expect(const char* word) {
  std::string t;
  return token(t) && t == word;
}
bool TextReader::integer(int64_t& v) {
  std::string t;
  if (!token(t)) return false;
  errno = 0;
  char* end = nullptr;
  const long long parsed = std::strtoll(t.c_str(), &end, 10);
  if (errno != 0 || end != t.c_str() + t.size() || t.empty()) return false;
  v = parsed;
  return true;
}
bool TextReader::unsignedInteger(uint64_t& v) {
  std::string t;
  if (!token(t) || t.empty() || t[0] == '-') return false;
  errno = 0;
  char* end = nullptr;
  const unsigned long long parsed = std::strtoull(t.c_str(), &end, 10);
  if (errno != 0 || end != t.c_str() + t.size()) return false;
  v = parsed;
  return true;
}
bool TextReader::boundedInt(int& v, int64_t min, int64_t max) {
  int64_t parsed = 0;
  if (!integer(parsed) || parsed < min || parsed > max) return false;
  v = static_cast<int>(parsed);
  return true;
}
bool TextReader::real(double& v) {
  std::string t;
  if (!token(t)) return false;
  char* end = nullptr;
  const double parsed = std::strtod(t.c_str(), &end);
  if (end != t.c_str() + t.size() || t.empty()) return false;
  v = parsed;
  return true;
}
bool TextReader::finite(double& v) { return real(v) && std::isfinite(v); }
bool TextReader::single(float& v) {
  std::string t;
  if (!token(t)) return false;
  char* end = nullptr;
  const float parsed = std::strtof(t.c_str(), &end);
  if (end != t.c_str() + t.size() || t.empty()) return false;
  v = parsed;
  return true;
}
bool TextReader::pose(sss::core::Pose& p) {
  double x[kPoseAmbientSize];
  for (double& v : x)
    if (!finite(v)) return false;
  p = fromParameters(x);
  return std::abs(p.rotation.norm() - 1.0) < 1e-6;
}
bool TextReader::matrix(Eigen::MatrixXd& m, int rows, int cols) {
  m.resize(rows, cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      if (!finite(m(r, c))) return false;
  return true;
}
bool TextReader::matrix6(sss::core::Matrix6d& m) {
  Eigen::MatrixXd d;
  if (!matrix(d, 6, 6)) return false;
  m = d;
  return true;
}
bool TextReader::raw(size_t size, std::string& out) {
  // The rest of the current line must be empty, then exactly `size` bytes follow.
  while (pos_ < text_.size() && text_[pos_] != '\n' && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  if (pos_ >= text_.size() || text_[pos_] != '\n') return false;
  ++pos_;
  if (size > text_.size() - pos_) return false;
  out.assign(text_, pos_, size);
  pos_ += size;
  return true;
}
size_t TextReader::remainingRecords(size_t tokens_per_record) const {
  return (text_.size() - pos_) / (2 * tokens_per_record) + 1;
}

// ---- files ---------------------------------------------------------------------------------------

void appendChecksum(std::string& text) {
  char line[64];
  std::snprintf(line, sizeof(line), "checksum %016" PRIx64 "\n", fnv1a(text.data(), text.size()));
  text += line;
}

sss::core::Result<std::string> readChecked(const std::string& path, size_t max_bytes) {
  using sss::core::Status;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return Status::error(std::string("cannot open: ") + std::strerror(errno));
  }
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0 || static_cast<uint64_t>(size) > max_bytes) {
    return Status::error("unreadable size or larger than " + std::to_string(max_bytes) + " bytes");
  }
  in.seekg(0, std::ios::beg);
  std::string text(static_cast<size_t>(size), '\0');
  if (!in.read(text.data(), size)) {
    return Status::error("read failed");
  }
  // Checksum line: the last line, over every byte before it.
  const size_t line = text.rfind("checksum ");
  if (line == std::string::npos || (line > 0 && text[line - 1] != '\n')) {
    return Status::error("no checksum line (truncated?)");
  }
  const std::string checksum_line = text.substr(line);
  uint64_t stored = 0;
  char tail = 0;
  if (std::sscanf(checksum_line.c_str(), "checksum %16" SCNx64 "%c", &stored, &tail) != 2 || tail != '\n' ||
      checksum_line.size() != 9 + 16 + 1) {
    return Status::error("malformed checksum line (truncated?)");
  }
  if (fnv1a(text.data(), line) != stored) {
    return Status::error("checksum mismatch: the file is corrupt");
  }
  text.resize(line);
  return text;
}


}  // namespace sss::optimiser::checkpoint
