// Landmark consistency error on the flat-seabed model. See landmark_consistency.hpp.
#include "tools/eval/landmark_consistency.hpp"

#include "pipeline/core/georeference.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <utility>

namespace sss::eval {
namespace {

// > 0 when the point is ahead of the sonar's fan plane.
double aheadOfFanM(const sss::core::Pose& T_world_sonar, const Eigen::Vector3d& point) {
  return (T_world_sonar.rotation * Eigen::Vector3d::UnitX()).dot(point - T_world_sonar.translation);
}

}  // namespace

std::optional<Eigen::Vector3d> georeferenceObservation(const Trajectory& trajectory, const SonarObservation& observation,
                                                       const LandmarkConsistencyOptions& options) {
  const std::optional<sss::core::Pose> T_world_body =
      poseAtTime(trajectory, observation.utime_us, options.max_interpolation_gap_s);
  if (!T_world_body) return std::nullopt;
  const sss::core::Pose T_world_sonar = *T_world_body * options.T_body_sonar;
  const double altitude_m = options.seabed_depth_m - T_world_sonar.translation.z();
  if (!(altitude_m > 0.0)) return std::nullopt;
  // The same flat-seabed geometry as the pipeline's geo-reference.
  return sss::core::georeferenceGroundRange(T_world_sonar, altitude_m, observation.ground_range_m);
}

LandmarkConsistencyResult landmarkConsistency(const Trajectory& trajectory,
                                              const std::vector<LandmarkCorrespondence>& correspondences,
                                              const LandmarkConsistencyOptions& options) {
  LandmarkConsistencyResult result;
  result.distances_m.reserve(correspondences.size());
  for (const LandmarkCorrespondence& c : correspondences) {
    const std::optional<Eigen::Vector3d> a = georeferenceObservation(trajectory, c.a, options);
    const std::optional<Eigen::Vector3d> b = georeferenceObservation(trajectory, c.b, options);
    if (!a || !b) {
      result.distances_m.push_back(std::numeric_limits<double>::quiet_NaN());
      ++result.skipped;
      continue;
    }
    result.distances_m.push_back((*a - *b).head<2>().norm());
  }
  result.horizontal_m = errorStatistics(result.distances_m);  // NaN entries are left out
  return result;
}

double flatSeabedDepthM(const Trajectory& truth, const HeightmapRaster* seabed, double altitude_m, std::string& source) {
  if (seabed) {
    double sum_m = 0.0;
    size_t count = 0;
    for (float depth_m : seabed->depth_m) {
      if (!std::isfinite(depth_m)) continue;
      sum_m += depth_m;
      ++count;
    }
    if (count > 0) {
      source = "mean depth of the true seabed";
      return sum_m / static_cast<double>(count);
    }
  }
  std::vector<double> depths_m;
  for (const StampedPose& p : truth) depths_m.push_back(p.T_world_body.translation.z());
  if (depths_m.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(depths_m.begin(), depths_m.begin() + depths_m.size() / 2, depths_m.end());
  char text[96];
  std::snprintf(text, sizeof text, "median truth depth + %.1f m altitude", altitude_m);
  source = text;
  return depths_m[depths_m.size() / 2] + altitude_m;
}

double signedGroundRangeM(const sss::core::Pose& T_world_sonar, const Eigen::Vector3d& point) {
  // The same frame as georeferenceGroundRange: v horizontal along the fan's seabed line (to
  // starboard), w horizontal perpendicular to it.
  const Eigen::Vector3d normal = T_world_sonar.rotation * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d down = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d v = down.cross(normal);
  if (v.norm() < 1e-9) return std::numeric_limits<double>::quiet_NaN();
  v.normalize();
  if (v.dot(T_world_sonar.rotation * Eigen::Vector3d::UnitY()) < 0.0) v = -v;
  const Eigen::Vector3d w = v.cross(down);
  const Eigen::Vector3d offset = point - T_world_sonar.translation;
  const double across_m = offset.dot(v);
  return std::copysign(std::hypot(offset.dot(w), across_m), across_m);
}

TrueCorrespondences generateTrueCorrespondences(const Trajectory& truth, const std::vector<SurveyLine>& lines,
                                                const TrueCorrespondenceOptions& options,
                                                const LandmarkConsistencyOptions& model) {
  struct Sighting {
    int line = 0;
    SonarObservation observation;
  };
  // Keyed by grid (north index, east index): std::map keeps the grid order deterministic.
  std::map<std::pair<int64_t, int64_t>, std::vector<Sighting>> sightings;
  TrueCorrespondences result;
  const double grid_m = options.grid_m;
  const auto sonarAt = [&](int64_t utime_us) {
    return *poseAtTime(truth, utime_us, model.max_interpolation_gap_s) * model.T_body_sonar;
  };
  for (const SurveyLine& line : lines) {
    for (size_t k = line.first_pose; k < line.last_pose && k + 1 < truth.size(); ++k) {
      const StampedPose& a = truth[k];
      const StampedPose& b = truth[k + 1];
      if (static_cast<double>(b.utime_us - a.utime_us) * 1e-6 > model.max_interpolation_gap_s) continue;
      const sss::core::Pose sonar_a = a.T_world_body * model.T_body_sonar;
      const sss::core::Pose sonar_b = b.T_world_body * model.T_body_sonar;
      // A point the fan passes between a and b lies within |ground range| (horizontally) of the
      // sonar at that time, so within max range of the box around the two sonar positions.
      const Eigen::Vector2d low = sonar_a.translation.head<2>().cwiseMin(sonar_b.translation.head<2>());
      const Eigen::Vector2d high = sonar_a.translation.head<2>().cwiseMax(sonar_b.translation.head<2>());
      const int64_t i0 = static_cast<int64_t>(std::ceil((low.x() - options.max_ground_range_m) / grid_m));
      const int64_t i1 = static_cast<int64_t>(std::floor((high.x() + options.max_ground_range_m) / grid_m));
      const int64_t j0 = static_cast<int64_t>(std::ceil((low.y() - options.max_ground_range_m) / grid_m));
      const int64_t j1 = static_cast<int64_t>(std::floor((high.y() + options.max_ground_range_m) / grid_m));
      for (int64_t i = i0; i <= i1; ++i) {
        for (int64_t j = j0; j <= j1; ++j) {
          const Eigen::Vector3d point(i * grid_m, j * grid_m, model.seabed_depth_m);
          if (!(aheadOfFanM(sonar_a, point) > 0.0 && aheadOfFanM(sonar_b, point) <= 0.0)) continue;
          // Bisection on the time: ahead at lo, not ahead at hi.
          int64_t lo = a.utime_us, hi = b.utime_us;
          while (hi - lo > 1) {
            const int64_t mid = lo + (hi - lo) / 2;
            if (aheadOfFanM(sonarAt(mid), point) > 0.0) lo = mid;
            else hi = mid;
          }
          const int64_t utime_us =
              std::abs(aheadOfFanM(sonarAt(lo), point)) < std::abs(aheadOfFanM(sonarAt(hi), point)) ? lo : hi;
          const double ground_range_m = signedGroundRangeM(sonarAt(utime_us), point);
          if (!(std::abs(ground_range_m) >= options.min_ground_range_m &&
                std::abs(ground_range_m) <= options.max_ground_range_m)) {
            continue;
          }
          std::vector<Sighting>& seen = sightings[{i, j}];
          if (!seen.empty() && seen.back().line == line.index) continue;  // first sighting per line
          seen.push_back({line.index, {utime_us, ground_range_m}});
          ++result.sightings;
        }
      }
    }
  }

  std::vector<LandmarkCorrespondence> candidates;
  for (const auto& [cell, seen] : sightings) {
    if (seen.size() >= 2) ++result.seabed_points;
    for (size_t p = 0; p < seen.size(); ++p) {
      for (size_t q = p + 1; q < seen.size(); ++q) candidates.push_back({seen[p].observation, seen[q].observation});
    }
  }
  result.candidate_pairs = candidates.size();
  if (candidates.size() <= options.max_correspondences) {
    result.pairs = std::move(candidates);
  } else {
    // Evenly over the grid order, so every part of the survey keeps its share.
    for (size_t k = 0; k < options.max_correspondences; ++k) {
      result.pairs.push_back(candidates[k * candidates.size() / options.max_correspondences]);
    }
  }
  return result;
}

}  // namespace sss::eval
