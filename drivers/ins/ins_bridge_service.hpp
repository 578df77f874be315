// What sss-ins-bridge does around its InsBridge, without sockets, LCM or logging (what happened
// comes back as log lines for the process to write):
//   start:   the state directory's odometer and mission origin restored (bridge_state.hpp); a file
//            replay keeps nothing;
//   INS:     bytes as they arrive -> SSS_NAV messages. Live they go out at once; replaying a file
//            they wait in a queue and leave at the recorded pace (takeDue);
//   fixes:   bytes from the fixes' own port (GNSS GGA + GST + ZDA, USBL) -> SSS_FIX messages, each
//            placed in the mission frame once the navigation has passed its time (FixAligner);
//   state:   the origin saved as soon as the first fix chooses it, the odometer every second it moves;
//   status:  staleness and counters for SSS_STATUS, and the input faults to report once by kind.
// The process wires these to its input sources, LCM and the loop's timers.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "drivers/ins/bridge_state.hpp"
#include "drivers/ins/fix_aligner.hpp"
#include "drivers/ins/ins_bridge.hpp"
#include "drivers/ins/ins_input_source.hpp"
#include "drivers/ins/position_fix.hpp"
#include "pipeline/core/health.hpp"
#include "pipeline/core/service_log.hpp"
#include "pipeline/transport/replay_pacer.hpp"
#include "sss_msgs/fix_t.hpp"
#include "sss_msgs/nav_t.hpp"

namespace sss::ins {

struct InsBridgeServiceOptions {
  InsBridgeOptions bridge;
  // The input is a recorded file: samples leave at its recorded pace, replay_speed times real time
  // (0: as fast as possible), and nothing is kept in the state directory.
  bool replay = false;
  double replay_speed = 1.0;
  // Absolute fixes are read from their own port.
  bool read_fixes = false;
  FixReaderOptions fix_reader;
  FixAlignerOptions fix_aligner;
  // Where the odometer and the origin survive restarts (resolved; empty: nothing kept).
  std::string state_directory;
};

// What to publish, with the arrival time of the bytes that produced it (for the latency figures).
struct BridgeMessages {
  std::vector<sss_msgs::nav_t> nav;
  std::vector<sss_msgs::fix_t> fixes;
  int64_t since_monotonic_us = 0;
  bool empty() const { return nav.empty() && fixes.empty(); }
};

class InsBridgeService {
 public:
  // Restores the odometer and the origin of an earlier run (not when replaying).
  InsBridgeService(const InsBridgeServiceOptions& options, sss::core::ServiceLog& log);
  InsBridgeService(const InsBridgeService&) = delete;
  InsBridgeService& operator=(const InsBridgeService&) = delete;

  // INS bytes. Live: the messages to publish now; replaying: none, the samples wait for takeDue().
  BridgeMessages onInsChunk(const InsInputChunk& chunk, sss::core::ServiceLog& log);
  // Bytes from the fixes' port: the fixes that can be placed now.
  BridgeMessages onFixChunk(const InsInputChunk& chunk);
  // Replaying: whether the queue has room for more of the file (reading stays ahead of the pace
  // without holding the whole file in memory).
  bool wantsReplayInput() const { return replay_queue_.size() < kReplayQueueSamples; }
  // Replaying: the queued samples due at now_monotonic_us (at most max_samples of them, so the
  // loop stays responsive at high replay speeds).
  BridgeMessages takeDue(int64_t now_monotonic_us, sss::core::ServiceLog& log, int max_samples = 500);
  bool replayQueueEmpty() const { return replay_queue_.empty(); }

  // Every second and at exit.
  void saveOdometerIfMoved(sss::core::ServiceLog& log);
  // Staleness (recovers by itself when data returns) and counters into SSS_STATUS; the fixes'
  // counters only when fixes are read.
  void reportHealth(sss::core::HealthMonitor& health, int64_t now_monotonic_us) const;
  // The INS input's new fault kinds, each once.
  std::vector<std::string> takeInsFaults() { return bridge_.takeNewFaultMessages(); }
  // The fixes' first problem, once (later ones are counted).
  std::vector<std::string> takeFixFaults();

  const InsBridge& bridge() const { return bridge_; }
  uint64_t fixesPublished() const { return fixes_published_; }

 private:
  static constexpr size_t kReplayQueueSamples = 256;

  // The samples waiting in samples_ as messages; the navigation they carry goes to the aligner,
  // and the fixes it can now place come along.
  BridgeMessages publishSamples(int64_t since_monotonic_us, sss::core::ServiceLog& log);
  void appendPlacedFixes(BridgeMessages& messages);

  const InsBridgeServiceOptions options_;
  InsBridge bridge_;
  BridgeStateStore state_;
  PositionFixReader fix_reader_;
  FixAligner fix_aligner_;
  std::vector<NavSample> samples_;          // assembled, not yet handed out (reused)
  std::deque<NavSample> replay_queue_;      // replaying: assembled, waiting for their time
  sss::transport::ReplayPacer pacer_;
  uint64_t fixes_published_ = 0;
  bool fix_problem_reported_ = false;
};

}  // namespace sss::ins
