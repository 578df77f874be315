// Building blocks shared by the optimiser's checkpoints (pose graph, engine): versioned text with
// exact doubles, an FNV-1a checksum line, atomic writes (temporary file, fsync, rename) and bounded reads.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "pipeline/core/pose.hpp"
#include "pipeline/core/status.hpp"

namespace sss::optimiser::checkpoint {

constexpr uint64_t kFnvOffsetBasis = 1469598103934665603ull;
// FNV-1a over data, continuing from `hash` (so a record can be hashed in pieces).
uint64_t fnv1a(const void* data, size_t size, uint64_t hash = kFnvOffsetBasis);

// Space-separated tokens, one record per line; doubles and floats in their shortest exact form.
class TextWriter {
 public:
  void word(const char* w);
  void integer(int64_t v);
  void unsignedInteger(uint64_t v);
  void real(double v);
  void single(float v);
  void pose(const sss::core::Pose& p);
  void matrix(const Eigen::MatrixXd& m);
  void endLine();
  // Raw bytes at the start of a line (an embedded section); must end with a newline.
  void raw(const std::string& bytes);
  std::string& text() { return text_; }

 private:
  void separate();
  std::string text_;
  bool at_line_start_ = true;
};

// Reads what TextWriter wrote; every method returns false on a missing or malformed token.
class TextReader {
 public:
  explicit TextReader(const std::string& text) : text_(text) {}
  bool token(std::string& out);
  bool expect(const char* word);
  bool integer(int64_t& v);
  bool unsignedInteger(uint64_t& v);
  bool boundedInt(int& v, int64_t min, int64_t max);
  bool real(double& v);  // any double, NaN and infinities included
  bool finite(double& v);
  bool single(float& v);  // any float, NaN included
  bool pose(sss::core::Pose& p);  // finite with a unit quaternion
  bool matrix(Eigen::MatrixXd& m, int rows, int cols);  // finite
  bool matrix6(sss::core::Matrix6d& m);
  // The `size` bytes after the newline that ends the current line (an embedded section).
  bool raw(size_t size, std::string& out);
  // Upper bound of the records of `tokens_per_record` tokens that could still follow: guards
  // allocations against a corrupt count.
  size_t remainingRecords(size_t tokens_per_record) const;

 private:
  const std::string& text_;
  size_t pos_ = 0;
};

// Appends "checksum <16 hex digits>\n" over every byte of text.
void appendChecksum(std::string& text);
// Reads the whole file (at most max_bytes), checks its last line "checksum ..." and returns the
// text before it; an error ("cannot open: ...", "checksum mismatch: ...") otherwise.
sss::core::Result<std::string> readChecked(const std::string& path, size_t max_bytes);
// Whole files are replaced with sss::core::writeFileAtomically (pipeline/core/state_file.hpp).

}  // namespace sss::optimiser::checkpoint
