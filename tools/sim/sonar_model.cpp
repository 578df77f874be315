// Side-scan ping formation by ray casting: seabed profile in the fan plane, horizon test for
// shadows, per-segment backscatter spread over the range bins it spans, then speckle and noise.
#include "tools/sim/sonar_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sss::sim {
namespace {

constexpr double kLn2 = 0.69314718055994530942;

// Counter-based generator: one stream per (seed, ping, side), cheap and identical on any thread.
struct SplitMix {
  uint64_t state;
  uint64_t next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in (0, 1].
  double uniform() { return (static_cast<double>(next() >> 11) + 1.0) * (1.0 / 9007199254740992.0); }
  double normal() {  // Box-Muller, one of the pair
    return std::sqrt(-2.0 * std::log(uniform())) * std::cos(2.0 * 3.14159265358979323846 * uniform());
  }
  // Gamma(shape, scale 1/shape): mean 1, variance 1/shape (Marsaglia and Tsang 2000).
  double unitMeanGamma(double shape) {
    if (shape < 1.0) return unitMeanGamma(shape + 1.0) * (shape + 1.0) / shape * std::pow(uniform(), 1.0 / shape);
    const double d = shape - 1.0 / 3.0;
    const double c = 1.0 / std::sqrt(9.0 * d);
    for (;;) {
      const double x = normal();
      const double v = std::pow(1.0 + c * x, 3);
      if (v <= 0.0) continue;
      if (std::log(uniform()) < 0.5 * x * x + d - d * v + d * std::log(v)) return d * v / shape;
    }
  }
};

}  // namespace

FanPlane fanPlane(const sss::core::Pose& T_world_sonar, Side side) {
  FanPlane plane;
  plane.origin = T_world_sonar.translation;
  plane.normal = T_world_sonar.rotation * Eigen::Vector3d::UnitX();
  Eigen::Vector3d outward = Eigen::Vector3d::UnitZ().cross(plane.normal);
  if (outward.norm() < 1e-9) throw std::invalid_argument("fanPlane: vehicle pointing vertically");
  outward.normalize();
  const Eigen::Vector3d starboard = T_world_sonar.rotation * Eigen::Vector3d::UnitY();
  if (outward.dot(starboard) < 0.0) outward = -outward;
  if (side == Side::kPort) outward = -outward;
  plane.outward = outward;
  Eigen::Vector3d down = plane.normal.cross(outward).normalized();
  if (down.z() < 0.0) down = -down;
  plane.down = down;
  return plane;
}

std::vector<ProfilePoint> castProfile(const Seabed& seabed, const sss::core::Pose& T_world_sonar, Side side,
                                      const SonarOptions& options) {
  const FanPlane plane = fanPlane(T_world_sonar, side);
  const double step = options.ground_step_m;
  const int count = static_cast<int>(std::ceil(options.range_m / step)) + 1;
  std::vector<ProfilePoint> profile;
  profile.reserve(count);
  double min_tan_depression = 1e300;
  for (int k = 0; k < count; ++k) {
    // Start a hair off nadir so the depression angle is defined.
    const double u = std::max(k * step, 1e-3);
    const Eigen::Vector3d base = plane.origin + u * plane.outward;
    // Find v with base + v * down on the seabed; pitch tilts `down`, so refine once.
    double v = (seabed.depthM(base.x(), base.y()) - base.z()) / plane.down.z();
    Eigen::Vector3d p = base + v * plane.down;
    v += (seabed.depthM(p.x(), p.y()) - p.z()) / plane.down.z();
    p = base + v * plane.down;
    ProfilePoint point;
    point.position_ned_m = p;
    point.slant_range_m = (p - plane.origin).norm();
    // Horizon test: visible only if no nearer point is seen at a shallower depression angle.
    const double tan_depression = v / u;
    point.visible = tan_depression <= min_tan_depression;
    min_tan_depression = std::min(min_tan_depression, tan_depression);
    profile.push_back(point);
    if (u > options.range_m) break;
  }
  return profile;
}

