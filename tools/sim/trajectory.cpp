// Survey path planning (straight lines joined by semicircular turns, crossing lines by
// turn-straight-turn paths) and the vehicle's true motion along it: terrain following on the smooth
// seabed, autopilot wobble, bank in turns.
#include "tools/sim/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace sss::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Vector2d headingVector(double heading_rad) { return {std::cos(heading_rad), std::sin(heading_rad)}; }
Eigen::Vector2d starboardVector(double heading_rad) { return {-std::sin(heading_rad), std::cos(heading_rad)}; }

// Angle in [0, 2 pi).
double positiveAngle(double angle_rad) {
  const double a = std::fmod(angle_rad, 2.0 * kPi);
  return a < 0.0 ? a + 2.0 * kPi : a;
}

PathSegment arcSegment(const Eigen::Vector2d& start, double heading_rad, double radius_m, double sign, double angle_rad) {
  PathSegment arc;
  arc.is_line = false;
  arc.start = start;
  arc.start_heading_rad = heading_rad;
  arc.turn_radius_m = radius_m;
  arc.turn_sign = sign;
  arc.length_m = radius_m * angle_rad;
  return arc;
}

// The shortest turn-straight-turn path (Dubins' CSC words: RSR, LSL, RSL, LSR) from one pose to
// another with turns of the given radius; segments without start distances. RSR and LSL always
// exist, so there is always a path (not always the shortest Dubins path, which may be CCC when the
// poses are closer than ~4 radii; the survey never asks for that).
std::vector<PathSegment> turnStraightTurn(const Eigen::Vector2d& from, double from_heading_rad, const Eigen::Vector2d& to,
                                          double to_heading_rad, double radius_m) {
  std::vector<PathSegment> best;
  double best_length = std::numeric_limits<double>::infinity();
  for (const double first : {1.0, -1.0}) {
    for (const double second : {1.0, -1.0}) {
      // A point on a turn of sign s lies at centre - s r starboard(heading).
      const Eigen::Vector2d c1 = from + first * radius_m * starboardVector(from_heading_rad);
      const Eigen::Vector2d c2 = to + second * radius_m * starboardVector(to_heading_rad);
      const Eigen::Vector2d d = c2 - c1;
      const double distance = d.norm();
      double straight = distance, heading = std::atan2(d.y(), d.x());
      if (first != second) {
        // Inner tangent: d = straight * heading vector - 2 s1 r * starboard vector.
        if (distance < 2.0 * radius_m) continue;
        straight = std::sqrt(distance * distance - 4.0 * radius_m * radius_m);
        heading += std::atan2(2.0 * first * radius_m, straight);
      }
      const double arc1 = positiveAngle(first * (heading - from_heading_rad));
      const double arc2 = positiveAngle(second * (to_heading_rad - heading));
      const double length = radius_m * (arc1 + arc2) + straight;
      if (length >= best_length) continue;
      best_length = length;
      best.clear();
      const Eigen::Vector2d q1 = c1 - first * radius_m * starboardVector(heading);
      const Eigen::Vector2d q2 = c2 - second * radius_m * starboardVector(heading);
      if (arc1 > 1e-9) best.push_back(arcSegment(from, from_heading_rad, radius_m, first, arc1));
      if (straight > 1e-9) {
        PathSegment line;
        line.start = q1;
        line.start_heading_rad = heading;
        line.length_m = straight;
        best.push_back(line);
      }
      if (arc2 > 1e-9) best.push_back(arcSegment(q2, heading, radius_m, second, arc2));
    }
  }
  return best;
}

}  // namespace

static void appendCrossLines(const TrajectoryOptions& options, std::vector<PathSegment>& segments, double& distance);

