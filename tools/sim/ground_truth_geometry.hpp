// Ground-truth sonar geometry: where a sample of a ping lies on the true seabed, and which ping
// and sample of another survey line see a given seabed point. Matching and bathymetry tests use it.
#pragma once

#include "pipeline/core/pose.hpp"
#include "tools/sim/seabed.hpp"
#include "tools/sim/sonar_model.hpp"

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace sss::sim {

struct SeabedHit {
  Eigen::Vector3d position_ned_m = Eigen::Vector3d::Zero();
  double slant_range_m = 0.0;
};

struct PingObservation {
  double ping_index = 0.0;  // fractional index into the poses given (where the fan plane crosses)
  size_t nearest_ping = 0;
  Side side = Side::kStarboard;
  double sample = 0.0;      // fractional sample index (slant range / sample spacing)
  double slant_range_m = 0.0;
  bool visible = false;     // false when a nearer feature shadows the point from this ping
};

class GroundTruthGeometry {
 public:
  GroundTruthGeometry(const Seabed* seabed, const SonarOptions& options);

  // The first (nearest to nadir) visible seabed point at the slant range of `sample` in the ping's
  // fan plane; nullopt in water column or shadow. Where relief causes layover (a boulder face and
  // the bed in front of it at one range) the pixel mixes both and this returns the bed point.
  std::optional<SeabedHit> sampleToSeabed(const sss::core::Pose& T_world_sonar, Side side, double sample) const;

  // Every crossing of the point by the fan planes of consecutive poses (one per pass), within
  // range. Poses are the true sonar poses of the pings of a line, in ping order.
  std::vector<PingObservation> observationsOf(const Eigen::Vector3d& point_ned_m,
                                              const std::vector<sss::core::Pose>& ping_poses) const;

 private:
  const Seabed* seabed_;
  SonarOptions options_;
};

}  // namespace sss::sim
