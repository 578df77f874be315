// The INS bridge's logic, free of sockets and LCM: NMEA bytes in (UDP datagrams, a TCP stream,
// a serial port, a file), complete navigation samples out with local NED position, body-frame
// velocity, distance travelled and validity/staleness flags; every fault counted.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drivers/ins/ins_state_assembler.hpp"
#include "drivers/ins/nmea_stream_parser.hpp"
#include "pipeline/core/config.hpp"
#include "pipeline/core/geodesy.hpp"
#include "pipeline/core/mission_origin.hpp"

namespace sss::ins {

struct InsBridgeOptions {
  // The origin of the local NED frame (mission.origin_*): an override; unset, the first valid
  // position fixes it (see pipeline/core/mission_origin.hpp).
  std::optional<sss::core::MissionOrigin> origin;
  InsAssemblerOptions assembler;
  NmeaStreamOptions stream;
  // A restarted bridge resumes its odometer; the path from the last saved position to the first
  // new one counts as a straight line when they are at most this far apart in time (a restart),
  // and adds nothing after a longer gap (another dive).
  double odometer_max_bridged_gap_s = 60.0;
};

// Where the odometer stood: what a restarted bridge needs so that distance travelled, which the
// optimiser's odometry uncertainty grows with, never goes back.
struct OdometerState {
  double distance_travelled_m = 0.0;
  int64_t utime_us = 0;  // INS time of the last position; 0: none yet
  Eigen::Vector3d position_ned_m = Eigen::Vector3d::Zero();
};

struct NavSample {
  InsState ins;                          // as assembled (geodetic, attitude, NED velocity, std)
  Eigen::Vector3d position_ned_m = Eigen::Vector3d::Zero();  // zero until the origin is known
  std::optional<sss::core::MissionOrigin> origin;            // of position_ned_m; none before the first fix
  Eigen::Vector3d velocity_body_m_s = Eigen::Vector3d::Zero();  // FRD
  double distance_travelled_m = 0.0;     // horizontal path length of the DR track so far
};

class InsBridge {
 public:
  explicit InsBridge(const InsBridgeOptions& options);

  // Bytes as received; host_monotonic_us stamps them for the silence check.
  void onBytes(const uint8_t* data, size_t size, int64_t host_monotonic_us, std::vector<NavSample>& out);
  // End of a UDP datagram (a sentence may omit its CR/LF there) or of a file.
  void onChunkEnd(int64_t host_monotonic_us, std::vector<NavSample>& out);
  // End of input: the open epoch too.
  void finish(int64_t host_monotonic_us, std::vector<NavSample>& out);

  // Staleness now, also when the INS went silent: INS time is extrapolated from the last epoch
  // by the host time elapsed since it arrived.
  uint32_t staleFlagsAt(int64_t host_monotonic_us) const;
  // "no heading for 1.5 s, no position for 6.0 s" or empty.
  std::string describeStale(int64_t host_monotonic_us) const;

  std::vector<std::string> takeNewFaultMessages();
  const NmeaStreamCounters& streamCounters() const { return parser_.counters(); }
  const InsAssemblerCounters& assemblerCounters() const { return assembler_.counters(); }
  uint64_t epochsOutOfOrder() const { return epochs_out_of_order_; }

  // The origin in use and where it came from; nullopt until configured, resumed or fixed.
  const std::optional<sss::core::MissionOrigin>& origin() const { return origin_; }
  sss::core::OriginSource originSource() const { return origin_source_; }
  // Before the first sample, when no origin is configured: keep the frame of an earlier run.
  void resumeOrigin(const sss::core::MissionOrigin& origin);

  OdometerState odometer() const;
  // Before the first sample: continue the odometer of an earlier run.
  void resumeOdometer(const OdometerState& state);

 private:
  void assemble(std::vector<std::string>& sentences, int64_t host_monotonic_us, std::vector<NavSample>& out);
  void emit(const InsState& state, int64_t host_monotonic_us, std::vector<NavSample>& out);

  void setOrigin(const sss::core::MissionOrigin& origin, sss::core::OriginSource source);

  InsBridgeOptions options_;
  std::optional<sss::core::MissionOrigin> origin_;
  sss::core::OriginSource origin_source_ = sss::core::OriginSource::kFirstFix;
  std::optional<sss::core::LocalTangentPlane> plane_;
  NmeaStreamParser parser_;
  InsStateAssembler assembler_;
  std::vector<std::string> sentences_;  // reused
  std::optional<Eigen::Vector3d> last_position_ned_m_;
  double distance_travelled_m_ = 0.0;
  int64_t last_position_utime_us_ = 0;
  bool resumed_ = false;  // resumeOdometer() called, no position since
  int64_t last_ins_utime_us_ = 0;
  int64_t last_epoch_host_us_ = 0;
  uint64_t epochs_out_of_order_ = 0;
  std::vector<std::string> reported_;  // fault kinds already handed out
};

// Reads the ins_bridge section's library keys (the origin is the mission section's).
void readInsBridgeOptions(sss::core::ConfigSection& section, InsBridgeOptions& options);

}  // namespace sss::ins