SonarModel::SonarModel(const SonarOptions& options, const Seabed* seabed) : options_(options), seabed_(seabed) {
  if (options.samples_per_side < 16) throw std::invalid_argument("SonarModel: samples_per_side must be >= 16");
  if (options.range_m <= 0.0 || options.sound_speed_m_s <= 0.0) throw std::invalid_argument("SonarModel: bad range");
  const double bin = options.sampleSpacingM();
  const double alpha_db_per_m = options.absorption_db_per_km / 1000.0;
  const double tvg_alpha_db_per_m = options.tvgAbsorptionDbPerKm() / 1000.0;
  noise_intensity_.resize(options.samples_per_side);
  tvg_residual_.resize(options.samples_per_side);
  for (int i = 0; i < options.samples_per_side; ++i) {
    const double r = std::max(i * bin, bin);
    // Receiver noise is flat before the TVG, so after it the noise rises with range exactly as
    // the TVG gain does: dark water column, grainy far range.
    const double tvg_db_rel = options.tvg_spreading_db_per_decade * std::log10(r / options.range_m) +
                              2.0 * tvg_alpha_db_per_m * (r - options.range_m);
    noise_intensity_[i] = options.noise_intensity_at_max_range * std::pow(10.0, tvg_db_rel / 10.0);
    // The signal model below is the echo after a TVG of 30 log r + 2 alpha r (true alpha); a TVG
    // of another law leaves this much, 0 dB at max range.
    const double residual_db = (options.tvg_spreading_db_per_decade - 30.0) * std::log10(r / options.range_m) +
                               2.0 * (tvg_alpha_db_per_m - alpha_db_per_m) * (r - options.range_m);
    tvg_residual_[i] = std::pow(10.0, residual_db / 10.0);
  }
}

double SonarModel::gainStepDb(uint32_t ping_number, Side side) const {
  if (options_.gain_step_interval_s <= 0.0 || options_.gain_step_sigma_db <= 0.0) return 0.0;
  const double time_s = ping_number / options_.ping_rate_hz;
  const auto step = static_cast<uint64_t>(std::floor(time_s / options_.gain_step_interval_s));
  SplitMix common{mixSeed(options_.seed ^ 0x6A1Eull, step)};
  SplitMix own{mixSeed(options_.seed ^ 0x6A1Full, 2 * step + static_cast<uint64_t>(side))};
  return options_.gain_step_sigma_db * (common.normal() + own.normal() / 3.0);
}

