// Options of the dense matcher: validation and the config file's keys. See dense_matcher.hpp.
#include "pipeline/matcher/dense_matcher.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace sss::matcher {

std::vector<std::string> validateDenseMatcherOptions(const DenseMatcherOptions& o) {
  std::vector<std::string> problems;
  if (o.patch_size < 3 || o.patch_size > 31 || o.patch_size % 2 == 0)
    problems.push_back("patch_size " + std::to_string(o.patch_size) + ": expected an odd number in [3, 31]");
  if (o.iterations < 0) problems.push_back("iterations must be >= 0");
  if (!(o.min_update_fraction >= 0.0 && o.min_update_fraction <= 1.0))
    problems.push_back("min_update_fraction must be in [0, 1]");
  if (!(o.max_offset_px >= 0.0)) problems.push_back("max_offset_px must be >= 0");
  if (!(o.max_dr_error_m >= 0.0)) problems.push_back("max_dr_error_m must be >= 0");
  if (!(o.max_init_distance_m > 0.0)) problems.push_back("max_init_distance_m must be > 0");
  if (!(o.min_zncc >= -1.0 && o.min_zncc <= 1.0)) problems.push_back("min_zncc must be in [-1, 1]");
  if (!(o.min_valid_fraction > 0.0 && o.min_valid_fraction <= 1.0))
    problems.push_back("min_valid_fraction must be in (0, 1]");
  if (!(o.min_patch_stddev >= 0.0)) problems.push_back("min_patch_stddev must be >= 0");
  if (!(o.max_fb_error_px >= 0.0)) problems.push_back("max_fb_error_px must be >= 0");
  if (!(o.random_search_ratio > 0.0 && o.random_search_ratio < 1.0))
    problems.push_back("random_search_ratio must be in (0, 1)");
  if (!(o.min_structure_ratio >= 0.0 && o.min_structure_ratio <= 1.0))
    problems.push_back("min_structure_ratio must be in [0, 1]");
  if (o.min_coherent_neighbours < 0 || o.min_coherent_neighbours > 8)
    problems.push_back("min_coherent_neighbours must be in [0, 8]");
  if (!(o.min_peak_margin >= 0.0 && o.min_peak_margin <= 2.0)) problems.push_back("min_peak_margin must be in [0, 2]");
  if (o.stride < 1 || o.stride > 64) problems.push_back("stride must be in [1, 64]");
  if (o.threads < 1 || o.threads > 256) problems.push_back("threads must be in [1, 256]");
  return problems;
}

void readDenseMatcherOptions(sss::core::ConfigSection& section, DenseMatcherOptions& options) {
  using sss::core::atLeast;
  using sss::core::greaterThan;
  using sss::core::inRange;
  section.optional("patch_size", options.patch_size,
                   {inRange(3, 31), sss::core::satisfies<int>([](int v) { return v % 2 == 1; }, "an odd number")});
  section.optional("iterations", options.iterations, {inRange(0, 100)});
  section.optional("min_update_fraction", options.min_update_fraction, {inRange(0.0, 1.0)});
  section.optional("max_offset_px", options.max_offset_px, {inRange(0.0, 500.0)});
  section.optional("max_dr_error_m", options.max_dr_error_m, {inRange(0.0, 100.0)});
  section.optional("max_init_distance_m", options.max_init_distance_m, {greaterThan(0.0)});
  section.optional("min_zncc", options.min_zncc, {inRange(-1.0, 1.0)});
  section.optional("min_valid_fraction", options.min_valid_fraction,
                   {sss::core::satisfies<double>([](double v) { return v > 0.0 && v <= 1.0; }, "a value in (0, 1]")});
  section.optional("min_patch_stddev", options.min_patch_stddev, {atLeast(0.0)});
  section.optional("forward_backward_check", options.forward_backward_check);
  section.optional("max_fb_error_px", options.max_fb_error_px, {atLeast(0.0)});
  section.optional("subpixel", options.subpixel);
  section.optional("reject_mirrored_relief", options.reject_mirrored_relief);
  section.optional("reject_shadowed_relief", options.reject_shadowed_relief);
  section.optional("reject_inverted_relief", options.reject_inverted_relief);
  section.optional("min_coherent_neighbours", options.min_coherent_neighbours, {inRange(0, 8)});
  section.optional("min_structure_ratio", options.min_structure_ratio, {inRange(0.0, 1.0)});
  section.optional("min_peak_margin", options.min_peak_margin, {inRange(0.0, 2.0)});
  section.optional("random_search_ratio", options.random_search_ratio,
                   {sss::core::satisfies<double>([](double v) { return v > 0.0 && v < 1.0; }, "a value in (0, 1)")});
  section.optional("stride", options.stride, {inRange(1, 64)});
  section.optional("threads", options.threads, {inRange(1, 256)});
  int seed = static_cast<int>(options.seed);
  section.optional("seed", seed, {atLeast(0)});
  options.seed = static_cast<std::uint64_t>(seed);
}

}  // namespace sss::matcher
