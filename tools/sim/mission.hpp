// A simulated side-scan mission: options (YAML + command line), the assembled seabed, vehicle,
// dead reckoning and sonar, per-ping rendering and JSF encoding, and every output file of sss-sim.
#pragma once

#include "pipeline/core/config.hpp"
#include "pipeline/core/geodesy.hpp"
#include "tools/sim/dead_reckoning.hpp"
#include "tools/sim/seabed.hpp"
#include "tools/sim/sonar_model.hpp"
#include "tools/sim/trajectory.hpp"
#include "pipeline/core/status.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace sss::sim {

// Absolute fixes written to fixes.nmea (GGA + GST + ZDA): GNSS while the vehicle is at the surface,
// USBL from a ship holding station over the middle of the survey.
struct SimFixOptions {
  std::string gnss = "none";        // none, start, start-end, lines: when the vehicle surfaces for them
  double gnss_sigma_m = 1.5;        // per axis (the GST says so)
  // A receiver's error wanders over minutes (ionosphere, orbits, multipath): first-order
  // Gauss-Markov with this correlation time, stationary sigma gnss_sigma_m. 0: white.
  double gnss_correlation_time_s = 300.0;
  double gnss_period_s = 5.0;       // one fix every period while at the surface
  double gnss_max_depth_m = 0.5;    // the antenna is out of the water above this depth
  double usbl_period_s = 0.0;       // 0: no USBL
  double usbl_sigma_fraction = 0.002;  // of the slant range, per axis
  double usbl_sigma_floor_m = 0.5;     // the ship's own GNSS and attitude
  double usbl_dropout_fraction = 0.1;  // fixes lost (no reply, bad geometry)
  double usbl_outlier_fraction = 0.05; // multipath: a fix far off with the usual sigma
  double usbl_outlier_min_m = 10.0;
  double usbl_outlier_max_m = 50.0;
};

struct SimOptions {
  int64_t seed = 1;                         // one seed for everything; modules derive their own
  std::string family = "default";           // the seabed family drawn by --randomise (a label)
  double origin_latitude_deg = 59.35;       // mission origin = NED origin
  double origin_longitude_deg = 18.07;
  int64_t start_utime_us = 1780300800000000;  // 2026-06-01T08:00:00Z
  double duration_s = 0.0;                  // 0: the whole planned survey; else truncate
  double seabed_margin_m = 20.0;            // seabed beyond the outermost swath edge
  bool auto_seabed_extent = true;           // size the seabed from the path and the range
  int waterfall_bins_per_side = 1000;       // PNG previews: slant-range samples are averaged
  double mosaic_resolution_m = 0.5;
  // False: no altitude in the files (INS stream and JSF headers), as a towed fish or a vehicle
  // without DVL records: the chain has to track the bottom in the sonar returns.
  bool record_altitude = true;
  SeabedOptions seabed;
  TrajectoryOptions trajectory;
  DeadReckoningOptions dead_reckoning;
  SonarOptions sonar;
  SimFixOptions fixes;
};

// Reads the `sim` section's keys into options (defaults stay where a key is absent); problems go
// to the section. Unknown keys are problems.
void readSimOptions(sss::core::ConfigSection section, SimOptions& options);
// Cross-field checks after the command line has overridden the file; empty when valid.
std::vector<std::string> validateSimOptions(const SimOptions& options);
// The `sim` section as YAML text (the same keys readSimOptions reads).
std::string simOptionsYaml(const SimOptions& options);

class Mission {
 public:
  explicit Mission(const SimOptions& options);

  const SimOptions& options() const { return options_; }
  const Seabed& seabed() const { return *seabed_; }
  const Trajectory& trajectory() const { return *trajectory_; }
  const DeadReckoning& deadReckoning() const { return *dead_reckoning_; }
  const SonarModel& sonar() const { return *sonar_; }
  const sss::core::LocalTangentPlane& tangentPlane() const { return plane_; }

  double durationS() const { return duration_s_; }
  size_t pingCount() const { return ping_count_; }
  double pingTimeS(size_t ping) const { return static_cast<double>(ping) / options_.sonar.ping_rate_hz; }
  int64_t pingUtimeUs(size_t ping) const;
  TrajectorySample truthAtPing(size_t ping) const { return trajectory_->sample(pingTimeS(ping)); }
  // True poses of the pings of one survey line (for GroundTruthGeometry) and their indices.
  std::vector<size_t> pingsOfLine(int line_index) const;

  PingSamples renderPing(size_t ping) const;
  // Both type 80 messages (port, then starboard) of one ping, with DR navigation in the headers.
  std::vector<uint8_t> encodePingJsf(size_t ping, const PingSamples& samples, uint8_t& sequence) const;

 private:
  SimOptions options_;
  sss::core::LocalTangentPlane plane_;
  std::unique_ptr<Seabed> seabed_;
  std::unique_ptr<Trajectory> trajectory_;
  std::unique_ptr<DeadReckoning> dead_reckoning_;
  std::unique_ptr<SonarModel> sonar_;
  double duration_s_ = 0.0;
  size_t ping_count_ = 0;
};

struct MissionReport {
  size_t pings = 0;
  double duration_s = 0.0;
  double distance_m = 0.0;
  double final_dr_error_m = 0.0;
  double max_dr_error_m = 0.0;
  double render_wall_s = 0.0;   // ping rendering + JSF writing
  double total_wall_s = 0.0;
  std::vector<std::string> files;
};

// Writes every output of sss-sim into out_dir (created if missing). Fails with a message when a
// file cannot be written.
sss::core::Status writeMission(const Mission& mission, const std::string& out_dir, MissionReport& report);

// The INS stream: iXblue $PIXSE NMEA bursts of the DR navigation at the DR rate.
std::string insNmeaStream(const Mission& mission);

// The absolute fixes of SimFixOptions (GNSS talker GP, USBL talker II), in time order; empty when
// the mission has none.
std::string fixesNmea(const Mission& mission);

}  // namespace sss::sim
