// Bottom tracking from the side-scan returns, see bottom_tracker.hpp.
#include "pipeline/subframe/bottom_tracker.hpp"

#include <algorithm>
#include <cmath>

namespace sss::subframe {

void readBottomTrackerOptions(sss::core::ConfigSection& section, BottomTrackerOptions& options) {
  using namespace sss::core;
  section.optional("min_altitude_m", options.min_altitude_m, {inRange(0.0, 1000.0)});
  section.optional("bin_m", options.bin_m, {inRange(0.001, 5.0)});
  section.optional("after_window_m", options.after_window_m, {inRange(0.05, 100.0)});
  section.optional("min_contrast_db", options.min_contrast_db, {inRange(0.1, 60.0)});
  section.optional("first_return_fraction", options.first_return_fraction, {inRange(0.1, 1.0)});
  section.optional("sides_agree_m", options.sides_agree_m, {inRange(0.0, 100.0)});
  section.optional("sides_agree_fraction", options.sides_agree_fraction, {inRange(0.0, 1.0)});
  section.optional("smoothing_pings", options.smoothing_pings, {inRange(1, 1000)});
  section.optional("gate_m", options.gate_m, {inRange(0.0, 1000.0)});
  section.optional("gate_fraction", options.gate_fraction, {inRange(0.0, 10.0)});
}

SideDetection detectFirstReturn(const std::vector<float>& envelope, double start_range_m, double spacing_m,
                                const BottomTrackerOptions& options) {
  SideDetection detection;
  if (envelope.empty() || !(spacing_m > 0.0) || !std::isfinite(start_range_m)) return detection;
  const int per_bin = std::max(1, static_cast<int>(std::lround(options.bin_m / spacing_m)));
  const int bins = static_cast<int>(envelope.size()) / per_bin;
  const double bin_length_m = per_bin * spacing_m;
  const int after_bins = std::max(2, static_cast<int>(std::lround(options.after_window_m / bin_length_m)));
  // The column before the edge starts past the transmit pulse (min_altitude_m).
  const int first_bin = std::max(0, static_cast<int>(std::ceil((options.min_altitude_m - start_range_m) / bin_length_m)));
  if (bins - after_bins - first_bin < 4) return detection;

  // Prefix sums of the per-bin level in dB (speckle is multiplicative: compare logarithms), each
  // bin at least 60 dB below the side's bright level (p90 of the bins): a water column of exact
  // zeros (quantised, or a simulator's) must not make one stray sample a 250 dB "rise".
  std::vector<double> level(static_cast<size_t>(bins), 0.0);
  for (int b = 0; b < bins; ++b) {
    double sum = 0.0;
    for (int k = 0; k < per_bin; ++k) {
      const float value = envelope[static_cast<size_t>(b) * per_bin + k];
      sum += std::isfinite(value) && value > 0.0f ? value : 0.0;
    }
    level[b] = sum / per_bin;
  }
  std::vector<double> sorted = level;
  const size_t p90 = sorted.size() * 9 / 10;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(p90), sorted.end());
  const double floor_level = std::max(sorted[p90] * 1e-6, 1e-30);
  std::vector<double> prefix(static_cast<size_t>(bins) + 1, 0.0);
  for (int b = 0; b < bins; ++b) prefix[b + 1] = prefix[b] + 10.0 * std::log10(std::max(level[b], floor_level));
  const int last_bin = bins - after_bins;
  std::vector<double> score(static_cast<size_t>(bins), -1e300);
  double best = -1e300;
  for (int b = first_bin + 2; b <= last_bin; ++b) {
    const double before = (prefix[b] - prefix[first_bin]) / (b - first_bin);
    const double after = (prefix[b + after_bins] - prefix[b]) / after_bins;
    score[b] = after - before;
    best = std::max(best, score[b]);
  }
  if (!(best >= options.min_contrast_db)) return detection;
  // The first strong rise: the first candidate within the fraction of the best, then the peak of
  // its rise (the score climbs over one window up to the edge itself).
  const double threshold = options.first_return_fraction * best;
  for (int b = first_bin + 2; b <= last_bin; ++b) {
    if (score[b] < threshold) continue;
    int peak = b;
    for (int k = b + 1; k <= std::min(last_bin, b + after_bins); ++k) {
      if (score[k] > score[peak]) peak = k;
    }
    // The long-window score is flat within a few bins of the edge (speckle): the edge itself is
    // the sharpest local step (half a metre either side) near that peak.
    const int local_bins = std::max(3, static_cast<int>(std::lround(0.5 / bin_length_m)));
    int edge = peak;
    double sharpest = -1e300;
    for (int k = std::max(first_bin + local_bins, peak - after_bins);
         k <= std::min(bins - local_bins, peak + after_bins); ++k) {
      const double step = (prefix[k + local_bins] - prefix[k]) / local_bins -
                          (prefix[k] - prefix[k - local_bins]) / local_bins;
      if (step > sharpest) {
        sharpest = step;
        edge = k;
      }
    }
    detection.valid = true;
    detection.slant_range_m = start_range_m + edge * bin_length_m;
    detection.contrast_db = score[peak];
    break;
  }
  return detection;
}

BottomTracker::BottomTracker(const BottomTrackerOptions& options) : options_(options) {}

