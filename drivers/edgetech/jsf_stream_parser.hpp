// JSF framing over a byte stream (TCP from the sonar processor, or a file): finds messages by
// their 16-byte header, resynchronises after garbage, bad start markers, impossible byte counts
// and truncated messages, counts each kind of fault, and never holds more than one maximal
// message in memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "drivers/edgetech/jsf_format.hpp"

namespace sss::edgetech {

struct JsfMessage {
  JsfMessageHeader header;
  std::vector<uint8_t> body;     // byte_count bytes after the header
  uint64_t stream_offset = 0;    // byte offset of the header in the stream
};

struct JsfParserCounters {
  uint64_t messages = 0;             // framed messages handed out
  uint64_t bytes_skipped = 0;        // bytes between messages that belong to none
  uint64_t bad_headers = 0;          // a start marker whose header is impossible (byte count, fields)
  uint64_t truncated_messages = 0;   // a message cut short by the start of the next one
  uint64_t resyncs = 0;              // times the parser had to search for the next header
};

struct JsfParserOptions {
  int32_t max_body_bytes = kMaxJsfBodyBytes;  // larger byte counts are corrupt, never allocated
};

class JsfStreamParser {
 public:
  explicit JsfStreamParser(JsfParserOptions options = {});

  // Appends bytes and moves every complete message to out.
  void feed(const uint8_t* data, size_t size, std::vector<JsfMessage>& out);
  // End of stream: a message still waiting for its look-ahead is handed out, a partial one is
  // counted as truncated.
  void finish(std::vector<JsfMessage>& out);

  const JsfParserCounters& counters() const { return counters_; }
  // Describes the first fault of each kind (empty when none since the last call); for logging
  // once per kind.
  std::vector<std::string> takeNewFaultMessages();

 private:
  enum class Framing { kNeedMore, kEmitted, kSkipped };
  Framing frameOne(std::vector<JsfMessage>& out, bool end_of_stream);
  bool plausibleHeader(const JsfMessageHeader& header) const;
  bool plausibleHeaderAt(size_t position) const;
  // Position of the first plausible header in (from, to], or npos.
  size_t findPlausibleHeader(size_t from, size_t to) const;
  // Sonar data (80) and older side-scan (82) describe their own size: the header, then samples.
  static bool sonarHeaderAvailable(const JsfMessageHeader& header, size_t body_bytes);
  static bool sonarSizeConsistent(const JsfMessageHeader& header, const uint8_t* body);
  void skip(size_t count);
  void beginSkipping(const std::string& kind, const std::string& message);
  void reportOnce(const std::string& kind, const std::string& message);

  JsfParserOptions options_;
  std::vector<uint8_t> buffer_;
  size_t start_ = 0;             // first unconsumed byte in buffer_
  uint64_t consumed_offset_ = 0; // stream offset of buffer_[start_]
  bool skipping_ = false;        // inside a run of skipped bytes (count one resync per run)
  JsfParserCounters counters_;
  std::vector<std::string> reported_kinds_;
  std::vector<std::string> new_faults_;
};

}  // namespace sss::edgetech
