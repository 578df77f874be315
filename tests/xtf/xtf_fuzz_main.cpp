// libFuzzer entry point for the XTF reader.
#include <cstddef>
#include <cstdint>

#include "xtf_fuzz_target.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sss::test::fuzzXtf(data, size);
  return 0;
}
