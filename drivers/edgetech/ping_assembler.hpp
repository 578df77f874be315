// Joins the port and starboard channel messages of one ping by ping number. A ping whose other
// side does not come within a timeout (or is pushed out by newer pings) is handed out with the
// side it has and a flag, never held forever and never dropped silently.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "drivers/edgetech/jsf_format.hpp"

namespace sss::edgetech {

using sss::sonar::AssembledPing;  // drivers/sonar/sonar_ping.hpp

struct PingAssemblerOptions {
  uint8_t subsystem = kSubsystemSideScanLow;  // the side-scan frequency to use; others are ignored
  // A sonar recording one frequency only (a 4125 or 2205 set to its high frequency) writes
  // subsystem 21 or 22 and never the configured 20: every ping would be ignored. When this many
  // side-scan records (subsystems 20-22) of one other subsystem arrive before any of the configured
  // one, that subsystem is used instead (held back meanwhile, so none is lost). 0: never.
  int adopt_other_side_scan_after = 64;
  double missing_side_timeout_s = 1.0;        // a lone side waits this long for its partner
  int max_pending_pings = 8;                   // more incomplete pings than this: the oldest goes out
};

struct PingAssemblerCounters {
  uint64_t complete_pings = 0;
  uint64_t incomplete_pings = 0;   // handed out with one side missing
  uint64_t duplicate_channels = 0; // a side seen twice for one ping: the later one is kept
  uint64_t other_subsystem = 0;    // messages of another subsystem, ignored
  // The subsystem used in place of the configured one, which the data never held (-1: none).
  int adopted_subsystem = -1;
};

class PingAssembler {
 public:
  explicit PingAssembler(PingAssemblerOptions options = {});

  // Adds one channel record that arrived at monotonic time arrival_us; completed pings go to out.
  void add(SonarChannelRecord record, int64_t arrival_us, std::vector<AssembledPing>& out);
  // Hands out pings whose partner timed out by now_us (call from a timer).
  void expire(int64_t now_us, std::vector<AssembledPing>& out);
  // Hands out everything pending (end of a file).
  void flush(std::vector<AssembledPing>& out);

  size_t pending() const { return pending_.size(); }
  const PingAssemblerCounters& counters() const { return counters_; }

 private:
  struct Pending {
    AssembledPing ping;
    int64_t first_arrival_us = 0;
  };
  void emit(Pending&& pending, std::vector<AssembledPing>& out);
  void join(SonarChannelRecord record, int64_t arrival_us, std::vector<AssembledPing>& out);
  // Uses the subsystem of the held records from now on and joins them (held_other_ not empty).
  void adoptHeld(std::vector<AssembledPing>& out);

  PingAssemblerOptions options_;
  bool configured_seen_ = false;
  // Side-scan records of one other subsystem held while the configured one has not appeared.
  std::vector<std::pair<SonarChannelRecord, int64_t>> held_other_;
  std::deque<Pending> pending_;  // in arrival order
  PingAssemblerCounters counters_;
};

}  // namespace sss::edgetech
