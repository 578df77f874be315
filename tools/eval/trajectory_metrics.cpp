// Trajectory metrics: association, Umeyama alignment, ATE, RPE, error series, survey lines. See
// trajectory_metrics.hpp.
#include "tools/eval/trajectory_metrics.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <complex>

namespace sss::eval {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

double rotationAngleDeg(const Eigen::Quaterniond& q) { return sss::core::logSO3(q).norm() * kRadToDeg; }

double headingRad(const Eigen::Quaterniond& q) { return sss::core::eulerFromQuaternion(q).heading_rad; }

// Index of the first sample with time >= utime_us.
size_t lowerBound(const Trajectory& trajectory, int64_t utime_us) {
  return static_cast<size_t>(std::lower_bound(trajectory.begin(), trajectory.end(), utime_us,
                                              [](const StampedPose& p, int64_t t) { return p.utime_us < t; }) -
                             trajectory.begin());
}

// Value of a per-sample quantity at utime_us, linear in time between samples, clamped at the ends.
double interpolateAtTime(const Trajectory& trajectory, const std::vector<double>& values, int64_t utime_us) {
  const size_t k = lowerBound(trajectory, utime_us);
  if (k == 0) return values.front();
  if (k >= trajectory.size()) return values.back();
  const double span = static_cast<double>(trajectory[k].utime_us - trajectory[k - 1].utime_us);
  const double alpha = static_cast<double>(utime_us - trajectory[k - 1].utime_us) / span;
  return values[k - 1] + alpha * (values[k] - values[k - 1]);
}

// Horizontal path of the truth, parameterised by horizontal distance.
class HorizontalPath {
 public:
  explicit HorizontalPath(const Trajectory& trajectory) {
    points_.reserve(trajectory.size());
    distance_.reserve(trajectory.size());
    double s = 0.0;
    for (size_t i = 0; i < trajectory.size(); ++i) {
      const Eigen::Vector2d p = trajectory[i].T_world_body.translation.head<2>();
      if (i > 0) s += (p - points_.back()).norm();
      points_.push_back(p);
      distance_.push_back(s);
    }
  }

  double distance(size_t i) const { return distance_[i]; }
  double length() const { return distance_.empty() ? 0.0 : distance_.back(); }
  const Eigen::Vector2d& point(size_t i) const { return points_[i]; }

  Eigen::Vector2d at(double s) const {
    if (s <= 0.0) return points_.front();
    if (s >= length()) return points_.back();
    const size_t k = static_cast<size_t>(std::lower_bound(distance_.begin(), distance_.end(), s) - distance_.begin());
    if (k == 0) return points_.front();
    const double span = distance_[k] - distance_[k - 1];
    const double alpha = span > 0.0 ? (s - distance_[k - 1]) / span : 0.0;
    return points_[k - 1] + alpha * (points_[k] - points_[k - 1]);
  }

 private:
  std::vector<Eigen::Vector2d> points_;
  std::vector<double> distance_;
};

}  // namespace

ErrorStatistics errorStatistics(std::vector<double> values) {
  ErrorStatistics stats;
  values.erase(std::remove_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); }), values.end());
  stats.count = values.size();
  if (values.empty()) return stats;
  double sum = 0.0, sum_squares = 0.0, max = values.front();
  for (double v : values) {
    sum += v;
    sum_squares += v * v;
    max = std::max(max, v);
  }
  const double n = static_cast<double>(values.size());
  stats.mean = sum / n;
  stats.rmse = std::sqrt(sum_squares / n);
  stats.max = max;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  stats.median = values[mid];
  if (values.size() % 2 == 0) {
    stats.median = 0.5 * (stats.median + *std::max_element(values.begin(), values.begin() + mid));
  }
  return stats;
}

double courseDeg(const Eigen::Vector2d& north_east) {
  double course = std::atan2(north_east.y(), north_east.x()) * kRadToDeg;
  if (course < 0.0) course += 360.0;
  if (course >= 360.0) course -= 360.0;
  return course;
}

std::vector<double> cumulativeDistanceM(const Trajectory& trajectory) {
  std::vector<double> distance(trajectory.size(), 0.0);
  for (size_t i = 1; i < trajectory.size(); ++i) {
    distance[i] = distance[i - 1] +
                  (trajectory[i].T_world_body.translation - trajectory[i - 1].T_world_body.translation).norm();
  }
  return distance;
}

// ---- association ---------------------------------------------------------------------------