double BottomTracker::median() const {
  std::vector<double> values(accepted_m_.begin(), accepted_m_.end());
  if (values.empty()) return 0.0;
  const size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle), values.end());
  double value = values[middle];
  if (values.size() % 2 == 0) {
    value = 0.5 * (value + *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle)));
  }
  return value;
}

double BottomTracker::lineAtNewest() const {
  const size_t n = accepted_m_.size();
  if (n < 3) return median();
  const double t_now = static_cast<double>(counters_.pings);
  double sum_t = 0.0, sum_h = 0.0, sum_tt = 0.0, sum_th = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(accepted_ping_[i]) - t_now;
    sum_t += t;
    sum_h += accepted_m_[i];
    sum_tt += t * t;
    sum_th += t * accepted_m_[i];
  }
  const double denominator = static_cast<double>(n) * sum_tt - sum_t * sum_t;
  if (!(denominator > 0.0)) return median();
  const double slope = (static_cast<double>(n) * sum_th - sum_t * sum_h) / denominator;
  return (sum_h - slope * sum_t) / static_cast<double>(n);  // the line at t = 0 (this ping)
}

BottomTrack BottomTracker::track(const std::vector<float>& port, const std::vector<float>& starboard,
                                 double start_range_m, double spacing_m) {
  ++counters_.pings;
  const SideDetection sides[2] = {detectFirstReturn(port, start_range_m, spacing_m, options_),
                                  detectFirstReturn(starboard, start_range_m, spacing_m, options_)};
  const size_t window = static_cast<size_t>(options_.smoothing_pings);
  const bool have_track = accepted_m_.size() >= 3;
  std::optional<double> raw;
  double side_share = 0.0;
  if (sides[0].valid && sides[1].valid) {
    const double a = sides[0].slant_range_m, b = sides[1].slant_range_m;
    const double tolerance = std::max(options_.sides_agree_m, options_.sides_agree_fraction * std::min(a, b));
    if (std::abs(a - b) <= tolerance) {
      raw = 0.5 * (a + b);
      side_share = 1.0;
    } else {
      // A fish or an echo on one side: the side nearer the track, or the clearer edge.
      const double m = have_track ? median() : 0.0;
      const bool port_wins = have_track ? std::abs(a - m) <= std::abs(b - m) : sides[0].contrast_db >= sides[1].contrast_db;
      raw = port_wins ? a : b;
      side_share = 0.5;
    }
  } else if (sides[0].valid || sides[1].valid) {
    raw = sides[0].valid ? sides[0].slant_range_m : sides[1].slant_range_m;
    side_share = 0.5;
    ++counters_.one_side_only;
  }

  BottomTrack result;
  bool accepted = false;
  bool restarted = false;  // the track restarted on the outlier run, this detection included
  if (raw) {
    ++counters_.detected;
    result.raw_altitude_m = *raw;
    if (have_track) {
      const double m = median();
      const double gate = std::max(options_.gate_m, options_.gate_fraction * m);
      if (std::abs(*raw - m) <= gate) {
        accepted = true;
      } else {
        ++counters_.outliers;
        outlier_run_m_.push_back(*raw);
        outlier_run_ping_.push_back(counters_.pings);
        if (outlier_run_m_.size() >= window) {
          // A whole window off the track: if those detections agree among themselves the seabed
          // really changed (a step, a mound): the track restarts on them.
          std::vector<double> run(outlier_run_m_.begin(), outlier_run_m_.end());
          std::sort(run.begin(), run.end());
          const double run_median = run[run.size() / 2];
          const double run_gate = std::max(options_.gate_m, options_.gate_fraction * run_median);
          const auto agreeing = std::count_if(run.begin(), run.end(),
                                              [&](double v) { return std::abs(v - run_median) <= run_gate; });
          if (static_cast<size_t>(agreeing) * 4 >= run.size() * 3) {
            accepted_m_.assign(outlier_run_m_.begin(), outlier_run_m_.end());
            accepted_ping_.assign(outlier_run_ping_.begin(), outlier_run_ping_.end());
            outlier_run_m_.clear();
            outlier_run_ping_.clear();
            ++counters_.restarts;
            accepted = restarted = true;
          } else {
            outlier_run_m_.pop_front();
            outlier_run_ping_.pop_front();
          }
        }
      }
    } else {
      accepted = true;
    }
    if (accepted && !restarted) {
      accepted_m_.push_back(*raw);
      accepted_ping_.push_back(counters_.pings);
      outlier_run_m_.clear();
      outlier_run_ping_.clear();
    }
    while (accepted_m_.size() > window) {
      accepted_m_.pop_front();
      accepted_ping_.pop_front();
    }
  }
  recent_score_.push_back(accepted ? side_share : 0.0);
  while (recent_score_.size() > window) recent_score_.pop_front();
  double quality = 0.0;
  for (double s : recent_score_) quality += s;
  quality /= static_cast<double>(window);
  const bool recent = std::any_of(recent_score_.begin(), recent_score_.end(), [](double s) { return s > 0.0; });
  result.valid = !accepted_m_.empty() && recent;
  result.altitude_m = result.valid ? lineAtNewest() : 0.0;
  result.quality = result.valid ? quality : 0.0;
  return result;
}

}  // namespace sss::subframe
