// Replays the NMEA fuzz corpus and generated mutations of a valid stream through the fuzz target,
// so every compiler (and the ASan/UBSan CI job) exercises what the fuzzer found.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "drivers/ins/ixblue_nmea.hpp"
#include "drivers/ins/position_fix.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace sss::ins {
namespace {

void run(const std::string& bytes) {
  LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
}

// 2000 mutations of a valid stream (1-8 edits each: random or interesting bytes, cuts, repeats of
// itself), the same on every run for a given seed.
void runMutations(const std::string& base, unsigned seed, const std::vector<char>& interesting) {
  std::mt19937 random(seed);
  for (int round = 0; round < 2000; ++round) {
    std::string bytes = base;
    const int edits = 1 + static_cast<int>(random() % 8);
    for (int e = 0; e < edits && !bytes.empty(); ++e) {
      const size_t at = random() % bytes.size();
      switch (random() % 4) {
        case 0: bytes[at] = static_cast<char>(random() & 0xFF); break;
        case 1: bytes[at] = interesting[random() % interesting.size()]; break;
        case 2: bytes.erase(at, 1 + random() % 16); break;
        case 3: bytes.insert(at, bytes.substr(random() % bytes.size(), random() % 64)); break;
      }
    }
    run(bytes);
  }
}

TEST(NmeaFuzzRegression, ReplaysEveryCorpusFile) {
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(SSS_INS_CORPUS_DIR)) {
    if (!entry.is_regular_file()) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    SCOPED_TRACE(entry.path().string());
    run(bytes);
    ++files;
  }
  EXPECT_GE(files, 5);
}

TEST(NmeaFuzzRegression, SurvivesGeneratedMutationsOfValidBursts) {
  InsState state;
  state.utime_us = 1710506096789012;
  state.latitude_deg = 59.9;
  state.longitude_deg = 10.7;
  state.depth_m = 80.0;
  state.altitude_m = 15.0;
  state.validity = kValidAll;
  std::string base;
  for (int i = 0; i < 3; ++i) {
    state.utime_us += 200000;
    base += encodeInsState(state);
  }
  runMutations(base, 12345, {'$', '*', ',', '\r', '\n', '\0', '-', '.', '9', 'A', '\x80'});
}

TEST(NmeaFuzzRegression, SurvivesGeneratedMutationsOfFixStreams) {
  PositionFix fix;
  fix.utime_us = 1780300800000000;
  fix.latitude_deg = 59.35;
  fix.longitude_deg = 18.07;
  fix.sigma_north_m = 0.9;
  fix.sigma_east_m = 1.1;
  fix.quality = 1;
  fix.hdop = 0.9;
  std::string base;
  for (int i = 0; i < 3; ++i) {
    fix.utime_us += 1000000;
    base += encodePositionFix(fix, i == 1 ? "U0" : "GP");
  }
  runMutations(base, 4242, {'$', '*', ',', '\r', '\n', '\0', '-', '.', '9', 'N', 'S', 'E', 'W', '\x80'});
}

}  // namespace
}  // namespace sss::ins
