// NMEA 0183 framing from an arbitrary byte stream (UDP datagrams, TCP pieces, file reads): yields
// checksum-verified sentence bodies, resynchronises at the next '$' and counts every rejection.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace sss::ins {

struct NmeaStreamOptions {
  // NMEA 0183 allows 82 characters; iXblue long sentences and NMEA 4 tag blocks stay well
  // below this. A longer line is corrupt (lost terminator): drop it, resync at the next '$'.
  size_t max_sentence_bytes = 256;
};

struct NmeaStreamCounters {
  int64_t bytes = 0;             // all bytes fed
  int64_t sentences = 0;         // accepted (checksum verified)
  int64_t bad_checksum = 0;      // checksum mismatch or a malformed "*HH"
  int64_t missing_checksum = 0;  // terminated without '*HH'
  int64_t overlong = 0;          // longer than max_sentence_bytes
  int64_t bad_character = 0;     // NUL, control or non-ASCII byte inside a sentence
  int64_t truncated = 0;         // a new '$' arrived before the sentence was terminated
  int64_t garbage_bytes = 0;     // bytes outside sentences, other than CR/LF
};

// The first error message of each kind, so the caller logs each kind once (empty: none yet).
struct NmeaStreamFirstErrors {
  std::string bad_checksum, missing_checksum, overlong, bad_character, truncated, garbage;
};

class NmeaStreamParser {
 public:
  explicit NmeaStreamParser(const NmeaStreamOptions& options = {});

  // Appends the body (between '$' and '*') of every complete, verified sentence in this chunk
  // to `sentences`. A sentence split across chunks completes in a later call. CR, LF, CRLF and
  // LFCR all terminate a sentence.
  void feed(const uint8_t* data, size_t size, std::vector<std::string>& sentences);
  std::vector<std::string> feed(std::string_view bytes);

  // Terminates a pending unterminated sentence (end of a UDP datagram that omits CR/LF, end of
  // file) and appends it if it verifies.
  void flush(std::vector<std::string>& sentences);

  const NmeaStreamCounters& counters() const { return counters_; }
  const NmeaStreamFirstErrors& firstErrors() const { return first_errors_; }
  // Sum of all rejection counts (not counting garbage bytes).
  int64_t rejectedSentences() const;

 private:
  void finishSentence(std::vector<std::string>& sentences);
  void reject(int64_t& counter, std::string& first_error, const std::string& text);
  std::string where() const;

  NmeaStreamOptions options_;
  NmeaStreamCounters counters_;
  NmeaStreamFirstErrors first_errors_;
  bool in_sentence_ = false;
  std::string buffer_;        // bytes after '$' of the current sentence
  int64_t sentence_start_ = 0;  // stream offset of the current sentence's '$'
  bool in_garbage_run_ = false;  // one garbage message per run, not per byte
};

}  // namespace sss::ins
