// Ping-navigation fusion: interpolation of DR nav at ping times (slerp for attitude), bounded
// waiting, altitude fallback, and counted drops. See ping_nav_fusion.hpp.
#include "pipeline/subframe/ping_nav_fusion.hpp"

#include <algorithm>
#include <cmath>

namespace sss::subframe {

using sss::core::Pose;

sss::core::Pose PingNavFusionOptions::T_body_sonar() const {
  return Pose(sss::core::quaternionFromEuler(sonar_rpy_body_rad.x(), sonar_rpy_body_rad.y(), sonar_rpy_body_rad.z()),
              sonar_position_body_m);
}

void readPingNavFusionOptions(sss::core::ConfigSection& section, PingNavFusionOptions& options) {
  using namespace sss::core;
  std::vector<double> lever{options.sonar_position_body_m.x(), options.sonar_position_body_m.y(),
                            options.sonar_position_body_m.z()};
  std::vector<double> rpy{options.sonar_rpy_body_rad.x(), options.sonar_rpy_body_rad.y(),
                          options.sonar_rpy_body_rad.z()};
  const Rule<std::vector<double>> three = satisfies<std::vector<double>>(
      [](const std::vector<double>& v) { return v.size() == 3; }, "a list of 3 numbers");
  section.optional("sonar_position_body_m", lever, {three});
  section.optional("sonar_rpy_body_rad", rpy, {three});
  if (lever.size() == 3) options.sonar_position_body_m = Eigen::Vector3d(lever[0], lever[1], lever[2]);
  if (rpy.size() == 3) options.sonar_rpy_body_rad = Eigen::Vector3d(rpy[0], rpy[1], rpy[2]);
  section.optional("nav_history_s", options.nav_history_s, {inRange(1.0, 3600.0)});
  section.optional("max_nav_gap_s", options.max_nav_gap_s, {inRange(0.001, 60.0)});
  section.optional("max_ping_wait_s", options.max_ping_wait_s, {inRange(0.0, 60.0)});
  section.optional("max_pending_pings", options.max_pending_pings, {inRange(1, 100000)});
  section.optional("heading_rate_window_s", options.heading_rate_window_s, {inRange(0.0, 30.0)});
  section.optional("min_altitude_m", options.min_altitude_m, {inRange(0.0, 1000.0)});
  section.optional("pose_heading_from_fit", options.pose_heading_from_fit);
  section.optional("duplicate_memory_pings", options.duplicate_memory_pings, {inRange(1, 100000)});
  section.optional("bottom_track_calibration_pings", options.bottom_track_calibration_pings, {inRange(1, 100000)});
  section.optional("min_bottom_track_calibration_pings", options.min_bottom_track_calibration_pings,
                   {inRange(1, 100000)});
  std::string policy = options.altitude_source == AltitudePolicy::kNav           ? "nav"
                       : options.altitude_source == AltitudePolicy::kBottomTrack ? "bottom_track"
                                                                                 : "auto";
  section.optional("altitude_source", policy, {oneOf({"nav", "bottom_track", "auto"})});
  options.altitude_source = policy == "nav"            ? AltitudePolicy::kNav
                            : policy == "bottom_track" ? AltitudePolicy::kBottomTrack
                                                       : AltitudePolicy::kAuto;
  ConfigSection bottom_track = section.section("bottom_track");
  readBottomTrackerOptions(bottom_track, options.bottom_track);
  bottom_track.rejectUnknownKeys();
  // A ping waits for nav half a heading-rate window past it: a shorter wait drops every ping.
  if (options.max_ping_wait_s <= 0.5 * options.heading_rate_window_s)
    section.addProblem("max_ping_wait_s", std::to_string(options.max_ping_wait_s),
                       "must exceed half of heading_rate_window_s (pings wait that long for nav)");
}

PingNavFusion::PingNavFusion(const PingNavFusionOptions& options)
    : options_(options), T_body_sonar_(options.T_body_sonar()), bottom_tracker_(options.bottom_track) {}

const char* altitudeSourceName(AltitudeSource source) {
  switch (source) {
    case AltitudeSource::kNav: return "nav";
    case AltitudeSource::kPingHeader: return "ping_header";
    case AltitudeSource::kBottomTrack: return "bottom_track";
  }
  return "unknown";
}

void PingNavFusion::addNav(const NavInput& nav, std::vector<FusedPing>& out) {
  ++counters_.nav_in;
  if (!nav.position_valid) {
    ++counters_.nav_without_position;
    return;
  }
  if (!history_.empty() && nav.utime_us <= history_.back().utime_us) {
    ++counters_.nav_out_of_order;
    return;
  }
  if (first_nav_utime_us_ == INT64_MIN) first_nav_utime_us_ = nav.utime_us;
  history_.push_back(nav);
  // Release before trimming the history: after a pause in the navigation (a line's end, a 60 s
  // stop) the first new sample lets the pings before the pause go, and they need the samples
  // from before it, which trimming to nav_history_s behind the new one would drop.
  release(out, false);
  const int64_t keep_us = static_cast<int64_t>(options_.nav_history_s * 1e6);
  while (history_.size() > 2 && history_.front().utime_us < nav.utime_us - keep_us) history_.pop_front();
}

bool PingNavFusion::seenRecently(int64_t ping_number) const {
  return std::find(recent_numbers_.begin(), recent_numbers_.end(), ping_number) != recent_numbers_.end();
}

void PingNavFusion::addPing(PingInput ping, std::vector<FusedPing>& out) {
  ++counters_.pings_in;
  if (seenRecently(ping.ping_number)) {
    ++counters_.pings_duplicate;
    return;
  }
  recent_numbers_.push_back(ping.ping_number);
  while (static_cast<int>(recent_numbers_.size()) > options_.duplicate_memory_pings) recent_numbers_.pop_front();
  if (ping.utime_us <= last_released_utime_us_) {
    ++counters_.pings_out_of_order;
    return;
  }
  auto position = std::upper_bound(pending_.begin(), pending_.end(), ping.utime_us,
                                   [](int64_t t, const PingInput& p) { return t < p.utime_us; });
  if (position != pending_.end()) ++counters_.pings_reordered;
  pending_.insert(position, std::move(ping));
  release(out, false);
}

void PingNavFusion::finish(std::vector<FusedPing>& out) { release(out, true); }

void PingNavFusion::release(std::vector<FusedPing>& out, bool flush) {
  const int64_t wait_us = static_cast<int64_t>(options_.max_ping_wait_s * 1e6);
  while (!pending_.empty()) {
    PingInput& front = pending_.front();
    // The heading rate is centred on the ping, so a ping waits for nav half a window past it
    // (0.5 s by default); at the end of input whatever nav brackets it is enough.
    const int64_t lookahead_us = static_cast<int64_t>(0.5 * options_.heading_rate_window_s * 1e6);
    const bool nav_arrived = !history_.empty() && (history_.back().utime_us >= front.utime_us + lookahead_us ||
                                                   (flush && history_.back().utime_us >= front.utime_us));
    if (!nav_arrived) {
      const bool waited_too_long = pending_.back().utime_us - front.utime_us > wait_us;
      const bool overflow = static_cast<int>(pending_.size()) > options_.max_pending_pings;
      if (!(flush || waited_too_long || overflow)) break;
      ++counters_.dropped_no_nav;
      last_released_utime_us_ = front.utime_us;
      pending_.pop_front();
      continue;
    }
    PingInput ping = std::move(front);
    pending_.pop_front();
    last_released_utime_us_ = ping.utime_us;
    if (resolve(std::move(ping), out)) ++counters_.pings_out;
  }
}

bool PingNavFusion::resolve(PingInput&& ping, std::vector<FusedPing>& out) {
  const int64_t t = ping.utime_us;
  // b: first nav at or after t; a: the one before it.
  auto b = std::lower_bound(history_.begin(), history_.end(), t,
                            [](const NavInput& n, int64_t time) { return n.utime_us < time; });
  if (b == history_.end()) return false;  // cannot happen: release() checked the newest nav
  if (b->utime_us != t && b == history_.begin()) {
    ++(t < first_nav_utime_us_ ? counters_.dropped_before_first_fix : counters_.dropped_too_old);
    return false;
  }
  auto a = b->utime_us == t ? b : std::prev(b);
  if (static_cast<double>(b->utime_us - a->utime_us) * 1e-6 > options_.max_nav_gap_s) {
    ++counters_.dropped_nav_gap;
    return false;
  }
  const double alpha = b == a ? 0.0 : static_cast<double>(t - a->utime_us) / static_cast<double>(b->utime_us - a->utime_us);
  const Pose pose_a = poseOf(*a);
  const Pose pose_b = poseOf(*b);

  FusedPing fused;
  fused.T_world_body = sss::core::interpolate(pose_a, pose_b, alpha);  // slerp for attitude
  fused.heading_rad = sss::core::wrapAngle(a->heading_rad + alpha * sss::core::wrapAngle(b->heading_rad - a->heading_rad));
  fused.roll_rad = a->roll_rad + alpha * (b->roll_rad - a->roll_rad);
  fused.distance_travelled_m = a->distance_travelled_m + alpha * (b->distance_travelled_m - a->distance_travelled_m);

  // Heading rate over heading_rate_window_s centred on the ping (a one-sided window would lag
  // the start of a turn by half a window and put its first pings into the line): the
  // least-squares slope of the unwrapped heading over every nav sample in the window, so that
  // INS heading noise (the paper's study adds up to 0.05 rad) does not read as a turn. The fitted
  // heading at the ping is the steady heading the line segmentation compares.
  fused.steady_heading_rad = fused.heading_rad;
  const int64_t half_window_us = static_cast<int64_t>(0.5 * options_.heading_rate_window_s * 1e6);
  auto w0 = std::lower_bound(history_.begin(), a, t - half_window_us,
                             [](const NavInput& n, int64_t time) { return n.utime_us < time; });
  auto w1 = std::lower_bound(b, history_.end(), t + half_window_us,
                             [](const NavInput& n, int64_t time) { return n.utime_us < time; });
  if (w1 == history_.end()) w1 = std::prev(history_.end());
  if (w1->utime_us > w0->utime_us) {
    double n = 0.0, sum_t = 0.0, sum_h = 0.0, sum_tt = 0.0, sum_th = 0.0;
    double unwrapped = 0.0;
    for (auto it = w0; it != std::next(w1); ++it) {
      if (it != w0) unwrapped += sss::core::wrapAngle(it->heading_rad - std::prev(it)->heading_rad);
      const double dt_s = static_cast<double>(it->utime_us - t) * 1e-6;
      n += 1.0;
      sum_t += dt_s;
      sum_h += unwrapped;
      sum_tt += dt_s * dt_s;
      sum_th += dt_s * unwrapped;
    }
    const double denominator = n * sum_tt - sum_t * sum_t;
    if (denominator > 0.0) {
      const double slope = (n * sum_th - sum_t * sum_h) / denominator;
      const double at_ping = (sum_h - slope * sum_t) / n;  // fitted unwrapped heading at t
      fused.heading_rate_rad_s = slope;
      fused.steady_heading_rad = sss::core::wrapAngle(w0->heading_rad + at_ping);
    }
  }
  if (options_.pose_heading_from_fit) {
    // The sonar's fan turns with the vehicle, which does not turn as fast as INS heading noise:
    // the fitted heading geo-references the ping and frames the subframe (a single noisy centre
    // heading would rotate every relative pose built on it).
    const sss::core::EulerAngles euler = sss::core::eulerFromQuaternion(fused.T_world_body.rotation);
    fused.T_world_body.rotation = sss::core::quaternionFromEuler(euler.roll_rad, euler.pitch_rad, fused.steady_heading_rad);
    fused.heading_rad = fused.steady_heading_rad;
  }

  // Altitude of the sonar: DVL altitude of the body, shifted by the lever arm's vertical
  // component in the world (a sonar mounted below the body origin is closer to the seabed).
  // An altitude beyond the ping's last sample is impossible (the seabed would be out of range).
  const double max_range_m =
      ping.start_range_m + ping.sampleSpacingM() * static_cast<double>(std::max(ping.port.size(), ping.starboard.size()));
  auto plausible = [&](double altitude_m) {
    if (!(altitude_m >= options_.min_altitude_m)) return false;
    if (max_range_m > ping.start_range_m && altitude_m >= max_range_m) {
      ++counters_.altitude_implausible;
      return false;
    }
    return true;
  };
  const double sonar_down_offset_m = (fused.T_world_body.rotation * T_body_sonar_.translation).z();
  const bool nav_altitude_ok = a->altitude_valid && b->altitude_valid && a->altitude_m >= options_.min_altitude_m &&
                               b->altitude_m >= options_.min_altitude_m;
  const double nav_altitude_m = a->altitude_m + alpha * (b->altitude_m - a->altitude_m) - sonar_down_offset_m;
  // The tracker follows every ping whenever it may be used, so that its track is warm when the
  // navigation's altitude stops.
  BottomTrack bottom;
  if (options_.altitude_source != AltitudePolicy::kNav) {
    bottom = bottom_tracker_.track(ping.port, ping.starboard, ping.start_range_m, ping.sampleSpacingM());
  }
  bool have_altitude = false;
  if (options_.altitude_source != AltitudePolicy::kBottomTrack) {
    if (nav_altitude_ok && plausible(nav_altitude_m)) {
      fused.altitude_m = nav_altitude_m;
      fused.altitude_source = AltitudeSource::kNav;
      ++counters_.altitude_from_nav;
      have_altitude = true;
    } else if (ping.altitude_m >= options_.min_altitude_m && plausible(ping.altitude_m)) {
      // The sonar's own altitude is measured at the sonar.
      fused.altitude_m = ping.altitude_m;
      fused.altitude_from_ping = true;
      fused.altitude_source = AltitudeSource::kPingHeader;
      ++counters_.altitude_from_ping;
      have_altitude = true;
    }
  }
  if (have_altitude && bottom.valid && bottom.altitude_m > 0.0) {
    const double ratio = fused.altitude_m / bottom.altitude_m;
    if (ratio > 0.5 && ratio < 1.5) {  // else one of them is lost (a fish, a DVL dropout)
      altitude_ratios_.push_back(ratio);
      while (static_cast<int>(altitude_ratios_.size()) > options_.bottom_track_calibration_pings) altitude_ratios_.pop_front();
    }
  }
  if (!have_altitude && options_.altitude_source != AltitudePolicy::kNav && bottom.valid &&
      bottom.altitude_m >= options_.min_altitude_m) {
    double scale = 1.0;
    if (static_cast<int>(altitude_ratios_.size()) >= options_.min_bottom_track_calibration_pings) {
      std::vector<double> ratios(altitude_ratios_.begin(), altitude_ratios_.end());
      std::nth_element(ratios.begin(), ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2), ratios.end());
      scale = ratios[ratios.size() / 2];
    }
    counters_.bottom_track_scale = scale;
    fused.altitude_m = scale * bottom.altitude_m;  // a slant range measured at the sonar
    fused.altitude_source = AltitudeSource::kBottomTrack;
    fused.bottom_track_quality = bottom.quality;
    ++counters_.altitude_from_bottom_track;
    have_altitude = true;
  }
  if (!have_altitude || fused.altitude_m < options_.min_altitude_m) {
    ++counters_.dropped_no_altitude;
    return false;
  }
  fused.ping = std::move(ping);
  out.push_back(std::move(fused));
  return true;
}

size_t PingNavFusion::memoryBytes() const {
  size_t bytes = history_.size() * sizeof(NavInput) + recent_numbers_.size() * sizeof(int64_t);
  for (const PingInput& p : pending_) bytes += sizeof(PingInput) + (p.port.capacity() + p.starboard.capacity()) * sizeof(float);
  return bytes;
}

}  // namespace sss::subframe
