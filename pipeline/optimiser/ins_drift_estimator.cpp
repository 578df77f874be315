#include "pipeline/optimiser/ins_drift_estimator.hpp"

#include <algorithm>
#include <cmath>

namespace sss::optimiser {

void InsDriftEstimator::add(double distance_travelled_m, double sigma_m) {
  if (!std::isfinite(distance_travelled_m) || !std::isfinite(sigma_m) || sigma_m <= 0.0) return;
  InsDriftState& s = state_;
  ++s.reports;
  // A new minimum of the sigma (an aiding, or the start) or an odometer that went back (a restart
  // of the INS bridge): a new stretch starts here.
  if (!s.started || sigma_m <= s.min_sigma_m || distance_travelled_m < s.last_distance_m) {
    s.started = true;
    s.min_distance_m = distance_travelled_m;
    s.min_sigma_m = sigma_m;
    s.last_distance_m = distance_travelled_m;
    return;
  }
  s.last_distance_m = distance_travelled_m;
  const double distance_m = distance_travelled_m - s.min_distance_m;
  const double growth_m = sigma_m - s.min_sigma_m;
  if (distance_m < options_.min_distance_m || growth_m < options_.min_growth_m) return;
  s.estimate = std::clamp(growth_m / distance_m, options_.min_fraction, options_.max_fraction);
}

bool InsDriftEstimator::restore(const InsDriftState& state) {
  const bool finite = std::isfinite(state.min_distance_m) && std::isfinite(state.min_sigma_m) &&
                      std::isfinite(state.last_distance_m) && state.min_sigma_m >= 0.0 && state.reports >= 0;
  if (!finite || (state.estimate && !(std::isfinite(*state.estimate) && *state.estimate >= 0.0))) return false;
  state_ = state;
  // Clamped as add() would (the configured range may have changed since the checkpoint was written).
  if (state_.estimate) state_.estimate = std::clamp(*state_.estimate, options_.min_fraction, options_.max_fraction);
  return true;
}

}  // namespace sss::optimiser
