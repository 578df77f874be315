// The subframe buffer's pipeline of library stages. See subframe_buffer.hpp.
#include "pipeline/subframe/subframe_buffer.hpp"

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
      canonical_(options.canonical),
      builder_(options.lines, options.subframes, geometry_) {}

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
  builder_.finish(out);
}

void SubframeBuffer::process(std::vector<Subframe>& out) {
  for (FusedPing& fused : fused_) {
    if (observer_) observer_(fused);
    CanonicalPing row = canonical_.transform(std::move(fused));
    if (row.turn) ++turn_rows_;
    builder_.addPing(std::move(row), out);
  }
  fused_.clear();
}

SubframeBufferCounters SubframeBuffer::counters() const {
  SubframeBufferCounters counters;
  counters.fusion = fusion_.counters();
  counters.builder = builder_.counters();
  counters.turn_rows = turn_rows_;
  return counters;
}

size_t SubframeBuffer::memoryBytes() const {
  return fusion_.memoryBytes() + canonical_.memoryBytes() + builder_.memoryBytes();
}

}  // namespace sss::subframe