std::optional<sss::core::Pose> poseAtTime(const Trajectory& trajectory, int64_t utime_us, double max_gap_s) {
  const size_t k = lowerBound(trajectory, utime_us);
  if (k < trajectory.size() && trajectory[k].utime_us == utime_us) return trajectory[k].T_world_body;
  if (k == 0 || k >= trajectory.size()) return std::nullopt;
  const StampedPose& a = trajectory[k - 1];
  const StampedPose& b = trajectory[k];
  const double span_s = static_cast<double>(b.utime_us - a.utime_us) * 1e-6;
  if (span_s > max_gap_s) return std::nullopt;
  const double alpha = static_cast<double>(utime_us - a.utime_us) / static_cast<double>(b.utime_us - a.utime_us);
  return sss::core::interpolate(a.T_world_body, b.T_world_body, alpha);
}

Association associate(const Trajectory& truth, const Trajectory& estimate, const AssociationOptions& options) {
  Association association;
  association.pairs.reserve(estimate.size());
  const int64_t tolerance_us = static_cast<int64_t>(std::llround(options.max_time_difference_s * 1e6));
  for (const StampedPose& e : estimate) {
    const size_t k = lowerBound(truth, e.utime_us);
    AssociatedPose pair;
    pair.utime_us = e.utime_us;
    pair.estimate = e.T_world_body;
    if (k < truth.size() && truth[k].utime_us == e.utime_us) {
      pair.truth = truth[k].T_world_body;
      association.pairs.push_back(pair);
      ++association.exact;
      continue;
    }
    if (options.interpolate_truth) {
      const std::optional<sss::core::Pose> interpolated = poseAtTime(truth, e.utime_us, options.max_interpolation_gap_s);
      if (interpolated) {
        pair.truth = *interpolated;
        association.pairs.push_back(pair);
        ++association.interpolated;
        continue;
      }
    }
    // Nearest neighbour within the tolerance.
    int64_t best_dt = -1;
    size_t best = 0;
    for (size_t candidate : {k, k - 1}) {
      if (candidate >= truth.size()) continue;  // k - 1 wraps when k == 0
      const int64_t dt = std::llabs(truth[candidate].utime_us - e.utime_us);
      if (best_dt < 0 || dt < best_dt) {
        best_dt = dt;
        best = candidate;
      }
    }
    if (best_dt >= 0 && best_dt <= tolerance_us) {
      pair.truth = truth[best].T_world_body;
      association.pairs.push_back(pair);
      ++association.nearest;
    } else {
      ++association.unmatched;
    }
  }
  return association;
}

// ---- alignment -----------------------------------------------------------------------------

std::optional<sss::core::Pose> umeyamaAlignment(const std::vector<Eigen::Vector3d>& source,
                                                const std::vector<Eigen::Vector3d>& target) {
  if (source.empty() || source.size() != target.size()) return std::nullopt;
  const double n = static_cast<double>(source.size());
  Eigen::Vector3d mean_source = Eigen::Vector3d::Zero(), mean_target = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < source.size(); ++i) {
    mean_source += source[i];
    mean_target += target[i];
  }
  mean_source /= n;
  mean_target /= n;
  // Umeyama eq. (38)-(40) with c = 1: covariance of target vs source, SVD, reflection guard.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < source.size(); ++i) {
    covariance += (target[i] - mean_target) * (source[i] - mean_source).transpose();
  }
  covariance /= n;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  if (source.size() > 1 && covariance.norm() > 0.0) {
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Vector3d s = Eigen::Vector3d::Ones();
    if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) s(2) = -1.0;
    rotation = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
  }
  const Eigen::Vector3d translation = mean_target - rotation * mean_source;
  return sss::core::Pose(Eigen::Quaterniond(rotation), translation);
}

// ---- survey lines --------------------------------------------------------------------------