std::vector<PathSegment> planSurvey(const TrajectoryOptions& options) {
  if (options.surface != "none" && options.surface != "start" && options.surface != "start-end" &&
      options.surface != "lines")
    throw std::invalid_argument("planSurvey: surface must be none, start, start-end or lines, not " + options.surface);
  if (options.lines < 1) throw std::invalid_argument("planSurvey: lines must be >= 1");
  const double h0 = options.line_heading_deg * kPi / 180.0;
  const Eigen::Vector2d along = headingVector(h0);
  const Eigen::Vector2d lateral = starboardVector(h0);
  const double s = options.line_spacing_m;
  const double length = options.line_length_m;

  // Each line: lateral offset (in spacings) and direction (+1 along h0, -1 against).
  std::vector<std::pair<double, double>> lines;
  if (options.pattern == "lawnmower" || options.pattern == "cross") {
    for (int k = 0; k < options.lines; ++k) lines.emplace_back(k * s, k % 2 == 0 ? 1.0 : -1.0);
  } else if (options.pattern == "loop") {
    // Racetrack loops that step sideways by one spacing per loop: the outbound lines lie side by
    // side, the return lines too, ceil(lines/2) spacings further out. Every turn is to starboard.
    const int outbound = (options.lines + 1) / 2;
    for (int k = 0; k < options.lines; ++k) {
      const int loop = k / 2;
      lines.emplace_back(k % 2 == 0 ? loop * s : (loop + outbound) * s, k % 2 == 0 ? 1.0 : -1.0);
    }
  } else {
    throw std::invalid_argument("planSurvey: unknown pattern " + options.pattern);
  }

  std::vector<PathSegment> segments;
  double distance = 0.0;
  for (size_t k = 0; k < lines.size(); ++k) {
    const auto [offset, direction] = lines[k];
    PathSegment line;
    line.is_line = true;
    line.line_index = static_cast<int>(k);
    line.start_distance_m = distance;
    line.length_m = length;
    line.start = lateral * offset + (direction > 0 ? Eigen::Vector2d::Zero() : Eigen::Vector2d(along * length));
    line.start_heading_rad = direction > 0 ? h0 : sss::core::wrapAngle(h0 + kPi);
    segments.push_back(line);
    distance += length;
    if (k + 1 == lines.size()) break;
    // Semicircle to the next line's start: the lateral gap is the turn's diameter.
    const Eigen::Vector2d end = line.start + headingVector(line.start_heading_rad) * length;
    const double next_offset = lines[k + 1].first;
    const Eigen::Vector2d next_start =
        lateral * next_offset + (lines[k + 1].second > 0 ? Eigen::Vector2d::Zero() : Eigen::Vector2d(along * length));
    const Eigen::Vector2d gap = next_start - end;
    const double diameter = gap.norm();
    if (diameter < 10.0) throw std::invalid_argument("planSurvey: turn diameter below 10 m; increase line spacing");
    PathSegment turn;
    turn.is_line = false;
    turn.start_distance_m = distance;
    turn.start = end;
    turn.start_heading_rad = line.start_heading_rad;
    turn.turn_radius_m = 0.5 * diameter;
    turn.turn_sign = gap.dot(starboardVector(line.start_heading_rad)) > 0 ? 1.0 : -1.0;
    turn.length_m = kPi * turn.turn_radius_m;
    segments.push_back(turn);
    distance += turn.length_m;
  }
  if (options.pattern == "cross") appendCrossLines(options, segments, distance);
  if (options.surface == "none") return segments;
  // Lead-in (and lead-out) at the surface and the ramp to depth, straight along the first (last) line.
  const double lead_m = options.surface_hold_m + options.surface_ramp_m;
  PathSegment lead_in;
  lead_in.is_line = true;
  lead_in.line_index = -1;
  lead_in.length_m = lead_m;
  lead_in.start_heading_rad = segments.front().start_heading_rad;
  lead_in.start = segments.front().start - headingVector(lead_in.start_heading_rad) * lead_m;
  for (PathSegment& segment : segments) segment.start_distance_m += lead_m;
  segments.insert(segments.begin(), lead_in);
  if (options.surface == "start-end" || options.surface == "lines") {
    const PathSegment& last = segments.back();
    PathSegment lead_out;
    lead_out.is_line = true;
    lead_out.line_index = -1;
    lead_out.length_m = lead_m;
    lead_out.start_distance_m = last.start_distance_m + last.length_m;
    if (last.is_line) {
      lead_out.start_heading_rad = last.start_heading_rad;
      lead_out.start = last.start + headingVector(last.start_heading_rad) * last.length_m;
    } else {
      const double r = last.turn_radius_m;
      const Eigen::Vector2d centre = last.start + last.turn_sign * r * starboardVector(last.start_heading_rad);
      lead_out.start_heading_rad = last.start_heading_rad + last.turn_sign * last.length_m / r;
      lead_out.start = centre - last.turn_sign * r * starboardVector(lead_out.start_heading_rad);
    }
    segments.push_back(lead_out);
  }
  return segments;
}

