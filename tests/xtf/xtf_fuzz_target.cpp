// XTF fuzz entry, see xtf_fuzz_target.hpp.
#include "xtf_fuzz_target.hpp"

#include <cmath>
#include <cstdlib>

#include "drivers/xtf/xtf_reader.hpp"

namespace sss::test {

int fuzzXtf(const uint8_t* data, size_t size) {
  using namespace sss::xtf;
  XtfReaderOptions options;
  options.max_record_bytes = 1 << 16;  // keep the fuzzer's memory small; same code paths
  // The last byte picks the read chunk and the pair, so buffer boundaries fall everywhere.
  options.read_chunk_bytes = size > 0 ? 1 + data[size - 1] % 251 : 1;
  options.pair_index = size > 0 ? (data[size - 1] >> 7) : 0;
  XtfReader reader(data, size, options);
  if (!reader.isOpen()) return 0;
  int pings = 0;
  sss::sonar::DriverPing ping;
  while (reader.next(ping)) {
    ++pings;
    if (!ping.ping.port && !ping.ping.starboard) std::abort();
    for (const auto* side : {&ping.ping.port, &ping.ping.starboard}) {
      if (!*side) continue;
      // Samples come from inside one record, whose size the options bound.
      if ((*side)->samples.size() > options.max_record_bytes) std::abort();
      if (!std::isfinite((*side)->sample_interval_s) || (*side)->sample_interval_s < 0.0) std::abort();
      for (const float s : (*side)->samples) {
        if (!(s >= 0.0f) || !std::isfinite(s)) std::abort();
      }
    }
  }
  const XtfReaderCounters& counters = reader.counters();
  if (counters.pings != static_cast<uint64_t>(pings)) std::abort();
  if (reader.bytesRead() != size) std::abort();  // every byte is read, none twice
  (void)reader.summary();
  (void)reader.takeNewFaultMessages();
  return pings;
}

}  // namespace sss::test