std::vector<SurveyLine> segmentSurveyLines(const Trajectory& truth, const LineSegmentationOptions& options) {
  std::vector<SurveyLine> lines;
  if (truth.size() < 2) return lines;
  const HorizontalPath path(truth);
  const double half = 0.5 * options.course_window_m;
  const double min_chord_m = 0.25 * half;  // shorter chords (path ends, stops) give no course
  const double max_rate_rad_per_m = options.max_turn_rate_deg_per_m / kRadToDeg;

  // 1-2: steady samples.
  std::vector<bool> steady(truth.size(), true);
  for (size_t i = 0; i < truth.size(); ++i) {
    const double s = path.distance(i);
    const Eigen::Vector2d here = path.at(s);
    const Eigen::Vector2d behind = here - path.at(s - half);
    const Eigen::Vector2d ahead = path.at(s + half) - here;
    if (behind.norm() < min_chord_m || ahead.norm() < min_chord_m) continue;
    const double change = std::abs(sss::core::wrapAngle(std::atan2(ahead.y(), ahead.x()) - std::atan2(behind.y(), behind.x())));
    steady[i] = change / half <= max_rate_rad_per_m;
  }

  const auto addLine = [&](size_t first, size_t last) {
    if (last <= first) return;
    const double length = path.distance(last) - path.distance(first);
    if (length < options.min_line_length_m) return;
    SurveyLine line;
    line.index = static_cast<int>(lines.size());
    line.first_pose = first;
    line.last_pose = last;
    line.start_utime_us = truth[first].utime_us;
    line.end_utime_us = truth[last].utime_us;
    line.length_m = length;
    line.heading_deg = courseDeg(path.point(last) - path.point(first));
    lines.push_back(line);
  };

  // 3-4: runs of steady samples, cut where the course leaves the run's initial course.
  const double max_change_rad = options.max_heading_change_deg / kRadToDeg;
  size_t i = 0;
  while (i < truth.size()) {
    if (!steady[i]) {
      ++i;
      continue;
    }
    size_t end = i;
    while (end + 1 < truth.size() && steady[end + 1]) ++end;
    size_t first = i;
    double reference = std::nan("");
    for (size_t k = i; k <= end; ++k) {
      const double s = path.distance(k);
      const double s_first = path.distance(first);
      if (s - s_first < options.course_window_m) continue;  // course not yet established
      const Eigen::Vector2d chord = path.at(s) - path.at(s - options.course_window_m);
      if (chord.norm() < min_chord_m) continue;
      const double course = std::atan2(chord.y(), chord.x());
      if (std::isnan(reference)) {
        reference = course;
        continue;
      }
      if (std::abs(sss::core::wrapAngle(course - reference)) > max_change_rad) {
        addLine(first, k - 1);
        first = k;
        reference = std::nan("");
      }
    }
    addLine(first, end);
    i = end + 1;
  }
  return lines;
}

// ---- evaluation ----------------------------------------------------------------------------

