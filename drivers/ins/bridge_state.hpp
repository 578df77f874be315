// What sss-ins-bridge keeps across restarts in its state directory:
//   odometer: the distance travelled (and the last position), saved every second while it moves,
//             so that a restarted bridge goes on counting instead of starting from 0 (the
//             optimiser's graph is indexed by it);
//   origin:   the mission origin, chosen once per mission (configured, else kept from an earlier
//             run, else the first fix, saved as soon as it is chosen): a restart mid-mission must
//             not move the frame. Delete the file to start a new mission frame.
// No middleware and no logging: what happened comes back as log lines for the process to write.
#pragma once

#include <cstdint>
#include <string>

#include "drivers/ins/ins_bridge.hpp"
#include "pipeline/core/service_log.hpp"

namespace sss::ins {

// What the store has to say, for the process to write (info and errors).
using BridgeStateLog = sss::core::ServiceLog;

class BridgeStateStore {
 public:
  // state_directory empty: nothing is kept (a file replay, or no directory configured).
  explicit BridgeStateStore(const std::string& state_directory);

  // At start, before the first sample: the odometer and, unless the configuration gives the
  // origin, the origin of an earlier run.
  void restore(InsBridge& bridge, BridgeStateLog& log);
  // After each batch of samples: the origin the first fix chose, said and saved once.
  void noteOrigin(const InsBridge& bridge, BridgeStateLog& log);
  // Every second and at exit: the odometer, when it moved since the last save. On the real-time
  // loop: no fsync (after a power loss the odometer may be a second behind; the optimiser bridges it).
  void saveOdometerIfMoved(const InsBridge& bridge, BridgeStateLog& log);

  uint64_t odometerWriteFailures() const { return odometer_write_failures_; }
  const std::string& odometerPath() const { return odometer_path_; }
  const std::string& originPath() const { return origin_path_; }

 private:
  std::string odometer_path_;  // empty: not kept
  std::string origin_path_;
  bool origin_said_ = false;
  int64_t saved_odometer_utime_us_ = -1;
  uint64_t odometer_write_failures_ = 0;
};

}  // namespace sss::ins
