// Fixes tied to the navigation, see fix_aligner.hpp.
#include "drivers/ins/fix_aligner.hpp"

#include <algorithm>

namespace sss::ins {

FixAligner::FixAligner(const FixAlignerOptions& options) : options_(options) {}

void FixAligner::addNav(int64_t utime_us, const Eigen::Vector3d& position_ned_m, double distance_travelled_m,
                        const std::optional<sss::core::MissionOrigin>& origin) {
  if (!history_.empty() && utime_us <= history_.back().utime_us) return;
  if (!position_ned_m.allFinite()) return;
  if (origin && !origin_) {
    origin_ = origin;
    plane_.emplace(origin->latitude_deg, origin->longitude_deg);
  }
  history_.push_back({utime_us, position_ned_m, distance_travelled_m});
  // Keep what a late fix may still need (and always the newest two samples).
  const int64_t keep_from_us = utime_us - static_cast<int64_t>(options_.max_latency_s * 1e6);
  while (history_.size() > 2 && history_[1].utime_us <= keep_from_us) history_.pop_front();
  if (!undated_.empty()) {
    // Fixes with a time of day only take the navigation's day (and run on across midnight).
    resolveFixDates(undated_, utime_us);
    waiting_.insert(waiting_.end(), undated_.begin(), undated_.end());
    undated_.clear();
  }
}

void FixAligner::addFix(const PositionFix& fix) {
  ++counters_.fixes_in;
  if (fix.dated) {
    waiting_.push_back(fix);
  } else if (history_.empty()) {
    undated_.push_back(fix);
  } else {
    std::vector<PositionFix> one = {fix};
    resolveFixDates(one, history_.back().utime_us);
    waiting_.push_back(one.front());
  }
}

std::vector<AlignedFix> FixAligner::take(bool final) {
  std::vector<AlignedFix> out;
  if (final) {
    counters_.outside_navigation += undated_.size();  // never any navigation to date them by
    undated_.clear();
  }
  if (waiting_.empty()) return out;
  std::stable_sort(waiting_.begin(), waiting_.end(),
                   [](const PositionFix& a, const PositionFix& b) { return a.utime_us < b.utime_us; });
  const int64_t newest_us = history_.empty() ? INT64_MIN : history_.back().utime_us;
  size_t done = 0;
  for (; done < waiting_.size(); ++done) {
    if (!final && waiting_[done].utime_us > newest_us) break;  // the navigation has not got there yet
    AlignedFix aligned;
    if (align(waiting_[done], aligned)) out.push_back(aligned);
  }
  waiting_.erase(waiting_.begin(), waiting_.begin() + static_cast<std::ptrdiff_t>(done));
  return out;
}

bool FixAligner::align(const PositionFix& fix, AlignedFix& out) {
  if (!plane_) {
    ++counters_.no_frame;
    return false;
  }
  const int64_t tolerance_us = static_cast<int64_t>(options_.max_extrapolation_s * 1e6);
  if (history_.empty() || fix.utime_us < history_.front().utime_us - tolerance_us ||
      fix.utime_us > history_.back().utime_us + tolerance_us) {
    ++counters_.outside_navigation;
    return false;
  }
  // The DR state at the fix time: linear between the bracketing samples, held at either end.
  NavPoint at = fix.utime_us <= history_.front().utime_us ? history_.front() : history_.back();
  const auto after = std::lower_bound(history_.begin(), history_.end(), fix.utime_us,
                                      [](const NavPoint& p, int64_t t) { return p.utime_us < t; });
  if (after != history_.begin() && after != history_.end()) {
    const NavPoint& a = *(after - 1);
    const NavPoint& b = *after;
    const double alpha = static_cast<double>(fix.utime_us - a.utime_us) / static_cast<double>(b.utime_us - a.utime_us);
    at.position_ned_m = a.position_ned_m + alpha * (b.position_ned_m - a.position_ned_m);
    at.distance_m = a.distance_m + alpha * (b.distance_m - a.distance_m);
  }
  if (fix.source == FixSource::kGnss && at.position_ned_m.z() > options_.gnss_max_depth_m) {
    ++counters_.below_surface;
    return false;
  }
  out.fix = fix;
  out.position_ne_m = plane_->toNed({fix.latitude_deg, fix.longitude_deg, 0.0}).head<2>();
  out.covariance_m2 = Eigen::Vector2d(fix.sigma_north_m * fix.sigma_north_m, fix.sigma_east_m * fix.sigma_east_m).asDiagonal();
  out.dr_position_m = at.position_ned_m;
  out.dr_distance_m = at.distance_m;
  out.depth_m = at.position_ned_m.z();
  ++counters_.aligned;
  return true;
}

}  // namespace sss::ins