TrajectoryEvaluation evaluateTrajectory(const Trajectory& truth, const Trajectory& estimate,
                                        const std::vector<SurveyLine>& truth_lines,
                                        const TrajectoryEvaluationOptions& options) {
  TrajectoryEvaluation result;
  result.estimate_poses = estimate.size();
  if (truth.empty() || estimate.empty()) {
    result.error = truth.empty() ? "the truth trajectory is empty" : "the estimate trajectory is empty";
    return result;
  }
  result.association = associate(truth, estimate, options.association);
  const std::vector<AssociatedPose>& pairs = result.association.pairs;
  if (pairs.empty()) {
    result.error = "no estimate pose lies within the truth's time span (or within " +
                   std::to_string(options.association.max_time_difference_s) +
                   " s of a truth pose); check both files use the same clock";
    return result;
  }

  // ATE raw.
  std::vector<double> position, horizontal, vertical, rotation;
  std::vector<Eigen::Vector3d> source, target;
  for (const AssociatedPose& p : pairs) {
    const Eigen::Vector3d e = p.estimate.translation - p.truth.translation;
    position.push_back(e.norm());
    horizontal.push_back(e.head<2>().norm());
    vertical.push_back(std::abs(e.z()));
    rotation.push_back(rotationAngleDeg(p.truth.rotation.conjugate() * p.estimate.rotation));
    source.push_back(p.estimate.translation);
    target.push_back(p.truth.translation);
  }
  AteResult& ate = result.ate;
  ate.position_m = errorStatistics(position);
  ate.horizontal_m = errorStatistics(horizontal);
  ate.vertical_m = errorStatistics(vertical);
  ate.rotation_deg = errorStatistics(rotation);

  // ATE aligned.
  ate.T_truth_estimate = umeyamaAlignment(source, target).value_or(sss::core::Pose::identity());
  ate.alignment_rotation_deg = rotationAngleDeg(ate.T_truth_estimate.rotation);
  ate.alignment_heading_deg = headingRad(ate.T_truth_estimate.rotation) * kRadToDeg;
  std::vector<double> aligned_position, aligned_horizontal;
  for (size_t i = 0; i < pairs.size(); ++i) {
    const Eigen::Vector3d e = ate.T_truth_estimate * source[i] - target[i];
    aligned_position.push_back(e.norm());
    aligned_horizontal.push_back(e.head<2>().norm());
  }
  ate.aligned_position_m = errorStatistics(aligned_position);
  ate.aligned_horizontal_m = errorStatistics(aligned_horizontal);

  // ATE gauge-free: rotation and scale about the estimate's first position (see AteResult).
  const auto northEast = [](const Eigen::Vector3d& p) { return std::complex<double>(p.x(), p.y()); };
  const std::complex<double> origin = northEast(pairs.front().estimate.translation);
  std::complex<double> cross(0.0, 0.0);
  double norm_a = 0.0;
  for (const AssociatedPose& p : pairs) {
    const std::complex<double> a = northEast(p.estimate.translation) - origin;
    cross += std::conj(a) * (northEast(p.truth.translation) - origin);
    norm_a += std::norm(a);
  }
  const std::complex<double> z = norm_a > 0.0 ? cross / norm_a : std::complex<double>(1.0, 0.0);
  ate.gauge_free_scale = std::abs(z);
  ate.gauge_free_rotation_deg = std::arg(z) * kRadToDeg;
  std::vector<double> gauge_free, gauge;
  for (const AssociatedPose& p : pairs) {
    const std::complex<double> a = northEast(p.estimate.translation) - origin;
    gauge_free.push_back(std::abs(northEast(p.truth.translation) - origin - z * a));
    gauge.push_back(std::abs((z - 1.0) * a));
  }
  ate.gauge_free_horizontal_m = errorStatistics(gauge_free);
  ate.gauge_horizontal_m = errorStatistics(gauge);

  // Truth path length at each pair (interpolated on the full truth, so sparse estimates do not
  // shorten the path).
  const std::vector<double> truth_distance = cumulativeDistanceM(truth);
  std::vector<double> distance(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) distance[i] = interpolateAtTime(truth, truth_distance, pairs[i].utime_us);

  // RPE over distance windows: for each start i, the first j with path length >= window.
  for (double window : options.rpe.windows_m) {
    RpeResult rpe;
    rpe.window_m = window;
    std::vector<double> percent, metres, degrees;
    size_t j = 0;
    for (size_t i = 0; i < pairs.size(); ++i) {
      j = std::max(j, i + 1);
      while (j < pairs.size() && distance[j] - distance[i] < window) ++j;
      if (j >= pairs.size()) break;
      const double travelled = distance[j] - distance[i];
      if (travelled <= 0.0 || travelled > window * (1.0 + options.rpe.max_window_overshoot_fraction)) continue;
      const sss::core::Pose truth_motion = sss::core::between(pairs[i].truth, pairs[j].truth);
      const sss::core::Pose estimate_motion = sss::core::between(pairs[i].estimate, pairs[j].estimate);
      const sss::core::Pose error = sss::core::between(truth_motion, estimate_motion);
      metres.push_back(error.translation.norm());
      percent.push_back(100.0 * error.translation.norm() / travelled);
      degrees.push_back(rotationAngleDeg(error.rotation));
    }
    rpe.translation_percent = errorStatistics(percent);
    rpe.translation_m = errorStatistics(metres);
    rpe.rotation_deg = errorStatistics(degrees);
    result.rpe.push_back(rpe);
  }

  // Series and per-line errors.
  std::vector<std::vector<double>> line_horizontal(truth_lines.size()), line_position(truth_lines.size()),
      line_aligned(truth_lines.size());
  size_t line_cursor = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    ErrorSample sample;
    sample.utime_us = pairs[i].utime_us;
    sample.time_s = static_cast<double>(pairs[i].utime_us - pairs.front().utime_us) * 1e-6;
    sample.distance_m = distance[i] - distance.front();
    sample.position_m = position[i];
    sample.horizontal_m = horizontal[i];
    sample.aligned_horizontal_m = aligned_horizontal[i];
    sample.gauge_free_horizontal_m = gauge_free[i];
    const double heading = headingRad(pairs[i].truth.rotation);
    const Eigen::Vector2d forward(std::cos(heading), std::sin(heading));
    const Eigen::Vector2d starboard(-std::sin(heading), std::cos(heading));
    const Eigen::Vector2d e = (pairs[i].estimate.translation - pairs[i].truth.translation).head<2>();
    sample.along_track_m = e.dot(forward);
    sample.across_track_m = e.dot(starboard);
    while (line_cursor < truth_lines.size() && truth_lines[line_cursor].end_utime_us < sample.utime_us) ++line_cursor;
    if (line_cursor < truth_lines.size() && truth_lines[line_cursor].start_utime_us <= sample.utime_us) {
      sample.line = truth_lines[line_cursor].index;
      line_horizontal[line_cursor].push_back(horizontal[i]);
      line_position[line_cursor].push_back(position[i]);
      line_aligned[line_cursor].push_back(aligned_horizontal[i]);
    }
    result.series.push_back(sample);
  }
  for (size_t k = 0; k < truth_lines.size(); ++k) {
    if (line_horizontal[k].empty()) continue;
    LineError line;
    line.line = truth_lines[k].index;
    line.horizontal_m = errorStatistics(line_horizontal[k]);
    line.position_m = errorStatistics(line_position[k]);
    line.aligned_horizontal_m = errorStatistics(line_aligned[k]);
    result.lines.push_back(line);
  }
  result.ok = true;
  return result;
}

}  // namespace sss::eval
