// Landmark consistency error (LCE, paper Sec. "Evaluation Metrics"): a seabed point seen from two
// pings should geo-reference to one place; the horizontal distance between the two is the error.
#pragma once

#include "pipeline/core/pose.hpp"
#include "tools/eval/heightmap_metrics.hpp"
#include "tools/eval/trajectory_io.hpp"
#include "tools/eval/trajectory_metrics.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
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

// ---- true correspondences from the truth trajectory -------------------------------------------

// The simulator writes no correspondence file, so sss-eval --lce makes them from the truth: seabed
// points on a grid (on the flat seabed of the model options), each seen from every survey line
// whose fan plane sweeps over it within the swath; two sightings from different lines are one
// correspondence. With the same model the truth's own LCE is ~0 (a self-check of the geometry).
struct TrueCorrespondenceOptions {
  double grid_m = 5.0;                 // spacing of the seabed points, north and east (multiples from 0)
  double min_ground_range_m = 10.0;    // |signed ground range| of a sighting: outside the nadir gap
  double max_ground_range_m = 70.0;    // and within the usable swath
  size_t max_correspondences = 20000;  // more are thinned evenly (in grid order)
};

struct TrueCorrespondences {
  std::vector<LandmarkCorrespondence> pairs;  // a: the earlier line's sighting
  size_t sightings = 0;                       // (point, line) sightings within the swath
  size_t seabed_points = 0;                   // points seen from two lines or more
  size_t candidate_pairs = 0;                 // before thinning to max_correspondences
};

// The sighting of a seabed point from a line is the time its fan plane (perpendicular to the
// sonar x axis) passes through the point while the vehicle moves forward (bisection to 1 us on
// the interpolated truth), and the point's signed ground range then (the inverse of
// georeferenceObservation: +starboard). One sighting per line and point: the first.
TrueCorrespondences generateTrueCorrespondences(const Trajectory& truth, const std::vector<SurveyLine>& lines,
                                                const TrueCorrespondenceOptions& options,
                                                const LandmarkConsistencyOptions& model);

// The flat seabed of the LCE model when the user gives none: the mean depth of the true seabed
// raster's finite cells when there is one (seabed not null), else the truth's median depth +
// altitude_m. `source` says which, for the report. Without pitch the LCE does not depend on it;
// with pitch p it moves the fan's seabed line by altitude * tan(p) along track, for the truth and
// the estimates alike.
double flatSeabedDepthM(const Trajectory& truth, const HeightmapRaster* seabed, double altitude_m, std::string& source);

// The signed ground range (+ starboard) of a seabed point that lies in the sonar's fan plane:
// sqrt(along^2 + across^2) of its horizontal offset from the point below the sonar, with the sign
// of the across part (georeferenceGroundRange maps it back to the point).
double signedGroundRangeM(const sss::core::Pose& T_world_sonar, const Eigen::Vector3d& point);

}  // namespace sss::eval
