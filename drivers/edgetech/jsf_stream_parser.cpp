// JSF framing with resynchronisation, see jsf_stream_parser.hpp.
//
// A message is accepted when its header is plausible (byte count within the limit; for types 80 and 82
// the sample count agrees with the byte count) and either no plausible header starts inside its
// body (a live stream hands out a ping as soon as its last byte arrives) or the bytes right
// after its body start another plausible header. A header inside the body with a failed
// look-ahead means this message was cut short: it is dropped and parsing resumes at the inner
// header, so the next good message is not lost. Deciding only on complete data means a sample
// that happens to read 0x1601 can delay a message, never drop it.
#include "drivers/edgetech/jsf_stream_parser.hpp"

#include <algorithm>
#include <cstring>

namespace sss::edgetech {

namespace {
constexpr size_t kNotFound = static_cast<size_t>(-1);
}

JsfStreamParser::JsfStreamParser(JsfParserOptions options) : options_(options) {}

bool JsfStreamParser::plausibleHeader(const JsfMessageHeader& h) const {
  if (h.byte_count < 0 || h.byte_count > options_.max_body_bytes) return false;
  if (h.protocol_version == 0) return false;
  if (h.message_type == kJsfSonarData) {
    // Side-scan and sub-bottom subsystems, port/starboard (or a single sub-bottom channel).
    const bool known_subsystem = h.subsystem == 0 || (h.subsystem >= 20 && h.subsystem <= 22);
    return known_subsystem && h.channel <= 1 && h.byte_count >= static_cast<int32_t>(kSonarDataHeaderSize);
  }
  if (h.message_type == kJsfOldSideScanData) {
    const bool known_subsystem = h.subsystem == 0 || (h.subsystem >= 20 && h.subsystem <= 22);
    return known_subsystem && h.channel <= 1 && h.byte_count >= static_cast<int32_t>(kOldSideScanHeaderSize);
  }
  return h.message_type != 0;
}

bool JsfStreamParser::sonarHeaderAvailable(const JsfMessageHeader& header, size_t body_bytes) {
  return (header.message_type == kJsfSonarData && body_bytes >= kSonarDataHeaderSize) ||
         (header.message_type == kJsfOldSideScanData && body_bytes >= kOldSideScanHeaderSize);
}

bool JsfStreamParser::sonarSizeConsistent(const JsfMessageHeader& header, const uint8_t* body) {
  if (header.message_type == kJsfOldSideScanData) {  // message 82: samples u32 at 12, format at 36
    const uint64_t samples = static_cast<uint64_t>(body[12]) | static_cast<uint64_t>(body[13]) << 8 |
                             static_cast<uint64_t>(body[14]) << 16 | static_cast<uint64_t>(body[15]) << 24;
    const uint16_t format = static_cast<uint16_t>(body[36] | body[37] << 8);
    return kOldSideScanHeaderSize + samples * (format == 1 ? 4 : 2) == static_cast<uint64_t>(header.byte_count) ||
           (format != 0 && format != 1);
  }
  const size_t num_samples = (static_cast<size_t>(body[115]) << 8 | body[114]) | (static_cast<size_t>(body[17] & 0xF) << 16);
  const int16_t format = static_cast<int16_t>(body[34] | body[35] << 8);
  const size_t bytes_per_sample = format == 1 ? 4 : 2;  // other formats: sized as 16-bit samples
  return kSonarDataHeaderSize + num_samples * bytes_per_sample == static_cast<size_t>(header.byte_count) ||
         (format != 0 && format != 1);
}

bool JsfStreamParser::plausibleHeaderAt(size_t position) const {
  if (position + kJsfHeaderSize > buffer_.size()) return false;
  const auto header = decodeHeader(buffer_.data() + position);
  if (!header || !plausibleHeader(*header)) return false;
  if (sonarHeaderAvailable(*header, buffer_.size() - position - kJsfHeaderSize)) {
    return sonarSizeConsistent(*header, buffer_.data() + position + kJsfHeaderSize);
  }
  return true;
}

size_t JsfStreamParser::findPlausibleHeader(size_t from, size_t to) const {
  const size_t last = std::min(to, buffer_.size() >= kJsfHeaderSize ? buffer_.size() - kJsfHeaderSize : 0);
  for (size_t p = from + 1; p <= last; ++p) {
    // 0x1601 little endian: 0x01 then 0x16.
    if (buffer_[p] == 0x01 && buffer_[p + 1] == 0x16 && plausibleHeaderAt(p)) return p;
  }
  return kNotFound;
}

void JsfStreamParser::skip(size_t count) {
  start_ += count;
  consumed_offset_ += count;
}

void JsfStreamParser::beginSkipping(const std::string& kind, const std::string& message) {
  if (skipping_) return;  // one resync (and one report) per run of skipped bytes
  skipping_ = true;
  ++counters_.resyncs;
  reportOnce(kind, message);
}

void JsfStreamParser::reportOnce(const std::string& kind, const std::string& message) {
  if (std::find(reported_kinds_.begin(), reported_kinds_.end(), kind) == reported_kinds_.end()) {
    reported_kinds_.push_back(kind);
    new_faults_.push_back(message);
  }
}

std::vector<std::string> JsfStreamParser::takeNewFaultMessages() {
  std::vector<std::string> faults;
  faults.swap(new_faults_);
  return faults;
}

JsfStreamParser::Framing JsfStreamParser::frameOne(std::vector<JsfMessage>& out, bool end_of_stream) {
  const size_t available = buffer_.size() - start_;
  if (available < 2) return Framing::kNeedMore;

  // Not at a start marker: skip to the next 0x01 byte that could begin one.
  if (!(buffer_[start_] == 0x01 && buffer_[start_ + 1] == 0x16)) {
    const uint8_t* next = static_cast<const uint8_t*>(std::memchr(buffer_.data() + start_ + 1, 0x01, available - 1));
    const size_t count = next ? static_cast<size_t>(next - (buffer_.data() + start_)) : available - 1;
    beginSkipping("garbage", "JSF stream at byte " + std::to_string(consumed_offset_) +
                                 ": no start marker 0x1601; skipping to the next header");
    counters_.bytes_skipped += count;
    skip(count);
    return Framing::kSkipped;
  }
  if (available < kJsfHeaderSize) return Framing::kNeedMore;

  const JsfMessageHeader header = *decodeHeader(buffer_.data() + start_);
  bool plausible = plausibleHeader(header);
  // Types 80 and 82 describe their own size: header + samples x bytes per sample must equal the byte count.
  if (plausible && sonarHeaderAvailable(header, available - kJsfHeaderSize)) {
    plausible = sonarSizeConsistent(header, buffer_.data() + start_ + kJsfHeaderSize);
  }
  if (!plausible) {
    ++counters_.bad_headers;
    beginSkipping("bad_header", "JSF message at byte " + std::to_string(consumed_offset_) + ": type " +
                                    std::to_string(header.message_type) + ", byte count " +
                                    std::to_string(header.byte_count) + " is impossible (limit " +
                                    std::to_string(options_.max_body_bytes) + " bytes, or sample count disagrees); "
                                    "skipping to the next header");
    counters_.bytes_skipped += 1;
    skip(1);
    return Framing::kSkipped;
  }

  const size_t message_size = kJsfHeaderSize + static_cast<size_t>(header.byte_count);
  const size_t body_end = start_ + message_size;
  const size_t inner_header = findPlausibleHeader(start_, std::min(body_end, buffer_.size()) - 1);

  bool accept = false;
  if (available >= message_size + kJsfHeaderSize) {
    // The look-ahead decides: the next message starts right after this one, or nothing looked
    // like a header inside it.
    accept = plausibleHeaderAt(body_end) || inner_header == kNotFound;
  } else if (available >= message_size) {
    // Body complete, look-ahead not here yet: hand it out now unless something inside looks
    // like a header (then wait for the look-ahead; at the end of the stream, accept).
    if (inner_header != kNotFound && !end_of_stream) return Framing::kNeedMore;
    accept = true;
  } else {
    // Body incomplete: wait, unless the stream ended.
    if (!end_of_stream) return Framing::kNeedMore;
    if (inner_header == kNotFound) {
      ++counters_.truncated_messages;
      reportOnce("truncated", "JSF message at byte " + std::to_string(consumed_offset_) + " ends with the stream after " +
                                  std::to_string(available) + " of " + std::to_string(message_size) + " bytes; dropped");
      skip(available);
      return Framing::kSkipped;
    }
  }

  if (!accept) {
    const size_t resume = inner_header != kNotFound ? inner_header : start_ + 1;
    ++counters_.truncated_messages;
    reportOnce("truncated", "JSF message at byte " + std::to_string(consumed_offset_) + " (type " +
                                std::to_string(header.message_type) + ", " + std::to_string(header.byte_count) +
                                " body bytes) is cut short by the next header at byte " +
                                std::to_string(consumed_offset_ + (resume - start_)) + "; dropped");
    skip(resume - start_);
    return Framing::kSkipped;
  }

  JsfMessage message;
  message.header = header;
  message.stream_offset = consumed_offset_;
  message.body.assign(buffer_.begin() + static_cast<std::ptrdiff_t>(start_ + kJsfHeaderSize),
                      buffer_.begin() + static_cast<std::ptrdiff_t>(body_end));
  out.push_back(std::move(message));
  ++counters_.messages;
  skipping_ = false;
  skip(message_size);
  return Framing::kEmitted;
}

void JsfStreamParser::feed(const uint8_t* data, size_t size, std::vector<JsfMessage>& out) {
  // Compact: drop consumed bytes before growing (the buffer never exceeds about two messages).
  if (start_ > 0 && (start_ >= buffer_.size() / 2 || start_ > (1u << 20))) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(start_));
    start_ = 0;
  }
  buffer_.insert(buffer_.end(), data, data + size);
  while (frameOne(out, false) != Framing::kNeedMore) {
  }
}

void JsfStreamParser::finish(std::vector<JsfMessage>& out) {
  while (buffer_.size() - start_ >= 2 && frameOne(out, true) != Framing::kNeedMore) {
  }
  const size_t left = buffer_.size() - start_;
  if (left > 0) {
    // Fewer than 16 bytes: a header cut by the end of the stream, or one stray byte.
    if (buffer_[start_] == 0x01) {
      ++counters_.truncated_messages;
      reportOnce("truncated", "JSF stream ends inside a message header at byte " + std::to_string(consumed_offset_) +
                                  "; " + std::to_string(left) + " bytes dropped");
    } else {
      counters_.bytes_skipped += left;
    }
    skip(left);
  }
  buffer_.clear();
  start_ = 0;
}

}  // namespace sss::edgetech
