// Dead-reckoning integration: DVL body velocity with scale factor, bias and noise, rotated by the
// INS attitude with heading bias and random walk, summed at the nav rate from the true start pose.
#include "tools/sim/dead_reckoning.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace sss::sim {

DeadReckoning::DeadReckoning(const DeadReckoningOptions& options, const Trajectory& trajectory, double duration_s)
    : options_(options) {
  if (options.rate_hz <= 0.0) throw std::invalid_argument("DeadReckoning: rate_hz must be positive");
  std::mt19937_64 rng(mixSeed(options.seed, 3001));
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const auto signedMagnitude = [&](double min, double max) {
    const double magnitude = min + (max - min) * uniform(rng);
    return (uniform(rng) < 0.5 ? -1.0 : 1.0) * magnitude;
  };
  const double k = options.drift_scale;
  scale_factor_ = k * signedMagnitude(options.velocity_scale_factor_min, options.velocity_scale_factor_max);
  heading_bias_rad_ = k * signedMagnitude(options.heading_bias_min_rad, options.heading_bias_max_rad);
  const double roll_bias = k * signedMagnitude(0.0, options.attitude_bias_rad);
  const double pitch_bias = k * signedMagnitude(0.0, options.attitude_bias_rad);
  // Drawn after the others so adding it left the earlier constants of a seed unchanged.
  heading_deviation_rad_ = k * std::abs(signedMagnitude(options.heading_deviation_min_rad, options.heading_deviation_max_rad));
  heading_deviation_phase_rad_ = 2.0 * M_PI * uniform(rng);
  // A separate stream for the study noise, so switching it on leaves the base errors unchanged.
  std::mt19937_64 study_rng(mixSeed(options.seed, 3002));

  const double dt = 1.0 / options.rate_hz;
  const auto count = static_cast<size_t>(std::floor(duration_s * options.rate_hz + 1e-9)) + 1;
  samples_.reserve(count);

  const TrajectorySample first = trajectory.sample(0.0);
  Eigen::Vector3d position = first.T_world_body.translation;
  double heading_walk = 0.0;
  double study_heading_noise = 0.0;
  double next_study_draw_s = 0.0;
  for (size_t i = 0; i < count; ++i) {
    const double t = i * dt;
    const TrajectorySample truth = trajectory.sample(t);
    const sss::core::EulerAngles true_euler = sss::core::eulerFromQuaternion(truth.T_world_body.rotation);

    if (options.heading_noise_rad > 0.0 && t >= next_study_draw_s - 1e-9) {
      study_heading_noise = options.heading_noise_rad * gauss(study_rng);
      next_study_draw_s += options.heading_noise_interval_s;
    }
    const double heading = sss::core::wrapAngle(true_euler.heading_rad + headingErrorRad(true_euler.heading_rad) + heading_walk);
    const double roll = true_euler.roll_rad + roll_bias + k * options.attitude_noise_rad * gauss(rng);
    const double pitch = true_euler.pitch_rad + pitch_bias + k * options.attitude_noise_rad * gauss(rng);

    NavSample nav;
    nav.time_s = t;
    nav.heading_rad = sss::core::wrapAngle(heading + study_heading_noise);
    nav.roll_rad = roll;
    nav.pitch_rad = pitch;
    nav.altitude_m = truth.altitude_m + 0.05 * gauss(rng);
    // Sample 0 is the true pose: the INS is initialised from a GNSS fix at the dive start.
    const Eigen::Vector3d true_position = truth.T_world_body.translation;
    if (i == 0) {
      nav.T_world_body = truth.T_world_body;
      nav.velocity_world_m_s = truth.velocity_world_m_s;
    } else {
      // DVL measures velocity in the body frame; the INS rotates it with its own attitude.
      const Eigen::Vector3d velocity_body = truth.T_world_body.rotation.conjugate() * truth.velocity_world_m_s;
      Eigen::Vector3d measured_body = (1.0 + scale_factor_) * velocity_body;
      for (int axis = 0; axis < 3; ++axis) measured_body[axis] += k * options.velocity_white_noise_m_s * gauss(rng);
      const Eigen::Quaterniond q_increment =
          sss::core::quaternionFromEuler(roll, pitch, heading + study_heading_noise);
      const Eigen::Vector3d velocity_world = q_increment * measured_body;
      position += velocity_world * dt;
      // Depth comes from the pressure sensor, not from integration: DR drifts only horizontally.
      position.z() = true_position.z() + k * options.depth_noise_m * gauss(rng);
      nav.T_world_body = sss::core::Pose(q_increment, position);
      nav.velocity_world_m_s = velocity_world;
      distance_m_ += truth.velocity_world_m_s.head<2>().norm() * dt;
    }
    nav.position_std_m = options.reported_start_std_m + k * options.reported_drift_fraction * distance_m_;
    samples_.push_back(nav);
    heading_walk += k * options.heading_random_walk_rad_per_sqrt_s * std::sqrt(dt) * gauss(rng);
  }
}

NavSample DeadReckoning::sampleAt(double time_s) const {
  const double dt = 1.0 / options_.rate_hz;
  const double index = std::clamp(time_s / dt, 0.0, static_cast<double>(samples_.size() - 1));
  const auto i0 = static_cast<size_t>(std::floor(index));
  const size_t i1 = std::min(i0 + 1, samples_.size() - 1);
  const double alpha = index - i0;
  NavSample out = samples_[i0];
  const NavSample& b = samples_[i1];
  out.time_s = time_s;
  out.T_world_body = sss::core::interpolate(samples_[i0].T_world_body, b.T_world_body, alpha);
  out.velocity_world_m_s += alpha * (b.velocity_world_m_s - out.velocity_world_m_s);
  out.altitude_m += alpha * (b.altitude_m - out.altitude_m);
  const sss::core::EulerAngles euler = sss::core::eulerFromQuaternion(out.T_world_body.rotation);
  out.heading_rad = euler.heading_rad;
  out.pitch_rad = euler.pitch_rad;
  out.roll_rad = euler.roll_rad;
  out.position_std_m += alpha * (b.position_std_m - out.position_std_m);
  return out;
}

sss::core::Pose DeadReckoning::poseAt(double time_s) const { return sampleAt(time_s).T_world_body; }

double DeadReckoning::headingErrorRad(double true_heading_rad) const {
  return heading_bias_rad_ + heading_deviation_rad_ * std::cos(true_heading_rad - heading_deviation_phase_rad_);
}

}  // namespace sss::sim
