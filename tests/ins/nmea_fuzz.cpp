// libFuzzer target for the INS NMEA path (stream parser + sentence parser + assembler + encoder)
// the position fix reader (GGA/GST/ZDA/RMC) and a sonar file's NMEA positions (GGA/RMC/GLL).
// Also linked into nmea_fuzz_regression_test, which replays the corpus with any compiler.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "drivers/ins/ins_state_assembler.hpp"
#include "drivers/ins/ixblue_nmea.hpp"
#include "drivers/ins/nmea_gga.hpp"
#include "drivers/ins/nmea_stream_parser.hpp"
#include "drivers/ins/position_fix.hpp"

namespace {

// Invariants beyond "no crash, no UB": abort() so libFuzzer records the input.
void check(bool condition) {
  if (!condition) std::abort();
}

bool sameCounters(const sss::ins::NmeaStreamCounters& a, const sss::ins::NmeaStreamCounters& b) {
  return a.bytes == b.bytes && a.sentences == b.sentences && a.bad_checksum == b.bad_checksum &&
         a.missing_checksum == b.missing_checksum && a.overlong == b.overlong &&
         a.bad_character == b.bad_character && a.truncated == b.truncated &&
         a.garbage_bytes == b.garbage_bytes;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace sss::ins;
  // The whole input at once.
  NmeaStreamParser whole;
  std::vector<std::string> sentences;
  whole.feed(data, size, sentences);
  whole.flush(sentences);

  // The same bytes in two pieces split where the first byte says: framing must not depend on
  // how the network cut the stream.
  const size_t split = size == 0 ? 0 : data[0] % (size + 1);
  NmeaStreamParser pieces;
  std::vector<std::string> piece_sentences;
  pieces.feed(data, split, piece_sentences);
  pieces.feed(data + split, size - split, piece_sentences);
  pieces.flush(piece_sentences);
  check(piece_sentences == sentences);
  check(sameCounters(whole.counters(), pieces.counters()));

  InsStateAssembler assembler;
  std::vector<InsState> states;
  for (const std::string& sentence : sentences) {
    check(sentence.size() < NmeaStreamOptions{}.max_sentence_bytes);
    for (const InsState& state : assembler.addSentence(sentence)) states.push_back(state);
  }
  if (auto state = assembler.flush()) states.push_back(*state);

  // Whatever the assembler accepted, the encoder must turn into sentences that parse cleanly.
  for (const InsState& state : states) {
    NmeaStreamParser reparser;
    InsStateAssembler reassembler;
    size_t reassembled = 0;
    for (const std::string& sentence : reparser.feed(encodeInsState(state))) {
      reassembled += reassembler.addSentence(sentence).size();
    }
    check(reparser.rejectedSentences() == 0 && reparser.counters().garbage_bytes == 0);
    for (int64_t rejected : reassembler.counters().rejected) check(rejected == 0);
    check(reassembled == 1);
  }

  // Position fixes: whatever is accepted is a finite position on Earth with a positive sigma, and
  // the same bytes in two pieces give the same fixes.
  PositionFixReader fix_reader;
  fix_reader.feed(std::string_view(reinterpret_cast<const char*>(data), size));
  const std::vector<PositionFix> fixes = fix_reader.finish();
  PositionFixReader fix_pieces;
  fix_pieces.feed(std::string_view(reinterpret_cast<const char*>(data), split));
  fix_pieces.feed(std::string_view(reinterpret_cast<const char*>(data) + split, size - split));
  check(fix_pieces.finish().size() == fixes.size());
  check(fix_reader.counters().fixes == fixes.size());
  for (const PositionFix& fix : fixes) {
    check(std::abs(fix.latitude_deg) <= 90.0 && std::abs(fix.longitude_deg) <= 180.0);
    check(fix.sigma_north_m > 0.0 && fix.sigma_east_m > 0.0 && std::isfinite(fix.sigma_north_m) &&
          std::isfinite(fix.sigma_east_m));
    check(fix.seconds_of_day >= 0.0 && fix.seconds_of_day < 86401.0);
  }

  // A sonar file's NMEA positions (GGA, RMC, GLL): every framed sentence, and the raw input as one
  // sentence; what is accepted is a position on Earth at a time of day.
  std::vector<std::string> candidates = sentences;
  candidates.emplace_back(reinterpret_cast<const char*>(data), size);
  for (const std::string& sentence : candidates) {
    if (const auto position = parseNmeaPosition(sentence)) {
      check(std::abs(position->latitude_deg) <= 90.0 && std::abs(position->longitude_deg) <= 180.0);
      check(position->seconds_of_day >= 0.0 && position->seconds_of_day < 86401.0 && position->quality > 0);
    }
  }
  return 0;
}
