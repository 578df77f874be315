// Overlap detection between subframes from their geo-referenced footprints.
#include "pipeline/matcher/overlap.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include "pipeline/core/georeference.hpp"

namespace sss::matcher {
namespace {

double polygonArea(const std::vector<cv::Point2d>& polygon) {
  if (polygon.size() < 3) return 0.0;
  std::vector<cv::Point2f> p(polygon.begin(), polygon.end());
  return std::abs(cv::contourArea(p));
}

// Convex hull of seabed points (float for OpenCV's intersection, relative to a local origin so
// float keeps centimetres).
std::vector<cv::Point2d> hull(const std::vector<cv::Point2d>& points) {
  if (points.size() < 3) return {};
  std::vector<cv::Point2f> p(points.begin(), points.end());
  std::vector<cv::Point2f> h;
  cv::convexHull(p, h);
  return std::vector<cv::Point2d>(h.begin(), h.end());
}

double intersectionArea(const std::vector<cv::Point2d>& a, const std::vector<cv::Point2d>& b, const cv::Point2d& origin) {
  if (a.size() < 3 || b.size() < 3) return 0.0;
  std::vector<cv::Point2f> pa, pb, out;
  for (const auto& p : a) pa.emplace_back(static_cast<float>(p.x - origin.x), static_cast<float>(p.y - origin.y));
  for (const auto& p : b) pb.emplace_back(static_cast<float>(p.x - origin.x), static_cast<float>(p.y - origin.y));
  const float area = cv::intersectConvexConvex(pa, pb, out, true);
  return area > 0.0f ? static_cast<double>(area) : 0.0;
}

}  // namespace

void readOverlapOptions(sss::core::ConfigSection& section, OverlapOptions& options) {
  section.optional("min_overlap_fraction", options.min_overlap_fraction, {sss::core::inRange(0.0, 1.0)});
  section.optional("fraction_of_swath", options.fraction_of_swath);
  section.optional("max_candidates", options.max_candidates, {sss::core::inRange(1, 100)});
  section.optional("footprint_row_step", options.footprint_row_step, {sss::core::inRange(1, 1000)});
  section.optional("skip_same_line", options.skip_same_line);
}

std::vector<std::string> validateOverlapOptions(const OverlapOptions& o) {
  std::vector<std::string> problems;
  if (!(o.min_overlap_fraction >= 0.0 && o.min_overlap_fraction <= 1.0))
    problems.push_back("min_overlap_fraction must be in [0, 1]");
  if (o.max_candidates < 1) problems.push_back("max_candidates must be >= 1");
  if (o.footprint_row_step < 1) problems.push_back("footprint_row_step must be >= 1");
  return problems;
}

Footprint computeFootprint(const sss::core::Subframe& subframe, const std::vector<sss::core::Pose>& T_world_body,
                           const OverlapOptions& options) {
  Footprint footprint;
  footprint.subframe_id = subframe.id;
  footprint.line_id = subframe.line_id;
  const int rows = std::min<int>(subframe.rows(), static_cast<int>(T_world_body.size()));
  const int cols = subframe.cols(), per_side = subframe.geometry.bins_per_side;
  if (rows == 0 || cols == 0 || subframe.mask.size() < static_cast<size_t>(rows) * cols) return footprint;
  std::vector<cv::Point2d> port, starboard;
  auto add = [&](std::vector<cv::Point2d>& points, int row, int column) {
    const auto p = sss::core::georeferencePixel(subframe.geometry, T_world_body[row], subframe.pings[row].altitude_m,
                                                    column);
    if (p) points.emplace_back(p->x(), p->y());
  };
  const int step = std::max(1, options.footprint_row_step);
  std::vector<int> sampled_rows;
  for (int row = 0; row < rows; row += step) sampled_rows.push_back(row);
  if (sampled_rows.back() != rows - 1) sampled_rows.push_back(rows - 1);  // the footprint's far edge
  for (int row : sampled_rows) {
    const uint8_t* mask = subframe.mask.data() + static_cast<size_t>(row) * cols;
    // Port: columns [0, per_side), outermost first; starboard: [per_side, cols), innermost first.
    int port_outer = -1, port_inner = -1, starboard_inner = -1, starboard_outer = -1;
    for (int c = 0; c < per_side; ++c) {
      if (mask[c] != sss::core::kMaskValid) continue;
      if (port_outer < 0) port_outer = c;
      port_inner = c;
    }
    for (int c = per_side; c < cols; ++c) {
      if (mask[c] != sss::core::kMaskValid) continue;
      if (starboard_inner < 0) starboard_inner = c;
      starboard_outer = c;
    }
    if (port_outer >= 0) {
      add(port, row, port_outer);
      add(port, row, port_inner);
    }
    if (starboard_inner >= 0) {
      add(starboard, row, starboard_inner);
      add(starboard, row, starboard_outer);
    }
  }
  footprint.port_ne_m = hull(port);
  footprint.starboard_ne_m = hull(starboard);
  footprint.port_area_m2 = polygonArea(footprint.port_ne_m);
  footprint.starboard_area_m2 = polygonArea(footprint.starboard_ne_m);
  footprint.area_m2 = footprint.port_area_m2 + footprint.starboard_area_m2;
  double n_min = 1e300, n_max = -1e300, e_min = 1e300, e_max = -1e300;
  for (const auto* polygon : {&footprint.port_ne_m, &footprint.starboard_ne_m}) {
    for (const auto& p : *polygon) {
      n_min = std::min(n_min, p.x);
      n_max = std::max(n_max, p.x);
      e_min = std::min(e_min, p.y);
      e_max = std::max(e_max, p.y);
    }
  }
  if (n_min <= n_max) footprint.bounds_ne_m = cv::Rect2d(n_min, e_min, n_max - n_min, e_max - e_min);
  return footprint;
}

namespace {

// The seabed two footprints share: its area (every side of one against every side of the other)
// and, the largest over the side pairs, its fraction of the smaller of the two swaths (one side of a
// subframe) that image it (OverlapOptions::fraction_of_swath).
struct SharedSeabed {
  double area_m2 = 0.0;
  double fraction_of_smaller_swath = 0.0;
};

SharedSeabed sharedSeabed(const Footprint& a, const Footprint& b) {
  SharedSeabed shared;
  if ((a.bounds_ne_m & b.bounds_ne_m).area() <= 0.0) return shared;
  const cv::Point2d origin(a.bounds_ne_m.x, a.bounds_ne_m.y);
  const std::pair<const std::vector<cv::Point2d>*, double> sides_a[] = {{&a.port_ne_m, a.port_area_m2},
                                                                         {&a.starboard_ne_m, a.starboard_area_m2}};
  const std::pair<const std::vector<cv::Point2d>*, double> sides_b[] = {{&b.port_ne_m, b.port_area_m2},
                                                                         {&b.starboard_ne_m, b.starboard_area_m2}};
  for (const auto& [polygon_a, area_a_m2] : sides_a) {
    for (const auto& [polygon_b, area_b_m2] : sides_b) {
      const double area = intersectionArea(*polygon_a, *polygon_b, origin);
      shared.area_m2 += area;
      const double smaller = std::min(area_a_m2, area_b_m2);
      if (smaller > 0.0) shared.fraction_of_smaller_swath = std::max(shared.fraction_of_smaller_swath, area / smaller);
    }
  }
  return shared;
}

}  // namespace

double overlapAreaM2(const Footprint& a, const Footprint& b) { return sharedSeabed(a, b).area_m2; }

std::vector<OverlapCandidate> findOverlaps(const Footprint& footprint, const std::vector<Footprint>& others,
                                           const OverlapOptions& options) {
  std::vector<OverlapCandidate> candidates;
  for (const Footprint& other : others) {
    if (other.subframe_id == footprint.subframe_id) continue;
    if (options.skip_same_line && other.line_id == footprint.line_id) continue;
    if (footprint.area_m2 <= 0.0 || other.area_m2 <= 0.0) continue;
    const SharedSeabed shared = sharedSeabed(footprint, other);
    const double area = shared.area_m2;
    const double fraction = options.fraction_of_swath ? shared.fraction_of_smaller_swath
                                                      : area / std::min(footprint.area_m2, other.area_m2);
    if (fraction >= options.min_overlap_fraction && area > 0.0) {
      candidates.push_back({other.subframe_id, fraction, area});
    }
  }
  // Largest overlap first; ties by id so the choice does not depend on storage order.
  std::sort(candidates.begin(), candidates.end(), [](const OverlapCandidate& x, const OverlapCandidate& y) {
    if (x.overlap_area_m2 != y.overlap_area_m2) return x.overlap_area_m2 > y.overlap_area_m2;
    return x.subframe_id < y.subframe_id;
  });
  if (static_cast<int>(candidates.size()) > options.max_candidates) candidates.resize(options.max_candidates);
  return candidates;
}

}  // namespace sss::matcher
