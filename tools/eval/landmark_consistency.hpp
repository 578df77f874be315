// Landmark consistency error (LCE, paper Sec. "Evaluation Metrics"): a seabed point seen from two
// pings should geo-reference to one place; the horizontal distance between the two is the error.
#pragma once

#include "pipeline/core/pose.hpp"
#include "tools/eval/trajectory_io.hpp"
#include "tools/eval/trajectory_metrics.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <vector>

namespace sss::eval {

// One side-scan observation of a seabed point: the ping time and the point's signed ground range
// across track (+ starboard, - port), as in the canonical image columns.
struct SonarObservation {
  int64_t utime_us = 0;
  double ground_range_m = 0.0;
};

// Two observations of the same true seabed point (from the simulator's true correspondences or
// hand annotation).
struct LandmarkCorrespondence {
  SonarObservation a;
  SonarObservation b;
};

// Flat-seabed model, the same as pipeline/subframe/georeference.cpp: the point lies in the
// sonar's fan plane (perpendicular to the sonar x axis) on the horizontal seabed at
// seabed_depth_m, at horizontal distance |ground_range_m| from the point below the sonar (pitch
// moves the fan's seabed line along track; that offset is part of the ground range).
struct LandmarkConsistencyOptions {
  double seabed_depth_m = 0.0;                              // NED z of the flat seabed
  sss::core::Pose T_body_sonar = sss::core::Pose::identity();
  double max_interpolation_gap_s = 1.0;                     // pose interpolation between samples
};

// The seabed point of one observation with the trajectory's pose at its time; nullopt when the
// time is outside the trajectory (or in a gap), the sonar is not above the seabed, or the ground
// range is shorter than the pitch offset of the fan line.
std::optional<Eigen::Vector3d> georeferenceObservation(const Trajectory& trajectory, const SonarObservation& observation,
                                                       const LandmarkConsistencyOptions& options);

struct LandmarkConsistencyResult {
  ErrorStatistics horizontal_m;     // over the correspondences that geo-reference on both sides
  std::vector<double> distances_m;  // per correspondence, NaN when skipped
  size_t skipped = 0;
};

LandmarkConsistencyResult landmarkConsistency(const Trajectory& trajectory,
                                              const std::vector<LandmarkCorrespondence>& correspondences,
                                              const LandmarkConsistencyOptions& options);

}  // namespace sss::eval
