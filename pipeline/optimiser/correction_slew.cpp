// Bounded-rate correction, see correction_slew.hpp.
#include "pipeline/optimiser/correction_slew.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace sss::optimiser {

using sss::core::Pose;

std::vector<std::string> validateCorrectionSlewOptions(const CorrectionSlewOptions& o) {
  std::vector<std::string> problems;
  if (!(o.max_rate_m_s >= 0.0)) problems.push_back("correction_max_rate_m_s must be >= 0 (0: no bound)");
  if (!(o.max_heading_rate_rad_s > 0.0)) problems.push_back("correction_max_heading_rate_rad_s must be > 0");
  if (!(o.report_jump_m > 0.0)) problems.push_back("correction_report_jump_m must be > 0");
  return problems;
}

void readCorrectionSlewOptions(sss::core::ConfigSection& section, CorrectionSlewOptions& options) {
  using sss::core::greaterThan;
  using sss::core::inRange;
  section.optional("correction_max_rate_m_s", options.max_rate_m_s, {inRange(0.0, 100.0)});
  section.optional("correction_max_heading_rate_rad_s", options.max_heading_rate_rad_s, {greaterThan(0.0)});
  section.optional("correction_report_jump_m", options.report_jump_m, {greaterThan(0.0)});
}

CorrectionSlew::CorrectionSlew(const CorrectionSlewOptions& options) : options_(options) {}

std::optional<double> CorrectionSlew::takeNewJump() {
  std::optional<double> out;
  out.swap(new_jump_m_);
  return out;
}

Correction CorrectionSlew::apply(const Correction& target, int64_t utime_us) {
  const Pose& goal = target.T_corrected_dr;
  if (last_target_) {
    const double jump_m = (goal.translation - last_target_->translation).norm();
    if (jump_m > 0.0) last_jump_m_ = jump_m;
    if (jump_m >= options_.report_jump_m) {
      ++jumps_;
      new_jump_m_ = jump_m;
    }
  }
  last_target_ = goal;
  Correction out = target;
  if (!published_ || options_.max_rate_m_s <= 0.0 || utime_us < last_utime_us_) {
    published_ = goal;
  } else {
    const double dt_s = 1e-6 * static_cast<double>(utime_us - last_utime_us_);
    const double distance_m = (goal.translation - published_->translation).norm();
    const double angle_rad = Eigen::AngleAxisd(published_->rotation.conjugate() * goal.rotation).angle();
    // The fraction of the way both bounds allow this step.
    double fraction = 1.0;
    if (distance_m > options_.max_rate_m_s * dt_s) fraction = std::min(fraction, options_.max_rate_m_s * dt_s / distance_m);
    if (angle_rad > options_.max_heading_rate_rad_s * dt_s)
      fraction = std::min(fraction, options_.max_heading_rate_rad_s * dt_s / angle_rad);
    published_ = fraction >= 1.0 ? goal : sss::core::interpolate(*published_, goal, fraction);
  }
  last_utime_us_ = utime_us;
  lag_m_ = (goal.translation - published_->translation).norm();
  lag_heading_rad_ = Eigen::AngleAxisd(published_->rotation.conjugate() * goal.rotation).angle();
  out.T_corrected_dr = *published_;
  // What is still to go is error of the published pose.
  for (int i = 0; i < 3; ++i) out.covariance(i, i) += lag_m_ * lag_m_;
  for (int i = 3; i < 6; ++i) out.covariance(i, i) += lag_heading_rad_ * lag_heading_rad_;
  return out;
}

}  // namespace sss::optimiser
