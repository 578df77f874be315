// Canonical transform of side-scan pings (paper Sec. "Canonical Transformation", after Xu et al.
// 2023): slant -> flat-seabed ground range, Lambertian cos^2 correction, profile normalisation, masks.
#pragma once

#include <cstdint>
#include <vector>

#include "pipeline/core/config.hpp"
#include "pipeline/core/subframe_types.hpp"
#include "pipeline/subframe/ping_nav_fusion.hpp"

namespace sss::subframe {

// Mask codes and the column layout are core (pipeline/core/subframe_types.hpp).
using sss::core::MaskCode;
using sss::core::kMaskValid;
using sss::core::kMaskNadir;
using sss::core::kMaskWaterColumn;
using sss::core::kMaskFarRange;
using sss::core::kMaskTurn;
using sss::core::kMaskNoData;
using sss::core::columnOf;
using sss::core::binOf;

struct CanonicalTransformOptions {
  // Ground-range axis of either side: bin k at first_bin_range_m + k * bin_size_m. 1250 x 6 cm
  // covers a 75 m side (the paper's 1-3k bins per side, ~4 raw samples of the 2205 per bin).
  int bins_per_side = 1250;
  double bin_size_m = 0.06;
  double first_bin_range_m = 0.0;
  // The swath follows the sonar's recorded range: with this on, bins_per_side is a minimum, and
  // the first ping with a pose widens it to the ground range of its last sample (a 120 m range
  // must not be cut at 75 m, where lines 200 m apart would share no pixel). Fixed from then on:
  // every subframe of a mission has the same ground-range axis (the matcher needs that).
  // On by default: over 15 randomised missions it pairs lines the 75 m swath cannot and helps on
  // balance (README, "Swath"), though far-range closures over rock can still be more wrong than
  // their covariance says. The matcher's store is bounded in memory (matcher.max_stored_mib), so
  // the larger subframes cannot outgrow the vehicle.
  bool swath_from_range = true;
  int max_bins_per_side = 16384;
  // Lambertian correction: divide by cos^2 of the flat-seabed incidence angle, floored here so the
  // nadir (cos -> 1) and grazing (cos -> 0) ends stay finite.
  bool lambertian_correction = true;
  double min_cos2 = 0.01;
  // Along-track profile normalisation: each bin divided by its running mean over about this many
  // recent pings (valid pixels only), so near and far range have the same mean (1.0).
  // One profile for both sides (bin k of port and starboard together) by default: it halves the
  // share of seabed content (sediment patches tens of metres wide) in what should be the sonar's
  // range-dependent gain only. The window spans several lines (2000 pings, ~8 min at 4 Hz).
  bool normalise_profile = true;
  bool profile_per_side = false;
  int normalisation_window_pings = 2000;
  // Masks.
  double water_column_margin_m = 0.5;      // slant range < altitude + margin: may be water column
  double nadir_max_depression_rad = 0.87;  // steeper than this below horizontal: outside the main
                                           // lobe (2205: 25 deg depression + 50 deg beam / 2)
  double min_ground_range_m = 1.0;         // nadir gap at least this wide
  double max_ground_range_m = 0.0;         // far range cut; 0: none
  double noise_floor = 0.0;                // running-mean raw intensity below this: far range; 0: off
  double max_heading_rate_rad_s = 0.02;    // turns: sim turns are ~0.057 rad/s, line hunting < 0.001
  double max_roll_rad = 0.06;              // banked turns / sharp attitude changes
};

void readCanonicalTransformOptions(sss::core::ConfigSection& section, CanonicalTransformOptions& options);

// A ping after the canonical transform: one image row. Column c < bins_per_side is port bin
// (bins_per_side - 1 - c), the rest starboard (subframe_t layout). Masked pixels are 0.
struct CanonicalPing {
  FusedPing fused;               // the raw samples are released once transformed
  std::vector<float> intensity;  // 2 * bins_per_side
  std::vector<uint8_t> mask;     // MaskCode per column
  bool turn = false;             // the whole row is masked as a turn
};

class CanonicalTransform {
 public:
  explicit CanonicalTransform(const CanonicalTransformOptions& options);

  CanonicalPing transform(FusedPing fused);

  const CanonicalTransformOptions& options() const { return options_; }
  int columns() const { return 2 * options_.bins_per_side; }
  // Ground range of a column (port and starboard alike; positive).
  double groundRangeM(int column) const;
  size_t memoryBytes() const { return (mean_.capacity() + raw_mean_.capacity()) * sizeof(double) + count_.capacity() * sizeof(int); }

 private:
  void resampleSide(const std::vector<float>& samples, const FusedPing& fused, bool port, CanonicalPing& out,
                    std::vector<float>& raw);

  CanonicalTransformOptions options_;
  std::vector<double> mean_;      // running mean of the Lambertian-corrected intensity per column
  std::vector<double> raw_mean_;  // running mean of the resampled raw intensity (noise floor)
  std::vector<int> count_;
  std::vector<double> prefix_;    // reused prefix sums of one side's samples
  std::vector<float> raw_;        // reused resampled raw row
};

}  // namespace sss::subframe
