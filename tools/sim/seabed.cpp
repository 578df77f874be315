// Simulated seabed generation: large-scale relief, ripples, trawl marks, boulders and sediment
// patches, all from hash-based value noise so the same seed gives the same bytes on any machine.
#include "tools/sim/seabed.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace sss::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

double latticeValue(uint64_t seed, int64_t ix, int64_t iy) {
  const uint64_t h = splitmix64(seed ^ splitmix64(static_cast<uint64_t>(ix) * 0x632BE59BD9B4E019ull +
                                                  static_cast<uint64_t>(iy)));
  return static_cast<double>(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

double smoothstep(double edge0, double edge1, double x) {
  const double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

struct TrawlMark {
  Eigen::Vector2d start;
  Eigen::Vector2d direction;
  double length_m;
  double wiggle_amplitude_m;
  double wiggle_wavelength_m;
  double wiggle_phase;
};

}  // namespace

uint64_t mixSeed(uint64_t a, uint64_t b) { return splitmix64(a ^ splitmix64(b + 0x51ED27ull)); }

double valueNoise2d(uint64_t seed, double x, double y) {
  const double fx = std::floor(x);
  const double fy = std::floor(y);
  const auto ix = static_cast<int64_t>(fx);
  const auto iy = static_cast<int64_t>(fy);
  const double tx = x - fx;
  const double ty = y - fy;
  const double sx = tx * tx * (3.0 - 2.0 * tx);
  const double sy = ty * ty * (3.0 - 2.0 * ty);
  const double v00 = latticeValue(seed, ix, iy);
  const double v10 = latticeValue(seed, ix + 1, iy);
  const double v01 = latticeValue(seed, ix, iy + 1);
  const double v11 = latticeValue(seed, ix + 1, iy + 1);
  const double a = v00 + (v10 - v00) * sx;
  const double b = v01 + (v11 - v01) * sx;
  return a + (b - a) * sy;
}

double fractalNoise2d(uint64_t seed, double x, double y, int octaves) {
  double sum = 0.0;
  double amplitude = 1.0;
  double norm = 0.0;
  for (int octave = 0; octave < octaves; ++octave) {
    // The rotation-like offset per octave hides the lattice alignment between octaves.
    sum += amplitude * valueNoise2d(mixSeed(seed, static_cast<uint64_t>(octave)), x + 17.3 * octave, y - 11.1 * octave);
    norm += amplitude;
    amplitude *= 0.5;
    x = 2.0 * x + 0.37 * y;
    y = 2.0 * y - 0.37 * x / 2.0;
  }
  return sum / norm;
}

Seabed::Seabed(const SeabedOptions& options) : options_(options) {
  if (options.resolution_m <= 0.0 || options.size_north_m <= 0.0 || options.size_east_m <= 0.0) {
    throw std::invalid_argument("Seabed: resolution and size must be positive");
  }
  rows_ = static_cast<int>(std::ceil(options.size_north_m / options.resolution_m)) + 1;
  cols_ = static_cast<int>(std::ceil(options.size_east_m / options.resolution_m)) + 1;
  depth_.assign(static_cast<size_t>(rows_) * cols_, static_cast<float>(options.mean_depth_m));
  reflectivity_.assign(depth_.size(), 0.35f);

  const uint64_t seed = options.seed;
  std::mt19937_64 rng(mixSeed(seed, 1001));
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double slope_direction = 2.0 * kPi * uniform(rng);
  const double slope = std::tan(options.slope_deg * kPi / 180.0);
  slope_gradient_ = options.enable_texture ? Eigen::Vector2d(slope * std::cos(slope_direction), slope * std::sin(slope_direction))
                                           : Eigen::Vector2d::Zero();

  // Trawl marks run roughly parallel (a fishing ground is trawled along the same contours).
  std::vector<TrawlMark> marks;
  if (options.enable_texture) {
    const double main_direction = 2.0 * kPi * uniform(rng);
    for (int i = 0; i < options.trawl_mark_count; ++i) {
      TrawlMark mark;
      mark.start = Eigen::Vector2d(options.north_min_m + uniform(rng) * options.size_north_m,
                                   options.east_min_m + uniform(rng) * options.size_east_m);
      const double angle = main_direction + (uniform(rng) - 0.5) * 0.7;
      mark.direction = Eigen::Vector2d(std::cos(angle), std::sin(angle));
      mark.length_m = (0.3 + 0.7 * uniform(rng)) * std::hypot(options.size_north_m, options.size_east_m);
      mark.start -= 0.5 * mark.length_m * mark.direction;
      mark.wiggle_amplitude_m = 2.0 + 6.0 * uniform(rng);
      mark.wiggle_wavelength_m = 150.0 + 250.0 * uniform(rng);
      mark.wiggle_phase = 2.0 * kPi * uniform(rng);
      marks.push_back(mark);
    }
  }
  const double ripple_direction = 2.0 * kPi * uniform(rng);

#pragma omp parallel for schedule(static)
  for (int row = 0; row < rows_; ++row) {
    const double north = options.north_min_m + row * options.resolution_m;
    for (int col = 0; col < cols_; ++col) {
      const double east = options.east_min_m + col * options.resolution_m;
      const size_t index = static_cast<size_t>(row) * cols_ + col;
      if (!options.enable_texture) continue;
      double depth = smoothDepthM(north, east);
      // Sediment patches: mud, sand and gravel with soft boundaries.
      const double patch =
          fractalNoise2d(mixSeed(seed, 3), north / options.sediment_patch_scale_m, east / options.sediment_patch_scale_m, 4);
      const double contrast = options.patch_contrast;
      double reflect = options.reflectivity_scale * (0.15 + contrast * 0.22 * smoothstep(-0.35, -0.2, patch) +
                                                     contrast * 0.25 * smoothstep(0.25, 0.4, patch));
      // Grain-scale texture from 4 m down to the grid.
      reflect *= 1.0 + options.texture_contrast * fractalNoise2d(mixSeed(seed, 4), north / 4.0, east / 4.0, 4);
      // Ripple fields: where a slow noise exceeds a threshold set by the covered fraction.
      const double field = fractalNoise2d(mixSeed(seed, 5), north / 120.0, east / 120.0, 2);
      const double threshold = 0.6 - 1.2 * options.ripple_fraction;
      const double ripple_weight = smoothstep(threshold, threshold + 0.1, field);
      if (ripple_weight > 0.0) {
        const double angle = ripple_direction + 0.4 * valueNoise2d(mixSeed(seed, 6), north / 60.0, east / 60.0);
        const double along = north * std::cos(angle) + east * std::sin(angle) +
                             1.5 * valueNoise2d(mixSeed(seed, 7), north / 15.0, east / 15.0);
        const double phase = 2.0 * kPi * along / options.ripple_wavelength_m;
        // Asymmetric ripple crest: the lee side is steeper, as on a real current-formed ripple.
        depth -= ripple_weight * options.ripple_amplitude_m * (std::sin(phase) + 0.25 * std::sin(2.0 * phase));
        if (options.megaripple_amplitude_m > 0.0) {
          // Megaripples lie a little askew of the small ripples riding on them.
          const double angle2 = angle + 0.3;
          const double along2 = north * std::cos(angle2) + east * std::sin(angle2) +
                                4.0 * valueNoise2d(mixSeed(seed, 11), north / 40.0, east / 40.0);
          const double phase2 = 2.0 * kPi * along2 / options.megaripple_wavelength_m;
          depth -= ripple_weight * options.megaripple_amplitude_m * (std::sin(phase2) + 0.3 * std::sin(2.0 * phase2));
        }
        reflect *= 1.0 + 0.15 * ripple_weight;
      }
      if (options.outcrop_fraction > 0.0) {
        const double field_rock =
            fractalNoise2d(mixSeed(seed, 8), north / options.outcrop_scale_m, east / options.outcrop_scale_m, 3);
        const double rock_threshold = 0.6 - 1.2 * options.outcrop_fraction;
        const double rock = smoothstep(rock_threshold, rock_threshold + 0.08, field_rock);
        if (rock > 0.0) {
          // Ridged noise (sharp crests, the bedding of a rock) plus blocky roughness.
          const double ridged = 1.0 - std::abs(fractalNoise2d(mixSeed(seed, 9), north / 7.0, east / 7.0, 4));
          const double rough = fractalNoise2d(mixSeed(seed, 10), north / 1.5, east / 1.5, 3);
          depth -= rock * options.outcrop_relief_m * (0.7 * ridged * ridged + 0.3 * (0.5 + 0.5 * rough));
          const double rock_reflect = 0.8 * (1.0 + 0.4 * rough);
          reflect = (1.0 - rock) * reflect + rock * rock_reflect;
        }
      }
      for (const TrawlMark& mark : marks) {
        const Eigen::Vector2d offset(north - mark.start.x(), east - mark.start.y());
        const double t = offset.dot(mark.direction);
        if (t < 0.0 || t > mark.length_m) continue;
        const double lateral = offset.x() * -mark.direction.y() + offset.y() * mark.direction.x() -
                               mark.wiggle_amplitude_m * std::sin(2.0 * kPi * t / mark.wiggle_wavelength_m + mark.wiggle_phase);
        const double w = options.trawl_mark_width_m;
        if (std::abs(lateral) > 3.0 * w) continue;
        // Ends taper so marks fade in and out like a door lifting off the bottom.
        const double taper = smoothstep(0.0, 20.0, t) * smoothstep(0.0, 20.0, mark.length_m - t);
        const double furrow = std::exp(-(lateral * lateral) / (0.25 * w * w));
        const double berm_offset = std::abs(lateral) - 0.9 * w;
        const double berm = std::exp(-(berm_offset * berm_offset) / (0.16 * w * w));
        depth += taper * options.trawl_mark_depth_m * (furrow - 0.5 * berm);
        reflect *= 1.0 + taper * (-0.25 * furrow + 0.2 * berm);
      }
      depth_[index] = static_cast<float>(depth);
      reflectivity_[index] = static_cast<float>(std::max(0.02, reflect));
    }
  }

  std::vector<SeabedObject> mounds;
  if (options.enable_texture) {
    const double area_hectare = options.size_north_m * options.size_east_m / 1e4;
    const int count = static_cast<int>(std::lround(options.boulders_per_hectare * area_hectare));
    const double log_min = std::log(options.boulder_min_radius_m);
    const double log_max = std::log(options.boulder_max_radius_m);
    for (int i = 0; i < count; ++i) {
      SeabedObject boulder;
      boulder.north_m = options.north_min_m + uniform(rng) * options.size_north_m;
      boulder.east_m = options.east_min_m + uniform(rng) * options.size_east_m;
      boulder.radius_m = std::exp(log_min + (log_max - log_min) * uniform(rng));
      boulder.height_m = boulder.radius_m * (0.5 + 0.5 * uniform(rng));
      boulder.reflectivity = 0.7 + 0.5 * uniform(rng);
      mounds.push_back(boulder);
    }
  }
  mounds.insert(mounds.end(), options.objects.begin(), options.objects.end());
  for (const SeabedObject& mound : mounds) addMound(mound);
}

void Seabed::addMound(const SeabedObject& object) {
  const double res = options_.resolution_m;
  const int row0 = std::max(0, static_cast<int>(std::floor((object.north_m - object.radius_m - options_.north_min_m) / res)));
  const int row1 = std::min(rows_ - 1, static_cast<int>(std::ceil((object.north_m + object.radius_m - options_.north_min_m) / res)));
  const int col0 = std::max(0, static_cast<int>(std::floor((object.east_m - object.radius_m - options_.east_min_m) / res)));
  const int col1 = std::min(cols_ - 1, static_cast<int>(std::ceil((object.east_m + object.radius_m - options_.east_min_m) / res)));
  const double base = depthM(object.north_m, object.east_m);
  for (int row = row0; row <= row1; ++row) {
    for (int col = col0; col <= col1; ++col) {
      const double dn = options_.north_min_m + row * res - object.north_m;
      const double de = options_.east_min_m + col * res - object.east_m;
      const double q = 1.0 - (dn * dn + de * de) / (object.radius_m * object.radius_m);
      if (q <= 0.0) continue;
      // A half-ellipsoid: steep flanks give the sharp shadow edge of a real boulder.
      const double top = base - object.height_m * std::sqrt(q);
      const size_t index = static_cast<size_t>(row) * cols_ + col;
      if (top < depth_[index]) {
        depth_[index] = static_cast<float>(top);
        reflectivity_[index] = static_cast<float>(object.reflectivity);
      }
    }
  }
}

double Seabed::smoothDepthM(double north_m, double east_m) const {
  if (!options_.enable_texture) return options_.mean_depth_m;
  const double centre_n = options_.north_min_m + 0.5 * options_.size_north_m;
  const double centre_e = options_.east_min_m + 0.5 * options_.size_east_m;
  const double lambda = options_.undulation_wavelength_m;
  return options_.mean_depth_m + slope_gradient_.x() * (north_m - centre_n) + slope_gradient_.y() * (east_m - centre_e) +
         options_.undulation_amplitude_m * fractalNoise2d(mixSeed(options_.seed, 2), north_m / lambda, east_m / lambda, 3);
}

bool Seabed::contains(double north_m, double east_m) const {
  const double row = (north_m - options_.north_min_m) / options_.resolution_m;
  const double col = (east_m - options_.east_min_m) / options_.resolution_m;
  return row >= 0.0 && col >= 0.0 && row <= rows_ - 1 && col <= cols_ - 1;
}

double Seabed::bilinear(const std::vector<float>& grid, double north_m, double east_m) const {
  const double row = std::clamp((north_m - options_.north_min_m) / options_.resolution_m, 0.0, rows_ - 1.000001);
  const double col = std::clamp((east_m - options_.east_min_m) / options_.resolution_m, 0.0, cols_ - 1.000001);
  const int r = static_cast<int>(row);
  const int c = static_cast<int>(col);
  const double tr = row - r;
  const double tc = col - c;
  const size_t i = static_cast<size_t>(r) * cols_ + c;
  const double a = grid[i] + (grid[i + 1] - grid[i]) * tc;
  const double b = grid[i + cols_] + (grid[i + cols_ + 1] - grid[i + cols_]) * tc;
  return a + (b - a) * tr;
}

double Seabed::depthM(double north_m, double east_m) const { return bilinear(depth_, north_m, east_m); }

double Seabed::reflectivity(double north_m, double east_m) const { return bilinear(reflectivity_, north_m, east_m); }

Eigen::Vector3d Seabed::normal(double north_m, double east_m) const {
  const double h = options_.resolution_m;
  const double d_north = (depthM(north_m + h, east_m) - depthM(north_m - h, east_m)) / (2.0 * h);
  const double d_east = (depthM(north_m, east_m + h) - depthM(north_m, east_m - h)) / (2.0 * h);
  // Surface z = D(n, e): the upward normal is (D_n, D_e, -1) normalised.
  return Eigen::Vector3d(d_north, d_east, -1.0).normalized();
}

}  // namespace sss::sim
