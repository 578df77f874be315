// Side-scan image statistics over raw pings: one pass for the first returns and the saturation
// level, one for the range-band sums and percentiles, one for the far-range speckle blocks.
#include "tools/imagery/sonar_statistics.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace sss::imagery {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double median(std::vector<double> values) {
  if (values.empty()) return kNaN;
  const size_t k = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

double quantile(std::vector<float>& values, double fraction) {
  if (values.empty()) return kNaN;
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(fraction * static_cast<double>(values.size())));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

double decibels(double ratio) { return ratio > 0.0 ? 20.0 * std::log10(ratio) : kNaN; }

// First seabed return of one side, in samples: from the altitude when known, else the first
// sample where a short running mean rises above a share of the side's median.
size_t firstReturnSample(const std::vector<float>& samples, const StatisticsPing& ping,
                         const SonarStatisticsOptions& options) {
  if (std::isfinite(ping.altitude_m) && ping.altitude_m > 0.0 && ping.sample_spacing_m > 0.0) {
    return std::min(samples.size(), static_cast<size_t>(ping.altitude_m / ping.sample_spacing_m));
  }
  std::vector<float> sorted(samples);
  const double threshold = options.first_return_share_of_median * quantile(sorted, 0.5);
  const size_t window = 16;
  double sum = 0.0;
  for (size_t i = 0; i < samples.size(); ++i) {
    sum += samples[i];
    if (i >= window) sum -= samples[i - window];
    if (i + 1 >= window && sum / window > threshold) return i + 1 - window;
  }
  return samples.size();
}

struct BandSums {
  double sum = 0.0;
  size_t count = 0;
  void add(double value) { sum += value, ++count; }
  double mean() const { return count > 0 ? sum / static_cast<double>(count) : kNaN; }
};

}  // namespace

SonarStatistics computeSonarStatistics(const std::vector<StatisticsPing>& pings, const SonarStatisticsOptions& options) {
  SonarStatistics stats;
  stats.pings = pings.size();
  if (pings.empty()) return stats;

  // Pass 1: first returns, ranges, the largest sample (the saturation level).
  std::vector<std::array<size_t, 2>> first_return(pings.size(), {0, 0});
  std::vector<double> ranges, returns;
  float largest = 0.0f;
  size_t total_samples = 0;
  for (size_t p = 0; p < pings.size(); ++p) {
    const StatisticsPing& ping = pings[p];
    if (std::isfinite(ping.altitude_m) && ping.altitude_m > 0.0) ++stats.pings_with_altitude;
    for (int side = 0; side < 2; ++side) {
      const std::vector<float>& samples = side == 0 ? ping.port : ping.starboard;
      if (samples.empty()) continue;
      first_return[p][side] = firstReturnSample(samples, ping, options);
      ranges.push_back(samples.size() * ping.sample_spacing_m);
      returns.push_back(first_return[p][side] * ping.sample_spacing_m);
      for (float v : samples) largest = std::max(largest, v);
      total_samples += samples.size();
    }
  }
  stats.range_m = median(ranges);
  stats.first_return_m = median(returns);
  const float saturated = static_cast<float>(options.saturation_fraction) * largest;

  // Pass 2: bands (water column, nadir, tenths of the range), seabed percentiles on a subsample.
  const size_t keep_every = std::max<size_t>(1, total_samples / 4000000);
  std::vector<float> seabed;
  seabed.reserve(total_samples / keep_every + 1);
  BandSums water, nadir, seabed_band;
  std::vector<BandSums> tenths(10);
  size_t saturated_count = 0, visited = 0;
  for (size_t p = 0; p < pings.size(); ++p) {
    for (int side = 0; side < 2; ++side) {
      const std::vector<float>& samples = side == 0 ? pings[p].port : pings[p].starboard;
      if (samples.empty()) continue;
      const double fr = static_cast<double>(first_return[p][side]);
      const size_t n = samples.size();
      for (size_t i = 0; i < n; ++i) {
        const double v = samples[i];
        if (samples[i] >= saturated) ++saturated_count;
        const double x = static_cast<double>(i);
        if (x >= 0.2 * fr && x < 0.8 * fr) water.add(v);
        if (x >= fr && x < 1.1 * fr) nadir.add(v);
        if (x < 1.1 * fr) continue;
        seabed_band.add(v);
        tenths[std::min<size_t>(9, i * 10 / n)].add(v);
        if (visited++ % keep_every == 0) seabed.push_back(samples[i]);
      }
    }
  }
  stats.saturated_fraction = total_samples > 0 ? static_cast<double>(saturated_count) / static_cast<double>(total_samples) : 0.0;
  const double seabed_mean = seabed_band.mean();
  stats.p01 = quantile(seabed, 0.01);
  stats.p50 = quantile(seabed, 0.50);
  stats.p99 = quantile(seabed, 0.99);
  stats.dynamic_range_db = decibels(stats.p99 / stats.p01);
  for (const BandSums& tenth : tenths) stats.profile_db.push_back(decibels(tenth.mean() / seabed_mean));
  stats.falloff_db = decibels(tenths[8].mean() / tenths[3].mean());
  stats.water_column_db = decibels(water.mean() / seabed_mean);
  stats.nadir_db = decibels(nadir.mean() / seabed_mean);

  // Pass 3: speckle in far-range blocks of consecutive pings.
  const auto bp = static_cast<size_t>(std::max(2, options.block_pings));
  const auto bs = static_cast<size_t>(std::max(2, options.block_samples));
  std::vector<double> ratios, intensity_ratios;
  for (int side = 0; side < 2; ++side) {
    for (size_t p0 = 0; p0 + bp <= pings.size(); p0 += bp) {
      size_t n = 0;
      for (size_t p = p0; p < p0 + bp; ++p) {
        const size_t size = (side == 0 ? pings[p].port : pings[p].starboard).size();
        n = p == p0 ? size : std::min(n, size);
      }
      if (n == 0) continue;
      const size_t first = static_cast<size_t>(options.far_range_min_fraction * static_cast<double>(n));
      const size_t last = static_cast<size_t>(options.far_range_max_fraction * static_cast<double>(n));
      for (size_t s0 = first; s0 + bs <= last; s0 += bs) {
        ++stats.far_range_blocks;
        double quarter_sum[4] = {0, 0, 0, 0};
        double sum = 0.0, sum_sq = 0.0, sum_4 = 0.0;
        bool clipped = false;
        for (size_t p = p0; p < p0 + bp; ++p) {
          const std::vector<float>& samples = side == 0 ? pings[p].port : pings[p].starboard;
          for (size_t s = s0; s < s0 + bs; ++s) {
            const double v = samples[s];
            clipped = clipped || samples[s] >= saturated;
            sum += v, sum_sq += v * v, sum_4 += v * v * v * v;
            quarter_sum[(p - p0 < bp / 2 ? 0 : 2) + (s - s0 < bs / 2 ? 0 : 1)] += v;
          }
        }
        const double count = static_cast<double>(bp * bs);
        const double mean = sum / count;
        if (clipped || !(mean > 0.0)) continue;
        bool homogeneous = true;
        for (double q : quarter_sum) homogeneous = homogeneous && std::abs(q / (count / 4.0) - mean) <= options.max_quarter_deviation * mean;
        if (!homogeneous) continue;
        const double variance = std::max(0.0, sum_sq / count - mean * mean);
        ratios.push_back(std::sqrt(variance) / mean);
        const double intensity_mean = sum_sq / count;
        intensity_ratios.push_back(std::sqrt(std::max(0.0, sum_4 / count - intensity_mean * intensity_mean)) / intensity_mean);
      }
    }
  }
  stats.homogeneous_blocks = ratios.size();
  stats.speckle_std_over_mean = median(ratios);
  stats.speckle_intensity_std_over_mean = median(intensity_ratios);
  return stats;
}

