// Canonical transform: ground-range resampling, Lambertian correction, running profile
// normalisation and masks. See canonical_transform.hpp.
#include "pipeline/subframe/canonical_transform.hpp"

#include <algorithm>
#include <cmath>

namespace sss::subframe {

void readCanonicalTransformOptions(sss::core::ConfigSection& section, CanonicalTransformOptions& options) {
  using namespace sss::core;
  section.optional("bins_per_side", options.bins_per_side, {inRange(16, 16384)});
  section.optional("bin_size_m", options.bin_size_m, {inRange(0.001, 10.0)});
  section.optional("first_bin_range_m", options.first_bin_range_m, {inRange(0.0, 1000.0)});
  section.optional("swath_from_range", options.swath_from_range);
  section.optional("max_bins_per_side", options.max_bins_per_side, {inRange(16, 16384)});
  section.optional("lambertian_correction", options.lambertian_correction);
  section.optional("min_cos2", options.min_cos2, {inRange(1e-6, 1.0)});
  section.optional("normalise_profile", options.normalise_profile);
  section.optional("profile_per_side", options.profile_per_side);
  section.optional("normalisation_window_pings", options.normalisation_window_pings, {inRange(1, 100000)});
  section.optional("water_column_margin_m", options.water_column_margin_m, {inRange(0.0, 100.0)});
  section.optional("nadir_max_depression_rad", options.nadir_max_depression_rad, {inRange(0.0, 1.5708)});
  section.optional("min_ground_range_m", options.min_ground_range_m, {inRange(0.0, 1000.0)});
  section.optional("max_ground_range_m", options.max_ground_range_m, {inRange(0.0, 10000.0)});
  section.optional("noise_floor", options.noise_floor, {atLeast(0.0)});
  section.optional("max_heading_rate_rad_s", options.max_heading_rate_rad_s, {greaterThan(0.0)});
  section.optional("max_roll_rad", options.max_roll_rad, {greaterThan(0.0)});
}

CanonicalTransform::CanonicalTransform(const CanonicalTransformOptions& options)
    : options_(options),
      mean_(2 * options.bins_per_side, 0.0),
      raw_mean_(2 * options.bins_per_side, 0.0),
      count_(2 * options.bins_per_side, 0),
      raw_(2 * options.bins_per_side, 0.0f) {}

double CanonicalTransform::groundRangeM(int column) const {
  bool port = false;
  const int bin = binOf(options_.bins_per_side, column, port);
  return options_.first_bin_range_m + bin * options_.bin_size_m;
}

void CanonicalTransform::resampleSide(const std::vector<float>& samples, const FusedPing& fused, bool port,
                                      CanonicalPing& out, std::vector<float>& raw) {
  const int bins = options_.bins_per_side;
  const double h = fused.altitude_m;
  const double spacing = fused.ping.sampleSpacingM();
  const double start = fused.ping.start_range_m;
  const size_t n = samples.size();
  // Prefix sums: a bin covers the slant-range interval of its ground-range extent, and the mean
  // over it (box filter) keeps far range, where one bin spans several samples, from aliasing.
  prefix_.resize(n + 1);
  prefix_[0] = 0.0;
  for (size_t i = 0; i < n; ++i) prefix_[i + 1] = prefix_[i] + samples[i];
  // Mean of the piecewise-constant signal over sample coordinates [s0, s1].
  auto integral = [&](double s) {
    const double clamped = std::clamp(s, 0.0, static_cast<double>(n));
    const size_t whole = static_cast<size_t>(clamped);
    double value = prefix_[whole];
    if (whole < n) value += (clamped - whole) * samples[whole];
    return value;
  };
  const double max_depression_tan = std::tan(options_.nadir_max_depression_rad);
  for (int k = 0; k < bins; ++k) {
    const int column = columnOf(bins, port, k);
    const double g = options_.first_bin_range_m + k * options_.bin_size_m;
    uint8_t& mask = out.mask[column];
    if (n == 0 || spacing <= 0.0) {
      mask = kMaskNoData;
      continue;
    }
    // paper / Xu et al.: flat seabed at the measured altitude h: slant range r = sqrt(g^2 + h^2).
    const double g0 = std::max(0.0, g - 0.5 * options_.bin_size_m);
    const double g1 = g + 0.5 * options_.bin_size_m;
    const double r = std::sqrt(g * g + h * h);
    const double s0 = (std::sqrt(g0 * g0 + h * h) - start) / spacing;
    const double s1 = (std::sqrt(g1 * g1 + h * h) - start) / spacing;
    if (s0 < 0.0 || s1 > static_cast<double>(n)) {
      mask = kMaskNoData;
      continue;
    }
    double value;
    if (s1 - s0 >= 1.0) {
      value = (integral(s1) - integral(s0)) / (s1 - s0);
    } else {
      // Near nadir a bin is shorter than a sample: linear interpolation between sample centres.
      const double s = (r - start) / spacing - 0.5;
      const size_t i0 = static_cast<size_t>(std::clamp(std::floor(s), 0.0, static_cast<double>(n - 1)));
      const size_t i1 = std::min(i0 + 1, n - 1);
      const double f = std::clamp(s - static_cast<double>(i0), 0.0, 1.0);
      value = (1.0 - f) * samples[i0] + f * samples[i1];
    }
    raw[column] = static_cast<float>(value);
    if (r < h + options_.water_column_margin_m) {
      mask = kMaskWaterColumn;
    } else if (g < options_.min_ground_range_m || h > g * max_depression_tan) {
      mask = kMaskNadir;
    } else if (options_.max_ground_range_m > 0.0 && g > options_.max_ground_range_m) {
      mask = kMaskFarRange;
    }
    if (options_.lambertian_correction) {
      // Lambertian law (paper, after [coiras2007tip], [aykin2013oceans]): backscatter ~ cos^2 of
      // the incidence angle; on a flat seabed cos(theta) = h / r.
      const double cos2 = std::max(options_.min_cos2, (h * h) / (r * r));
      value /= cos2;
    }
    out.intensity[column] = static_cast<float>(value);
  }
}

CanonicalPing CanonicalTransform::transform(FusedPing fused) {
  const int columns = 2 * options_.bins_per_side;
  CanonicalPing out;
  out.intensity.assign(columns, 0.0f);
  out.mask.assign(columns, kMaskValid);
  std::fill(raw_.begin(), raw_.end(), 0.0f);
  resampleSide(fused.ping.port, fused, true, out, raw_);
  resampleSide(fused.ping.starboard, fused, false, out, raw_);
  out.turn = std::abs(fused.heading_rate_rad_s) > options_.max_heading_rate_rad_s ||
             std::abs(fused.roll_rad) > options_.max_roll_rad;

  // Running along-track profile: a cumulative mean over the first window, then an exponential one
  // with the same memory. Turn rows do not enter it (their geometry is wrong). The profile index
  // of a column is its ground-range bin (both sides shared) or the column itself.
  const double window = static_cast<double>(options_.normalisation_window_pings);
  const int bins = options_.bins_per_side;
  auto profileIndex = [&](int c) {
    bool port = false;
    return options_.profile_per_side ? c : binOf(bins, c, port);
  };
  if (!out.turn) {
    for (int c = 0; c < columns; ++c) {
      if (out.mask[c] != kMaskValid) continue;
      const int k = profileIndex(c);
      count_[k] = std::min(count_[k] + 1, options_.normalisation_window_pings * 2);
      const double weight = 1.0 / std::min(static_cast<double>(count_[k]), window * (options_.profile_per_side ? 1 : 2));
      mean_[k] += weight * (out.intensity[c] - mean_[k]);
      raw_mean_[k] += weight * (raw_[c] - raw_mean_[k]);
    }
  }
  for (int c = 0; c < columns; ++c) {
    if (out.mask[c] != kMaskValid) continue;
    const int k = profileIndex(c);
    if (options_.noise_floor > 0.0 && count_[k] > 0 && raw_mean_[k] < options_.noise_floor) {
      out.mask[c] = kMaskFarRange;
    } else if (options_.normalise_profile) {
      if (count_[k] == 0 || mean_[k] <= 0.0) {
        out.mask[c] = kMaskNoData;
      } else {
        out.intensity[c] = static_cast<float>(out.intensity[c] / mean_[k]);
      }
    }
  }
  for (int c = 0; c < columns; ++c) {
    if (out.turn && out.mask[c] == kMaskValid) out.mask[c] = kMaskTurn;
    if (out.mask[c] != kMaskValid) out.intensity[c] = 0.0f;
  }
  // The raw samples are not needed any more; subframes hold canonical rows only.
  fused.ping.port = {};
  fused.ping.starboard = {};
  out.fused = std::move(fused);
  return out;
}

}  // namespace sss::subframe
