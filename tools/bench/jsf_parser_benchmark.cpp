// JSF parse throughput (Google Benchmark): framing alone, and framing + type 80 decoding, on
// EdgeTech 2205-sized pings (20k samples per side).
#include <benchmark/benchmark.h>

#include <cmath>

#include "drivers/edgetech/jsf_stream_parser.hpp"

namespace {

std::vector<uint8_t> makeStream(int pings, size_t samples) {
  std::vector<uint8_t> stream;
  std::vector<float> magnitudes(samples);
  for (size_t i = 0; i < samples; ++i) magnitudes[i] = 100.0f + 50.0f * std::sin(0.01f * static_cast<float>(i));
  for (int p = 0; p < pings; ++p) {
    for (uint8_t channel : {sss::sonar::kChannelPort, sss::sonar::kChannelStarboard}) {
      sss::sonar::SonarChannelRecord record;
      record.channel = channel;
      record.ping_number = static_cast<uint32_t>(p);
      record.ping_time_us = 1'780'000'000'000'000 + p * 100'000;
      record.sample_interval_s = 7.5e-6;
      const auto codes = sss::edgetech::quantiseEnvelope(magnitudes, record.weighting_factor);
      const auto bytes = sss::edgetech::encodeSonarData(record, codes);
      stream.insert(stream.end(), bytes.begin(), bytes.end());
    }
  }
  return stream;
}

void feedInChunks(const std::vector<uint8_t>& stream, bool decode, benchmark::State& state) {
  for (auto _ : state) {
    sss::edgetech::JsfStreamParser parser;
    std::vector<sss::edgetech::JsfMessage> messages;
    size_t decoded = 0;
    for (size_t offset = 0; offset < stream.size(); offset += 65536) {  // TCP-sized reads
      parser.feed(stream.data() + offset, std::min<size_t>(65536, stream.size() - offset), messages);
      if (decode) {
        for (const auto& m : messages) {
          decoded += sss::edgetech::decodeSonarData(m.header, m.body.data(), m.body.size()).ok() ? 1 : 0;
        }
      }
      messages.clear();
    }
    benchmark::DoNotOptimize(decoded);
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(stream.size()));
}

void BM_JsfFraming(benchmark::State& state) {
  static const std::vector<uint8_t> stream = makeStream(50, 20000);
  feedInChunks(stream, false, state);
}
BENCHMARK(BM_JsfFraming)->Unit(benchmark::kMillisecond);

void BM_JsfFramingAndDecoding(benchmark::State& state) {
  static const std::vector<uint8_t> stream = makeStream(50, 20000);
  feedInChunks(stream, true, state);
}
BENCHMARK(BM_JsfFramingAndDecoding)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
