// Recorded sensor files -> timed chunks, see recorded_streams.hpp.
#include "tools/emulators/recorded_streams.hpp"

#include <algorithm>
#include <fstream>

#include "drivers/edgetech/jsf_file_reader.hpp"
#include "drivers/ins/ins_state_assembler.hpp"
#include "drivers/ins/nmea_stream_parser.hpp"
#include "drivers/ins/position_fix.hpp"

namespace sss::emulators {

sss::core::Result<std::vector<TimedChunk>> loadJsfChunks(const std::string& path) {
  std::vector<TimedChunk> chunks;
  sss::edgetech::JsfFileReader reader(path);
  if (!reader.isOpen()) return sss::core::Status::error(reader.error());
  sss::edgetech::JsfMessage message;
  int64_t last_time_us = 0;
  while (reader.next(message)) {
    TimedChunk chunk;
    chunk.bytes.resize(sss::edgetech::kJsfHeaderSize);
    sss::edgetech::encodeHeader(message.header, chunk.bytes.data());
    chunk.bytes.insert(chunk.bytes.end(), message.body.begin(), message.body.end());
    if (message.header.message_type == sss::edgetech::kJsfSonarData) {
      const auto decoded = sss::edgetech::decodeSonarData(message.header, message.body.data(), message.body.size());
      if (decoded) last_time_us = decoded->ping_time_us;
    }
    chunk.time_us = last_time_us;  // other types go out with the ping before them
    chunks.push_back(std::move(chunk));
  }
  return chunks;
}

sss::core::Result<std::vector<TimedChunk>> loadInsChunks(const std::string& path) {
  std::vector<TimedChunk> chunks;
  std::ifstream file(path);
  if (!file) return sss::core::Status::error("cannot open INS file '" + path + "'");
  sss::ins::InsStateAssembler assembler;
  TimedChunk pending;
  int64_t last_time_us = 0;
  std::string line;
  while (std::getline(file, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    pending.bytes.insert(pending.bytes.end(), line.begin(), line.end());
    pending.bytes.push_back('\r');
    pending.bytes.push_back('\n');
    sss::ins::NmeaStreamParser parser;
    const std::vector<std::string> bodies = parser.feed(line + "\r\n");
    for (const std::string& body : bodies) {
      for (const sss::ins::InsState& state : assembler.addSentence(body)) last_time_us = state.utime_us;
    }
    if (line.rfind("$PIXSE,STATUS", 0) == 0) {
      pending.time_us = last_time_us;
      chunks.push_back(std::move(pending));
      pending = TimedChunk{};
    }
  }
  if (!pending.bytes.empty()) {
    if (const auto state = assembler.flush()) last_time_us = state->utime_us;
    pending.time_us = last_time_us;
    chunks.push_back(std::move(pending));
  }
  return chunks;
}

sss::core::Result<std::vector<TimedChunk>> loadFixChunks(const std::string& path, int64_t reference_utime_us) {
  sss::core::Result<sss::ins::FixFileContents> read = sss::ins::readPositionFixFile(path, sss::ins::FixReaderOptions{});
  if (!read) return read.status();
  std::vector<sss::ins::PositionFix>& fixes = read->fixes;
  sss::ins::resolveFixDates(fixes, reference_utime_us);
  std::vector<TimedChunk> chunks;
  for (const sss::ins::PositionFix& fix : fixes) {
    const std::string text = sss::ins::encodePositionFix(fix, fix.source == sss::ins::FixSource::kGnss ? "GP" : "II");
    chunks.push_back({fix.utime_us, std::vector<uint8_t>(text.begin(), text.end())});
  }
  std::stable_sort(chunks.begin(), chunks.end(), [](const TimedChunk& a, const TimedChunk& b) { return a.time_us < b.time_us; });
  return chunks;
}

}  // namespace sss::emulators
