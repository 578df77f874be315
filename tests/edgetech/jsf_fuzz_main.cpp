// libFuzzer entry point for the JSF parser.
#include <cstddef>
#include <cstdint>

#include "jsf_fuzz_target.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sss::test::fuzzJsf(data, size);
  return 0;
}
