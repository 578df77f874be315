#include "pipeline/optimiser/ins_drift_estimator.hpp"

#include <algorithm>
#include <cmath>

namespace sss::optimiser {

void InsDriftEstimator::add(double distance_travelled_m, double sigma_m) {
  if (!std::isfinite(distance_travelled_m) || !std::isfinite(sigma_m) || sigma_m <= 0.0) return;
  ++reports_;
  // A new minimum of the sigma (an aiding, or the start) or an odometer that went back (a restart
  // of the INS bridge): a new stretch starts here.
  if (!started_ || sigma_m <= min_sigma_m_ || distance_travelled_m < last_distance_m_) {
    started_ = true;
    min_distance_m_ = distance_travelled_m;
    min_sigma_m_ = sigma_m;
    last_distance_m_ = distance_travelled_m;
    return;
  }
  last_distance_m_ = distance_travelled_m;
  const double distance_m = distance_travelled_m - min_distance_m_;
  const double growth_m = sigma_m - min_sigma_m_;
  if (distance_m < options_.min_distance_m || growth_m < options_.min_growth_m) return;
  estimate_ = std::clamp(growth_m / distance_m, options_.min_fraction, options_.max_fraction);
}

}  // namespace sss::optimiser
