// INS/DVL dead-reckoning error model: integrates DVL velocity (scale factor, bias, white noise)
// with an INS heading (bias, random walk, optional paper-style heading noise) along the true path.
#pragma once

#include "pipeline/core/pose.hpp"
#include "tools/sim/trajectory.hpp"

#include <cstdint>
#include <vector>

namespace sss::sim {

struct DeadReckoningOptions {
  uint64_t seed = 1;
  double rate_hz = 20.0;                       // integration and INS output rate
  double drift_scale = 1.0;                    // multiplies every error magnitude below
  // Per-mission constants drawn with a random sign and a magnitude uniform in [min, max]:
  // straight-line drift ~ hypot(scale factor, heading bias) = 0.14-0.42 % of distance.
  double velocity_scale_factor_min = 0.001;
  double velocity_scale_factor_max = 0.003;
  double heading_bias_min_rad = 0.0005;        // 0.03-0.09 deg, a good INS after alignment
  double heading_bias_max_rad = 0.0015;
  // Heading error that depends on the heading, one cycle per revolution (residual gyrocompass
  // speed/latitude error, alignment residuals): amplitude drawn in [min, max], random phase.
  // Unlike a constant bias it does not cancel on the reversed lines of a lawnmower survey, which
  // is what makes real DR drift on such surveys.
  double heading_deviation_min_rad = 0.001;
  double heading_deviation_max_rad = 0.002;
  double heading_random_walk_rad_per_sqrt_s = 2e-5;
  double velocity_white_noise_m_s = 0.005;     // DVL bottom-track noise per sample
  double attitude_noise_rad = 0.0002;          // roll/pitch output noise (white)
  double attitude_bias_rad = 0.0005;           // roll/pitch bias magnitude (random sign)
  double depth_noise_m = 0.02;                 // pressure depth noise
  // Paper robustness study: Gaussian noise of this std is added to the heading used for each DR
  // increment (every heading_noise_interval_s), independently per increment. Not scaled by
  // drift_scale.
  double heading_noise_rad = 0.0;
  double heading_noise_interval_s = 0.25;      // one ping at 4 Hz, as the paper's per-ping DR
  // The accuracy the INS reports (STDPOS, STDHRP): its specification for the error ranges above,
  // scaled like them by drift_scale (an INS knows its own class, not the errors it drew): the
  // start's reported_start_std_m (the GNSS it was initialised from) growing per axis by
  // reported_drift_fraction of the distance travelled (the rms of the scale factor and heading
  // errors drawn above, ~0.002), and reported_heading_std_rad.
  double reported_start_std_m = 0.5;
  double reported_drift_fraction = 0.002;
  double reported_heading_std_rad = 0.002;
};

struct NavSample {
  double time_s = 0.0;
  sss::core::Pose T_world_body;              // DR estimate
  Eigen::Vector3d velocity_world_m_s = Eigen::Vector3d::Zero();
  double altitude_m = 0.0;                   // DVL altitude (true + small noise)
  double heading_rad = 0.0;
  double pitch_rad = 0.0;
  double roll_rad = 0.0;
  double position_std_m = 0.0;               // the INS's own growing horizontal uncertainty
};

class DeadReckoning {
 public:
  // Integrates over [0, duration_s] at rate_hz; sample 0 is the true pose at time 0.
  DeadReckoning(const DeadReckoningOptions& options, const Trajectory& trajectory, double duration_s);

  const std::vector<NavSample>& samples() const { return samples_; }
  // Interpolated DR pose at any time within the integrated span (clamped outside).
  sss::core::Pose poseAt(double time_s) const;
  NavSample sampleAt(double time_s) const;

  // The drawn per-mission error constants (for mission.yaml and tests).
  double velocityScaleFactor() const { return scale_factor_; }
  double headingBiasRad() const { return heading_bias_rad_; }
  double headingDeviationRad() const { return heading_deviation_rad_; }
  double headingDeviationPhaseRad() const { return heading_deviation_phase_rad_; }
  // The heading error (without random walk and study noise) at a true heading.
  double headingErrorRad(double true_heading_rad) const;
  double distanceTravelledM() const { return distance_m_; }

 private:
  DeadReckoningOptions options_;
  std::vector<NavSample> samples_;
  double scale_factor_ = 0.0;
  double heading_bias_rad_ = 0.0;
  double heading_deviation_rad_ = 0.0;
  double heading_deviation_phase_rad_ = 0.0;
  double distance_m_ = 0.0;
};

}  // namespace sss::sim
