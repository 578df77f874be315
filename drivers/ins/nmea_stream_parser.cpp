// NMEA 0183 stream framing: a small state machine over bytes (outside / inside a sentence) with
// hard length limits, so no input can grow memory or stall the stream past the next '$'.
#include "drivers/ins/nmea_stream_parser.hpp"

#include "drivers/ins/ixblue_nmea.hpp"

namespace sss::ins {
namespace {

int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

std::string printable(std::string_view text) {
  constexpr size_t kMaxShown = 40;
  std::string out(text.substr(0, kMaxShown));
  if (text.size() > kMaxShown) out += "...";
  return out;
}

}  // namespace

NmeaStreamParser::NmeaStreamParser(const NmeaStreamOptions& options) : options_(options) {
  if (options_.max_sentence_bytes < 8) options_.max_sentence_bytes = 8;
  buffer_.reserve(options_.max_sentence_bytes);
}

std::string NmeaStreamParser::where() const {
  return "NMEA sentence at byte " + std::to_string(sentence_start_);
}

void NmeaStreamParser::reject(int64_t& counter, std::string& first_error,
                              const std::string& text) {
  ++counter;
  if (first_error.empty()) first_error = text;
}

int64_t NmeaStreamParser::rejectedSentences() const {
  return counters_.bad_checksum + counters_.missing_checksum + counters_.overlong +
         counters_.bad_character + counters_.truncated;
}

void NmeaStreamParser::feed(const uint8_t* data, size_t size,
                            std::vector<std::string>& sentences) {
  for (size_t i = 0; i < size; ++i) {
    const uint8_t byte = data[i];
    const int64_t offset = counters_.bytes++;
    if (byte == '$') {
      if (in_sentence_) {
        reject(counters_.truncated, first_errors_.truncated,
               where() + ": a new '$' at byte " + std::to_string(offset) +
                   " before the end of line; partial sentence \"" + printable(buffer_) +
                   "\" dropped");
      }
      in_sentence_ = true;
      in_garbage_run_ = false;
      buffer_.clear();
      sentence_start_ = offset;
      continue;
    }
    if (!in_sentence_) {
      if (byte == '\r' || byte == '\n') continue;
      ++counters_.garbage_bytes;
      if (!in_garbage_run_ && first_errors_.garbage.empty()) {
        first_errors_.garbage = "NMEA stream at byte " + std::to_string(offset) +
                                ": bytes outside a sentence; skipping to the next '$'";
      }
      in_garbage_run_ = true;
      continue;
    }
    if (byte == '\r' || byte == '\n') {
      finishSentence(sentences);
      continue;
    }
    if (byte < 0x20 || byte > 0x7E) {
      reject(counters_.bad_character, first_errors_.bad_character,
             where() + ": byte 0x" + std::string(1, "0123456789ABCDEF"[byte >> 4]) +
                 std::string(1, "0123456789ABCDEF"[byte & 0xF]) + " at byte " +
                 std::to_string(offset) +
                 " is not printable ASCII; sentence dropped, resyncing at the next '$'");
      in_sentence_ = false;
      in_garbage_run_ = true;
      buffer_.clear();
      continue;
    }
    // '$' and the terminator are not stored, so the body limit is the line limit minus 3.
    if (buffer_.size() + 3 >= options_.max_sentence_bytes) {
      reject(counters_.overlong, first_errors_.overlong,
             where() + ": longer than " + std::to_string(options_.max_sentence_bytes) +
                 " bytes (lost line end?); dropped, resyncing at the next '$'");
      in_sentence_ = false;
      in_garbage_run_ = true;
      buffer_.clear();
      continue;
    }
    buffer_.push_back(static_cast<char>(byte));
  }
}

std::vector<std::string> NmeaStreamParser::feed(std::string_view bytes) {
  std::vector<std::string> sentences;
  feed(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), sentences);
  return sentences;
}

void NmeaStreamParser::flush(std::vector<std::string>& sentences) {
  if (in_sentence_) finishSentence(sentences);
  in_garbage_run_ = false;
}

void NmeaStreamParser::finishSentence(std::vector<std::string>& sentences) {
  in_sentence_ = false;
  const size_t star = buffer_.find('*');
  if (star == std::string::npos) {
    reject(counters_.missing_checksum, first_errors_.missing_checksum,
           where() + ": \"" + printable(buffer_) + "\" has no '*HH' checksum; dropped");
    buffer_.clear();
    return;
  }
  const std::string_view body(buffer_.data(), star);
  const std::string_view tail = std::string_view(buffer_).substr(star + 1);
  const int high = tail.size() == 2 ? hexValue(tail[0]) : -1;
  const int low = tail.size() == 2 ? hexValue(tail[1]) : -1;
  if (high < 0 || low < 0) {
    reject(counters_.bad_checksum, first_errors_.bad_checksum,
           where() + ": checksum field \"*" + printable(tail) +
               "\" is not two hex digits; dropped");
    buffer_.clear();
    return;
  }
  const int expected = nmeaChecksum(body);
  if (high * 16 + low != expected) {
    static const char kHex[] = "0123456789ABCDEF";
    reject(counters_.bad_checksum, first_errors_.bad_checksum,
           where() + ": checksum *" + std::string(tail) + " does not match computed " +
               kHex[expected >> 4] + kHex[expected & 0xF] + " for \"" + printable(body) +
               "\"; dropped");
    buffer_.clear();
    return;
  }
  ++counters_.sentences;
  sentences.emplace_back(body);
  buffer_.clear();
}

}  // namespace sss::ins
