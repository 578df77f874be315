// The JSF fuzz entry: frames arbitrary bytes (fed in arbitrary chunks) and decodes every type 80
// message; shared by the libFuzzer binary and the corpus regression test.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sss::test {
// Returns the number of sonar records decoded.
int fuzzJsf(const uint8_t* data, size_t size);
}