static void appendCrossLines(const TrajectoryOptions& options, std::vector<PathSegment>& segments, double& distance) {
  const double h0 = options.line_heading_deg * kPi / 180.0;
  const Eigen::Vector2d along = headingVector(h0);
  const Eigen::Vector2d lateral = starboardVector(h0);
  const double s = options.line_spacing_m;
  const double length = options.line_length_m;
  // Crossing lines: perpendicular to the lawnmower at 1/(K+1) ... K/(K+1) of its length, one
  // spacing beyond the outer lines on either side; the first from the side and end where the
  // lawnmower finished, then alternating.
  if (options.cross_lines < 1) throw std::invalid_argument("planSurvey: cross_lines must be >= 1");
  if (options.cross_turn_radius_m < 5.0) throw std::invalid_argument("planSurvey: cross_turn_radius_m below 5 m");
  const double lateral_min = -s, lateral_max = (options.lines - 1) * s + s;
  const PathSegment& last = segments.back();
  const bool finished_far_end = last.start_heading_rad == h0;  // the last lawnmower line flew along h0
  for (int j = 0; j < options.cross_lines; ++j) {
    const int k = finished_far_end ? options.cross_lines - 1 - j : j;
    const double along_m = length * (k + 1) / (options.cross_lines + 1);
    const bool to_port = j % 2 == 0;  // the lawnmower ends on its starboard-most line
    PathSegment line;
    line.is_line = true;
    line.line_index = options.lines + j;
    line.length_m = lateral_max - lateral_min;
    line.start = along * along_m + lateral * (to_port ? lateral_max : lateral_min);
    line.start_heading_rad = sss::core::wrapAngle(h0 + (to_port ? -0.5 * kPi : 0.5 * kPi));
    const PathSegment& previous = segments.back();
    const Eigen::Vector2d previous_end = previous.start + headingVector(previous.start_heading_rad) * previous.length_m;
    for (PathSegment connection : turnStraightTurn(previous_end, previous.start_heading_rad, line.start,
                                                   line.start_heading_rad, options.cross_turn_radius_m)) {
      connection.start_distance_m = distance;
      segments.push_back(connection);
      distance += connection.length_m;
    }
    line.start_distance_m = distance;
    segments.push_back(line);
    distance += line.length_m;
  }
}

Eigen::Vector4d Trajectory::planExtent(const TrajectoryOptions& options) {
  const std::vector<PathSegment> segments = planSurvey(options);
  Eigen::Vector4d extent(1e18, 1e18, -1e18, -1e18);  // north min, east min, north max, east max
  for (const PathSegment& segment : segments) {
    const int steps = 64;
    for (int i = 0; i <= steps; ++i) {
      const double a = segment.length_m * i / steps;
      Eigen::Vector2d p;
      if (segment.is_line) {
        p = segment.start + headingVector(segment.start_heading_rad) * a;
      } else {
        const double r = segment.turn_radius_m;
        const Eigen::Vector2d centre = segment.start + segment.turn_sign * r * starboardVector(segment.start_heading_rad);
        p = centre - segment.turn_sign * r * starboardVector(segment.start_heading_rad + segment.turn_sign * a / r);
      }
      extent[0] = std::min(extent[0], p.x());
      extent[1] = std::min(extent[1], p.y());
      extent[2] = std::max(extent[2], p.x());
      extent[3] = std::max(extent[3], p.y());
    }
  }
  return extent;
}

Trajectory::Trajectory(const TrajectoryOptions& options, const Seabed* seabed)
    : options_(options), seabed_(seabed), segments_(planSurvey(options)) {
  if (options.speed_m_s <= 0.0) throw std::invalid_argument("Trajectory: speed must be positive");
  total_length_m_ = segments_.back().start_distance_m + segments_.back().length_m;
  std::mt19937_64 rng(mixSeed(options.seed, 2001));
  std::uniform_real_distribution<double> phase(0.0, 2.0 * kPi);
  phase_roll_ = phase(rng);
  phase_pitch_ = phase(rng);
  phase_yaw_ = phase(rng);
  phase_altitude_ = phase(rng);
  if (options.surface != "none") {
    surface_windows_.push_back({-1e12, options.surface_hold_m, options.surface_ramp_m});
    if (options.surface == "start-end" || options.surface == "lines")
      surface_windows_.push_back({total_length_m_ - options.surface_hold_m, 1e12, options.surface_ramp_m});
    if (options.surface == "lines") {
      // Half way through each turn between two lawnmower lines, ramps shortened to fit the turn.
      for (const PathSegment& segment : segments_) {
        if (segment.is_line) continue;
        const double middle = segment.start_distance_m + 0.5 * segment.length_m;
        const double half_hold = std::min(0.5 * options.surface_hold_m, 0.25 * segment.length_m);
        const double ramp = std::max(1.0, std::min(options.surface_ramp_m, 0.5 * segment.length_m - half_hold));
        surface_windows_.push_back({middle - half_hold, middle + half_hold, ramp});
      }
    }
  }
}

double Trajectory::submergedWeight(double distance_m) const {
  double weight = 1.0;
  for (const SurfaceWindow& w : surface_windows_) {
    const double outside = std::max({w.from_m - distance_m, distance_m - w.to_m, 0.0});
    const double x = std::clamp(outside / w.ramp_m, 0.0, 1.0);
    // Smootherstep: neither pitch nor vertical acceleration jumps where the ramp starts and ends.
    weight = std::min(weight, x * x * x * (x * (6.0 * x - 15.0) + 10.0));
  }
  return weight;
}

