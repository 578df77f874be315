// Polling helper for tests of non-blocking sources: loopback sockets, pseudo-terminals and files
// deliver within milliseconds, so a second only bounds a failing test.
#pragma once

#include <cstdint>

#include "pipeline/core/time.hpp"

namespace sss::test {

// Calls step() until done() or a second has passed; false on the timeout.
template <typename Step, typename Done>
bool within1s(Step step, Done done) {
  const int64_t deadline_us = sss::core::monotonicUtime() + 1'000'000;
  while (!done()) {
    if (sss::core::monotonicUtime() > deadline_us) return false;
    step();
  }
  return true;
}

}  // namespace sss::test
