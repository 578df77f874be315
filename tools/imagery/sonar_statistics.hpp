// Image statistics of side-scan pings that a person compares between a simulator and a real
// file: speckle of homogeneous far-range seabed, dynamic range, across-track fall-off, water
// column and nadir. Works on raw envelope samples (before any ground-range correction), so the
// same figures come from a JSF of the simulator and an XTF of another vendor.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace sss::imagery {

// One ping as recorded: envelope samples per side from slant range 0 outward.
struct StatisticsPing {
  std::vector<float> port;
  std::vector<float> starboard;
  double sample_spacing_m = 0.0;                                   // slant range per sample
  double altitude_m = std::numeric_limits<double>::quiet_NaN();    // from the navigation; NaN unknown
};

struct SonarStatisticsOptions {
  // Speckle: blocks of block_pings x block_samples in slant range [far_min, far_max] x range;
  // a block is homogeneous when the means of its four quarters lie within max_quarter_deviation
  // of the block mean (no edge, shadow or gain change inside) and it holds no saturated sample.
  double far_range_min_fraction = 0.6;
  double far_range_max_fraction = 0.9;
  int block_pings = 32;
  int block_samples = 32;
  double max_quarter_deviation = 0.15;
  // Samples at or above this share of the largest sample in the data count as saturated.
  double saturation_fraction = 0.999;
  // Without an altitude, the first return is the first sample where a 16-sample running mean
  // exceeds this share of the side's median.
  double first_return_share_of_median = 0.5;
};

struct SonarStatistics {
  size_t pings = 0;
  double range_m = 0.0;                 // median recorded slant range
  double first_return_m = 0.0;          // median first seabed return (altitude or detected)
  size_t pings_with_altitude = 0;       // first return from the navigation, else detected
  // Speckle: median std/mean of the envelope over homogeneous far-range blocks (fully developed
  // speckle, a Rayleigh envelope: 0.52; heavier-tailed real seabeds 0.6-1).
  double speckle_std_over_mean = std::numeric_limits<double>::quiet_NaN();
  // The same blocks in intensity (envelope squared): 1 for single-look speckle, 1/sqrt(L) for L
  // looks averaged; the figure often quoted for "speckle" without saying which.
  double speckle_intensity_std_over_mean = std::numeric_limits<double>::quiet_NaN();
  size_t homogeneous_blocks = 0;
  size_t far_range_blocks = 0;
  // Seabed samples (beyond 1.1 x the first return): percentiles and their spread.
  double p01 = 0.0, p50 = 0.0, p99 = 0.0;
  double dynamic_range_db = 0.0;        // 20 log10(p99 / p01)
  double saturated_fraction = 0.0;      // of all samples
  // Across-track: mean envelope per tenth of the slant range, dB re the seabed mean (NaN where a
  // tenth lies in the water column), and the far/near ratio (80-90 % vs 30-40 % of the range).
  std::vector<double> profile_db;
  double falloff_db = std::numeric_limits<double>::quiet_NaN();
  // Water column (0.2-0.8 x first return) and nadir (1.0-1.1 x first return) re the seabed mean.
  double water_column_db = std::numeric_limits<double>::quiet_NaN();
  double nadir_db = std::numeric_limits<double>::quiet_NaN();
};

SonarStatistics computeSonarStatistics(const std::vector<StatisticsPing>& pings,
                                       const SonarStatisticsOptions& options = {});

// The figures as one JSON object (NaN as null) and as a few lines of text.
std::string statisticsJson(const SonarStatistics& statistics);
std::string statisticsText(const SonarStatistics& statistics);

}  // namespace sss::imagery