void Trajectory::planarState(double distance_m, Eigen::Vector2d& position, double& heading_rad, double& curvature,
                             int& line) const {
  distance_m = std::clamp(distance_m, 0.0, total_length_m_);
  auto it = std::upper_bound(segments_.begin(), segments_.end(), distance_m,
                             [](double d, const PathSegment& s) { return d < s.start_distance_m; });
  const PathSegment& segment = *(it == segments_.begin() ? it : it - 1);
  const double a = std::min(distance_m - segment.start_distance_m, segment.length_m);
  if (segment.is_line) {
    position = segment.start + headingVector(segment.start_heading_rad) * a;
    heading_rad = segment.start_heading_rad;
    curvature = 0.0;
    line = segment.line_index;
    return;
  }
  const double r = segment.turn_radius_m;
  const Eigen::Vector2d centre = segment.start + segment.turn_sign * r * starboardVector(segment.start_heading_rad);
  heading_rad = segment.start_heading_rad + segment.turn_sign * a / r;
  position = centre - segment.turn_sign * r * starboardVector(heading_rad);
  // Bank builds up over the first and last 10 m of the turn rather than jumping.
  const double ramp = std::clamp(std::min(a, segment.length_m - a) / 10.0, 0.0, 1.0);
  curvature = segment.turn_sign * ramp / r;
  line = -1;
}

TrajectorySample Trajectory::sample(double time_s) const {
  const double distance = time_s * options_.speed_m_s;
  Eigen::Vector2d planar;
  double path_heading = 0.0;
  double curvature = 0.0;
  int line = -1;
  planarState(distance, planar, path_heading, curvature, line);

  const double t = time_s;
  const auto depthAt = [&](const Eigen::Vector2d& p, double path_m, double time) {
    double depth_m = seabed_->smoothDepthM(p.x(), p.y()) - options_.altitude_m +
                     options_.altitude_wobble_m * std::sin(2.0 * kPi * time / 31.0 + phase_altitude_);
    if (options_.altitude_variation_m > 0.0) {
      depth_m -= options_.altitude_variation_m *
                 fractalNoise2d(mixSeed(options_.seed, 2002), path_m / options_.altitude_variation_length_m, 0.5, 2);
    }
    if (surface_windows_.empty()) return depth_m;
    return options_.surface_depth_m + submergedWeight(path_m) * (depth_m - options_.surface_depth_m);
  };
  const double depth = depthAt(planar, distance, t);
  // Slope of the flown depth along track gives the mean pitch (bow up when climbing).
  const double ds = 1.0;
  const Eigen::Vector2d ahead = planar + headingVector(path_heading) * ds;
  const Eigen::Vector2d behind = planar - headingVector(path_heading) * ds;
  const double dz_ds = (depthAt(ahead, distance + ds, t) - depthAt(behind, distance - ds, t)) / (2.0 * ds);

  const double roll = options_.roll_amplitude_rad * std::sin(2.0 * kPi * t / options_.roll_period_s + phase_roll_) +
                      std::clamp(curvature * 35.0, -1.0, 1.0) * options_.max_turn_bank_rad;
  const double pitch = -std::atan(dz_ds) +
                       options_.pitch_amplitude_rad * std::sin(2.0 * kPi * t / options_.pitch_period_s + phase_pitch_);
  const double heading = sss::core::wrapAngle(
      path_heading + options_.yaw_amplitude_rad * std::sin(2.0 * kPi * t / options_.yaw_period_s + phase_yaw_));

  TrajectorySample sample;
  sample.time_s = time_s;
  sample.T_world_body = sss::core::Pose(sss::core::quaternionFromEuler(roll, pitch, heading),
                                        Eigen::Vector3d(planar.x(), planar.y(), depth));
  const Eigen::Vector2d velocity_planar = headingVector(path_heading) * options_.speed_m_s;
  // Vertical speed: terrain following along the path plus the altitude wobble's own rate.
  const double wobble_rate = submergedWeight(distance) * options_.altitude_wobble_m * (2.0 * kPi / 31.0) *
                             std::cos(2.0 * kPi * t / 31.0 + phase_altitude_);
  sample.velocity_world_m_s =
      Eigen::Vector3d(velocity_planar.x(), velocity_planar.y(), dz_ds * options_.speed_m_s + wobble_rate);
  sample.altitude_m = seabed_->depthM(planar.x(), planar.y()) - depth;
  sample.line_index = line;
  return sample;
}

}  // namespace sss::sim
