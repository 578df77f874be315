// The subframe buffer's pipeline of library stages. See subframe_buffer.hpp.
#include "pipeline/subframe/subframe_buffer.hpp"

#include <algorithm>
#include <cmath>

namespace sss::subframe {

void readSubframeBufferOptions(sss::core::ConfigSection& section, SubframeBufferOptions& options) {
  sss::core::ConfigSection fusion = section.section("fusion");
  readPingNavFusionOptions(fusion, options.fusion);
  fusion.rejectUnknownKeys();
  sss::core::ConfigSection canonical = section.section("canonical");
  readCanonicalTransformOptions(canonical, options.canonical);
  canonical.rejectUnknownKeys();
  sss::core::ConfigSection lines = section.section("lines");
  readLineSegmenterOptions(lines, options.lines);
  lines.rejectUnknownKeys();
  sss::core::ConfigSection subframes = section.section("subframes");
  readSubframeOptions(subframes, options.subframes);
  subframes.rejectUnknownKeys();
}

namespace {
SubframeGeometry geometryOf(const SubframeBufferOptions& options) {
  SubframeGeometry geometry;
  geometry.bins_per_side = options.canonical.bins_per_side;
  geometry.bin_size_m = options.canonical.bin_size_m;
  geometry.first_bin_range_m = options.canonical.first_bin_range_m;
  geometry.T_body_sonar = options.fusion.T_body_sonar();
  return geometry;
}
}  // namespace

SubframeBuffer::SubframeBuffer(const SubframeBufferOptions& options)
    : options_(options),
      geometry_(geometryOf(options)),
      fusion_(options.fusion),
      canonical_(std::make_unique<CanonicalTransform>(options.canonical)),
      builder_(std::make_unique<SubframeBuilder>(options.lines, options.subframes, geometry_)),
      swath_fixed_(!options.canonical.swath_from_range) {}

void SubframeBuffer::fitSwathTo(const FusedPing& first) {
  swath_fixed_ = true;
  const PingInput& ping = first.ping;
  const double last_slant_m =
      ping.start_range_m + ping.sampleSpacingM() * static_cast<double>(std::max(ping.port.size(), ping.starboard.size()));
  if (!(last_slant_m > first.altitude_m)) return;
  const double ground_m = std::sqrt(last_slant_m * last_slant_m - first.altitude_m * first.altitude_m);
  const CanonicalTransformOptions& c = options_.canonical;
  const int bins = std::min(c.max_bins_per_side,
                            static_cast<int>(std::ceil((ground_m - c.first_bin_range_m) / c.bin_size_m)));
  if (bins <= c.bins_per_side) return;
  // Nothing transformed yet: the stages start again on the wider axis (keeping the numbering).
  const SubframeNumbering numbering = builder_->numbering();
  options_.canonical.bins_per_side = bins;
  geometry_ = geometryOf(options_);
  canonical_ = std::make_unique<CanonicalTransform>(options_.canonical);
  builder_ = std::make_unique<SubframeBuilder>(options_.lines, options_.subframes, geometry_);
  builder_->resumeNumbering(numbering);
}

void SubframeBuffer::addNav(const NavInput& nav, std::vector<Subframe>& out) {
  fusion_.addNav(nav, fused_);
  process(out);
}

void SubframeBuffer::addPing(PingInput ping, std::vector<Subframe>& out) {
  fusion_.addPing(std::move(ping), fused_);
  process(out);
}

void SubframeBuffer::finish(std::vector<Subframe>& out) {
  fusion_.finish(fused_);
  process(out);
  builder_->finish(out);
}

void SubframeBuffer::process(std::vector<Subframe>& out) {
  for (FusedPing& fused : fused_) {
    if (observer_) observer_(fused);
    if (!swath_fixed_) fitSwathTo(fused);
    CanonicalPing row = canonical_->transform(std::move(fused));
    if (row.turn) ++turn_rows_;
    builder_->addPing(std::move(row), out);
  }
  fused_.clear();
}

SubframeBufferCounters SubframeBuffer::counters() const {
  SubframeBufferCounters counters;
  counters.fusion = fusion_.counters();
  counters.builder = builder_->counters();
  counters.turn_rows = turn_rows_;
  return counters;
}

size_t SubframeBuffer::memoryBytes() const {
  return fusion_.memoryBytes() + canonical_->memoryBytes() + builder_->memoryBytes();
}

}  // namespace sss::subframe
