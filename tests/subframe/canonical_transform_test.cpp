// Canonical transform on hand-built pings: ground-range resampling puts an echo at its bin, the
// Lambertian correction and profile normalisation flatten a cos^2 seabed, masks follow the rules.
#include "pipeline/subframe/canonical_transform.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace sss::subframe {
namespace {

constexpr double kAltitudeM = 18.0;
constexpr double kSpacingM = 0.015;  // 20 us at 1500 m/s
constexpr int kSamples = 5000;       // 75 m

FusedPing flatSeabedPing(std::function<float(double slant_m)> intensity) {
  FusedPing fused;
  fused.altitude_m = kAltitudeM;
  fused.ping.sound_speed_m_s = 1500.0;
  fused.ping.sample_interval_s = 2.0 * kSpacingM / 1500.0;
  for (int i = 0; i < kSamples; ++i) {
    const double r = (i + 0.5) * kSpacingM;
    fused.ping.port.push_back(intensity(r));
    fused.ping.starboard.push_back(intensity(r));
  }
  return fused;
}

TEST(CanonicalTransform, PutsAnEchoAtItsGroundRangeBin) {
  CanonicalTransformOptions options;
  options.normalise_profile = false;
  options.lambertian_correction = false;
  CanonicalTransform transform(options);
  const double ground_m = 40.0;
  const double slant_m = std::hypot(ground_m, kAltitudeM);
  const CanonicalPing row =
      transform.transform(flatSeabedPing([&](double r) { return std::abs(r - slant_m) < 0.02 ? 100.0f : 1.0f; }));
  const int bins = options.bins_per_side;
  const auto starboard_peak = std::max_element(row.intensity.begin() + bins, row.intensity.end());
  const auto port_peak = std::max_element(row.intensity.begin(), row.intensity.begin() + bins);
  const int starboard_bin = static_cast<int>(starboard_peak - row.intensity.begin()) - bins;
  const int port_bin = bins - 1 - static_cast<int>(port_peak - row.intensity.begin());
  // 40 m / 0.06 m = bin 666.7: the echo spans two bins at most.
  EXPECT_NEAR(starboard_bin, ground_m / options.bin_size_m, 1.0);
  EXPECT_EQ(port_bin, starboard_bin);  // mirrored layout
}

TEST(CanonicalTransform, LambertianCorrectionAndNormalisationFlattenTheProfile) {
  CanonicalTransform transform({});
  // A Lambertian flat seabed: intensity ~ cos^2(incidence) = h^2 / r^2, plus a far-range loss
  // that only the along-track normalisation removes.
  auto seabed = [](double r) {
    if (r < kAltitudeM) return 0.01f;
    return static_cast<float>(kAltitudeM * kAltitudeM / (r * r) * std::exp(-r / 60.0));
  };
  CanonicalPing row;
  for (int i = 0; i < 20; ++i) row = transform.transform(flatSeabedPing(seabed));
  double min_value = 1e9, max_value = 0.0;
  int valid = 0;
  for (size_t c = 0; c < row.intensity.size(); ++c) {
    if (row.mask[c] != kMaskValid) continue;
    ++valid;
    min_value = std::min(min_value, static_cast<double>(row.intensity[c]));
    max_value = std::max(max_value, static_cast<double>(row.intensity[c]));
  }
  EXPECT_GT(valid, 1900);  // 2 x (72.8 - 15.1) m / 0.06 m
  EXPECT_NEAR(min_value, 1.0, 1e-3);
  EXPECT_NEAR(max_value, 1.0, 1e-3);

  // Without normalisation, the cos^2 correction alone leaves the far-range loss exp(-r/60).
  CanonicalTransformOptions lambert_only;
  lambert_only.normalise_profile = false;
  const CanonicalPing corrected = CanonicalTransform(lambert_only).transform(flatSeabedPing(seabed));
  const int bins = lambert_only.bins_per_side;
  const double g = 30.0;
  const int column = bins + static_cast<int>(g / lambert_only.bin_size_m);
  EXPECT_NEAR(corrected.intensity[column], std::exp(-std::hypot(g, kAltitudeM) / 60.0), 0.01);
}

TEST(CanonicalTransform, MasksNadirWaterColumnNoDataAndTurns) {
  CanonicalTransformOptions options;
  options.max_ground_range_m = 70.0;
  CanonicalTransform transform(options);
  FusedPing fused = flatSeabedPing([](double) { return 1.0f; });
  fused.ping.port.clear();  // a missing side
  const CanonicalPing row = transform.transform(fused);
  const int bins = options.bins_per_side;
  auto maskAt = [&](double ground_m) { return row.mask[bins + static_cast<int>(ground_m / options.bin_size_m)]; };
  EXPECT_EQ(maskAt(0.5), kMaskWaterColumn);  // r within 0.5 m of the altitude
  EXPECT_EQ(maskAt(5.0), kMaskNadir);        // depression 74 deg > 50 deg
  EXPECT_EQ(maskAt(14.0), kMaskNadir);
  EXPECT_EQ(maskAt(16.0), kMaskValid);       // 18 / tan(50 deg) = 15.1 m
  EXPECT_EQ(maskAt(71.0), kMaskFarRange);
  EXPECT_EQ(maskAt(74.0), kMaskNoData);      // beyond the last sample (72.8 m ground range)
  EXPECT_TRUE(std::all_of(row.mask.begin(), row.mask.begin() + bins, [](uint8_t m) { return m == kMaskNoData; }));

  FusedPing turning = flatSeabedPing([](double) { return 1.0f; });
  turning.heading_rate_rad_s = 0.05;
  const CanonicalPing turn_row = transform.transform(turning);
  EXPECT_TRUE(turn_row.turn);
  EXPECT_EQ(turn_row.mask[bins + 500], kMaskTurn);
  FusedPing banked = flatSeabedPing([](double) { return 1.0f; });
  banked.roll_rad = 0.08;
  EXPECT_TRUE(transform.transform(banked).turn);
}

}  // namespace
}  // namespace sss::subframe
