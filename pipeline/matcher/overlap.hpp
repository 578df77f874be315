// Overlap detection between subframes from their geo-referenced footprints: the port and
// starboard swaths as polygons on the seabed (lines cross at any angle), intersected exactly.
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

#include "pipeline/core/config.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/core/subframe_types.hpp"

namespace sss::matcher {

struct OverlapOptions {
  // A pair is a candidate when the seabed both subframes image covers at least this fraction of
  // the smaller footprint (paper: overlapping subframes; adjacent survey lines overlap 40-80 %).
  double min_overlap_fraction = 0.15;
  // true: of the smaller of the two swaths (one side of a subframe) that share the seabed instead.
  // One side of a subframe meets one side of the other on parallel lines, so a fraction of the
  // footprint (both sides) halves the overlap of adjacent lines, and halves it again when their
  // subframes meet half a subframe apart: far-range lines (150 m apart, 93 m range) then get no
  // pair at all. Measured, off (README): it recovers such missions and costs others.
  bool fraction_of_swath = false;
  int max_candidates = 4;       // per new subframe, largest overlap first: bounded work per subframe
  int footprint_row_step = 10;  // rows between footprint vertices along track (10 pings = 5 m)
  // Subframes of the same survey line never overlap except at a shared edge; they are skipped.
  bool skip_same_line = true;
};

void readOverlapOptions(sss::core::ConfigSection& section, OverlapOptions& options);
std::vector<std::string> validateOverlapOptions(const OverlapOptions& options);

// The seabed imaged by a subframe's valid pixels, under a given set of ping poses: one convex
// polygon per side (north, east in metres), between the innermost and outermost valid bins.
struct Footprint {
  int64_t subframe_id = 0;
  int line_id = 0;
  std::vector<cv::Point2d> port_ne_m;
  std::vector<cv::Point2d> starboard_ne_m;
  double port_area_m2 = 0.0;
  double starboard_area_m2 = 0.0;
  double area_m2 = 0.0;  // both sides
  cv::Rect2d bounds_ne_m;  // of both polygons (a quick rejection test)
};

Footprint computeFootprint(const sss::core::Subframe& subframe, const std::vector<sss::core::Pose>& T_world_body,
                           const OverlapOptions& options);

// Area imaged by both footprints (every side of one against every side of the other).
double overlapAreaM2(const Footprint& a, const Footprint& b);

struct OverlapCandidate {
  int64_t subframe_id = 0;
  double overlap_fraction = 0.0;  // of the smaller footprint (or swath: fraction_of_swath)
  double overlap_area_m2 = 0.0;
};

// Of `others`, the ones overlapping `footprint` enough, largest first, at most max_candidates.
std::vector<OverlapCandidate> findOverlaps(const Footprint& footprint, const std::vector<Footprint>& others,
                                           const OverlapOptions& options);

}  // namespace sss::matcher
