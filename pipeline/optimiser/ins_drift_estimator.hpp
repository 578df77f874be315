// The INS's own drift rate, read from the position accuracy it reports. In dead reckoning an
// INS's reported 1-sigma position error grows in proportion to the distance travelled (its
// specification, e.g. "0.1 % of distance travelled", from its DVL scale and heading accuracy);
// that rate is the pose graph's odometry drift fraction for this vehicle, where the configured
// odometry_drift_fraction is one guess for every INS. A closure set is then held against the DR
// this INS actually gives: a good INS is not bent by closures noisier than itself, a poor one
// gives way to them.
#pragma once

#include <optional>

namespace sss::optimiser {

struct InsDriftEstimatorOptions {
  // Distance travelled since the reported sigma's last minimum (the INS's last aiding: its start,
  // a GNSS fix at the surface) before a rate is given: a short stretch says little.
  double min_distance_m = 300.0;
  // Growth of the reported sigma over that stretch below this: the INS does not report a
  // dead-reckoning model (a constant or aided accuracy), and no rate is given.
  double min_growth_m = 0.1;
  // The rate given is clamped to this range (per axis, fraction of distance travelled).
  double min_fraction = 0.0005;
  double max_fraction = 0.02;
};

// What the estimator has learnt, as a checkpoint keeps it (the engine's checkpoint stores it, so a
// restarted optimiser does not wait for another 300 m of drift).
struct InsDriftState {
  bool started = false;
  double min_distance_m = 0.0;  // odometer and sigma at the stretch's start (the sigma's minimum)
  double min_sigma_m = 0.0;
  double last_distance_m = 0.0;
  std::optional<double> estimate;
  int reports = 0;
};

// Feed it the INS's reports in time order; it tracks the sigma's growth since its last minimum.
class InsDriftEstimator {
 public:
  explicit InsDriftEstimator(const InsDriftEstimatorOptions& options = {}) : options_(options) {}

  // One report: the INS odometer (m) and its horizontal position 1-sigma per axis (m). Reports
  // without a finite, positive sigma or a finite distance are ignored (not reported).
  void add(double distance_travelled_m, double sigma_m);

  // The drift fraction: the newest stretch's growth over its distance, once one qualified (then
  // kept until a newer stretch qualifies: after an aiding the INS first has to drift again).
  std::optional<double> driftFraction() const { return state_.estimate; }
  int reports() const { return state_.reports; }

  const InsDriftState& state() const { return state_; }
  // From a checkpoint: false (and nothing changed) when a value is not finite or negative; the
  // estimate is clamped to this estimator's range (the configuration may have changed since).
  bool restore(const InsDriftState& state);

 private:
  InsDriftEstimatorOptions options_;
  InsDriftState state_;
};

}  // namespace sss::optimiser
