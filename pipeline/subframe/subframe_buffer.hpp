// The subframe buffer's library: pings and DR nav in, canonical geo-referenced subframes out
// (fusion -> canonical transform -> line segmentation -> subframes), with its counters.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "pipeline/core/config.hpp"
#include "pipeline/subframe/canonical_transform.hpp"
#include "pipeline/subframe/ping_nav_fusion.hpp"
#include "pipeline/subframe/subframe_builder.hpp"

namespace sss::subframe {

struct SubframeBufferOptions {
  PingNavFusionOptions fusion;
  CanonicalTransformOptions canonical;
  LineSegmenterOptions lines;
  SubframeOptions subframes;
};

// Reads the library keys of the subframe_buffer section (sub-sections fusion, canonical, lines,
// subframes) into options.
void readSubframeBufferOptions(sss::core::ConfigSection& section, SubframeBufferOptions& options);

struct SubframeBufferCounters {
  PingNavFusionCounters fusion;
  SubframeBuilderCounters builder;
  uint64_t turn_rows = 0;
};

class SubframeBuffer {
 public:
  explicit SubframeBuffer(const SubframeBufferOptions& options);

  // Each call appends the subframes it completes.
  void addNav(const NavInput& nav, std::vector<Subframe>& out);
  void addPing(PingInput ping, std::vector<Subframe>& out);
  // End of input: pings still waiting are dropped, the open line's tail is decided.
  void finish(std::vector<Subframe>& out);

  SubframeBufferCounters counters() const;
  const BottomTrackerCounters& bottomTrackCounters() const { return fusion_.bottomTrackCounters(); }
  SubframeNumbering numbering() const { return builder_->numbering(); }
  void resumeNumbering(const SubframeNumbering& numbering) { builder_->resumeNumbering(numbering); }
  const SubframeBufferOptions& options() const { return options_; }
  // The ground-range axis: the configured one, widened by the first ping with a pose when
  // canonical.swath_from_range (see CanonicalTransformOptions).
  const SubframeGeometry& geometry() const { return geometry_; }
  // Bytes held by the buffers (nav history, waiting pings, rows of the open subframe).
  size_t memoryBytes() const;
  // Called with every ping that got its DR pose, turns included (the offline runner's per-ping
  // trajectory), before the canonical transform.
  void setFusedPingObserver(std::function<void(const FusedPing&)> observer) { observer_ = std::move(observer); }

 private:
  void process(std::vector<Subframe>& out);
  void fitSwathTo(const FusedPing& first);

  SubframeBufferOptions options_;
  SubframeGeometry geometry_;
  PingNavFusion fusion_;
  std::unique_ptr<CanonicalTransform> canonical_;
  std::unique_ptr<SubframeBuilder> builder_;
  bool swath_fixed_ = false;
  std::vector<FusedPing> fused_;  // reused
  uint64_t turn_rows_ = 0;
  std::function<void(const FusedPing&)> observer_;
};

}  // namespace sss::subframe