std::vector<double> SonarModel::accumulate(const sss::core::Pose& T_world_sonar, Side side) const {
  const int n = options_.samples_per_side;
  const double bin = options_.sampleSpacingM();
  std::vector<double> energy(n, 0.0);
  const std::vector<ProfilePoint> profile = castProfile(*seabed_, T_world_sonar, side, options_);
  const Eigen::Quaterniond world_to_body = T_world_sonar.rotation.conjugate();
  const Eigen::Vector3d along = T_world_sonar.rotation * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d origin = T_world_sonar.translation;
  const double res = seabed_->options().resolution_m;
  const double beam_k = 4.0 * kLn2 / (options_.vertical_beam_width_rad * options_.vertical_beam_width_rad);

  for (size_t k = 1; k < profile.size(); ++k) {
    const ProfilePoint& a = profile[k - 1];
    const ProfilePoint& b = profile[k];
    // A segment with a shadowed end is not ensonified: its bins stay dark.
    if (!a.visible || !b.visible) continue;
    const Eigen::Vector3d mid = 0.5 * (a.position_ned_m + b.position_ned_m);
    const Eigen::Vector3d ray = mid - origin;
    const double r = ray.norm();
    if (r > options_.range_m) continue;
    const Eigen::Vector3d ray_dir = ray / r;
    const Eigen::Vector3d up_normal = seabed_->normal(mid.x(), mid.y());
    const double cos_incidence = std::max(0.0, -ray_dir.dot(up_normal));
    // The beam's along-track footprint averages reflectivity over r * beam width.
    const double footprint = r * options_.horizontal_beam_width_rad;
    double reflect = seabed_->reflectivity(mid.x(), mid.y());
    if (footprint > 2.0 * res) {
      const Eigen::Vector3d offset = along * (footprint / 3.0);
      reflect = (reflect + seabed_->reflectivity(mid.x() + offset.x(), mid.y() + offset.y()) +
                 seabed_->reflectivity(mid.x() - offset.x(), mid.y() - offset.y())) / 3.0;
    }
    const Eigen::Vector3d ray_body = world_to_body * ray_dir;
    const double elevation = std::atan2(ray_body.z(), std::abs(ray_body.y()));
    const double off_axis = elevation - options_.depression_rad;
    const double beam = std::max(options_.sidelobe_level, std::exp(-beam_k * off_axis * off_axis));
    // Lambertian backscatter (cos^2 of incidence, as the paper's intensity model) per metre of
    // seabed; spreading and absorption are undone by the TVG up to the 10 log r footprint term.
    const double length = (b.position_ned_m - a.position_ned_m).norm();
    const double e = reflect * cos_incidence * cos_incidence * beam * length;
    // Spread the segment's energy uniformly over the range interval it covers.
    double xa = a.slant_range_m / bin;
    double xb = b.slant_range_m / bin;
    if (xa > xb) std::swap(xa, xb);
    const double span = xb - xa;
    const int first = static_cast<int>(std::floor(xa + 0.5));
    const int last = static_cast<int>(std::floor(xb + 0.5));
    for (int i = std::max(first, 0); i <= std::min(last, n - 1); ++i) {
      const double overlap = span <= 1e-12 ? 1.0 : (std::min(xb, i + 0.5) - std::max(xa, i - 0.5)) / span;
      if (overlap > 0.0) energy[i] += e * overlap;
    }
  }
  // Energy per metre of range: bright where much seabed falls into one range bin (near nadir).
  for (int i = 0; i < n; ++i) energy[i] = energy[i] * tvg_residual_[i] / bin + options_.volume_backscatter;
  return energy;
}

std::vector<float> SonarModel::expectedIntensity(const sss::core::Pose& T_world_sonar, Side side) const {
  const std::vector<double> energy = accumulate(T_world_sonar, side);
  return std::vector<float>(energy.begin(), energy.end());
}

PingSamples SonarModel::render(const sss::core::Pose& T_world_sonar, uint32_t ping_number) const {
  PingSamples ping;
  for (Side side : {Side::kPort, Side::kStarboard}) {
    const std::vector<double> signal = accumulate(T_world_sonar, side);
    SplitMix rng{mixSeed(options_.seed, 2ull * ping_number + static_cast<uint64_t>(side))};
    std::vector<float>& out = side == Side::kPort ? ping.port : ping.starboard;
    out.resize(signal.size());
    const double scale = options_.output_scale * std::pow(10.0, gainStepDb(ping_number, side) / 20.0);
    const double shape = options_.speckle_shape;
    const double looks = options_.speckle_looks;
    for (size_t i = 0; i < signal.size(); ++i) {
      const double noise = noise_intensity_[i];
      // Speckle: complex Gaussian echo, so intensity is exponential and the envelope Rayleigh
      // distributed (gamma with `looks` averaged); K-distributed clutter modulates the echo's
      // power (not the receiver noise's) by a gamma texture first.
      const double texture = shape > 0.0 ? rng.unitMeanGamma(shape) : 1.0;
      const double speckle = looks == 1.0 ? -std::log(rng.uniform()) : rng.unitMeanGamma(looks);
      const double intensity = (signal[i] * texture + noise) * speckle;
      out[i] = static_cast<float>(scale * std::sqrt(intensity));
    }
  }
  return ping;
}

}  // namespace sss::sim