namespace {
// NaN (a band with no sample) is written as null.
nlohmann::json number(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }
}  // namespace

std::string statisticsJson(const SonarStatistics& s) {
  nlohmann::json profile = nlohmann::json::array();
  for (double db : s.profile_db) profile.push_back(number(db));
  const nlohmann::json json = {{"pings", s.pings},
                               {"range_m", number(s.range_m)},
                               {"first_return_m", number(s.first_return_m)},
                               {"pings_with_altitude", s.pings_with_altitude},
                               {"speckle_std_over_mean", number(s.speckle_std_over_mean)},
                               {"speckle_intensity_std_over_mean", number(s.speckle_intensity_std_over_mean)},
                               {"homogeneous_blocks", s.homogeneous_blocks},
                               {"far_range_blocks", s.far_range_blocks},
                               {"p01", number(s.p01)},
                               {"p50", number(s.p50)},
                               {"p99", number(s.p99)},
                               {"dynamic_range_db", number(s.dynamic_range_db)},
                               {"saturated_fraction", number(s.saturated_fraction)},
                               {"profile_db", profile},
                               {"falloff_db", number(s.falloff_db)},
                               {"water_column_db", number(s.water_column_db)},
                               {"nadir_db", number(s.nadir_db)}};
  return json.dump(2);
}

std::string statisticsText(const SonarStatistics& s) {
  char text[1024];
  std::snprintf(text, sizeof text,
                "pings %zu, range %.1f m, first return %.1f m (altitude in %zu pings)\n"
                "speckle std/mean %.3f (intensity %.3f) over %zu of %zu far-range blocks\n"
                "seabed envelope p1 %.4g  p50 %.4g  p99 %.4g: dynamic range %.1f dB; saturated %.4f %%\n"
                "across-track: 80-90 %% of range vs 30-40 %%: %+.1f dB; water column %+.1f dB, nadir %+.1f dB re seabed\n",
                s.pings, s.range_m, s.first_return_m, s.pings_with_altitude, s.speckle_std_over_mean, s.speckle_intensity_std_over_mean,
                s.homogeneous_blocks, s.far_range_blocks, s.p01, s.p50, s.p99, s.dynamic_range_db,
                100.0 * s.saturated_fraction, s.falloff_db, s.water_column_db, s.nadir_db);
  std::string result = text;
  result += "profile dB per tenth of range:";
  for (double db : s.profile_db) {
    char cell[32];
    if (std::isfinite(db)) std::snprintf(cell, sizeof cell, " %+.1f", db);
    else std::snprintf(cell, sizeof cell, " -");
    result += cell;
  }
  return result + "\n";
}

}  // namespace sss::imagery
