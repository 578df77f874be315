// The XTF fuzz entry: reads arbitrary bytes through XtfReader's in-memory path (the same framing
// and decoding as files); shared by the libFuzzer binary and the corpus regression test.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sss::test {
// Returns the number of pings read.
int fuzzXtf(const uint8_t* data, size_t size);
}
