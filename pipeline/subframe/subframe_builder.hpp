// Survey-line segmentation from the heading history and cutting of each line into subframes of
// N pings (paper Sec. "Subframe Pose Estimation": images evenly divided into subframes).
#pragma once

#include <cstdint>
#include <vector>

#include "pipeline/core/config.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/core/subframe_types.hpp"
#include "pipeline/subframe/canonical_transform.hpp"

namespace sss::subframe {

struct LineSegmenterOptions {
  // A line is a stretch of steady pings (not turn rows: see CanonicalTransformOptions) whose
  // heading stays within max_heading_deviation_rad of the line's mean heading.
  double max_heading_deviation_rad = 0.1;  // ~6 deg: DR heading hunting is < 0.3 deg
  int min_steady_pings = 8;                // steady pings in a row before a line opens (2 s)
  double max_ping_gap_s = 5.0;             // a longer gap between pings ends the line
  // A line that leaves its heading before it fills one subframe, its own heading having changed by
  // more than max_heading_deviation_rad from its first ping to its last, is a piece of a turn too
  // slow for the turn-rate mask (a wide turn: 0.015 rad/s at 250 m line spacing and 2 m/s), not a
  // survey line: its pings are turn pings. Matched as a line, such a piece is a fan whose far range is
  // stretched on one side and squeezed on the other by range x rate / speed (60-90 % at 90 m).
  // Off by default: on randomised seed 3798961521 (45 of 49 lines such pieces) it halved the
  // heightmap error (SLAM 1.36 -> 0.68 m) but not the ATE (0.885 -> 1.036 m, DR 0.675): the closures'
  // error there comes from the matches on sand waves (reject_inverted_relief), not from the pieces.
  bool curved_pieces_are_turns = false;
};

struct SubframeOptions {
  int pings_per_subframe = 200;  // paper: 200 pings per subframe
  int min_pings = 50;            // a line's last, partial subframe is emitted from this many pings (25 m)
  int intensity_bits = 16;       // quantisation of the published image: 8 or 16
  double max_intensity = 16.0;   // full scale of the quantised image (normalised mean = 1)
};

void readLineSegmenterOptions(sss::core::ConfigSection& section, LineSegmenterOptions& options);
void readSubframeOptions(sss::core::ConfigSection& section, SubframeOptions& options);

// The subframe types are core types (pipeline/core/subframe_types.hpp), shared with the matcher and
// the optimiser; their short names here for the stage's own code.
using sss::core::Subframe;
using sss::core::SubframeGeometry;
using sss::core::SubframePing;

struct SubframeBuilderCounters {
  uint64_t pings_in = 0;
  uint64_t turn_pings = 0;            // not in any line
  uint64_t lines = 0;                 // lines opened
  uint64_t subframes = 0;
  uint64_t partial_subframes = 0;     // a line's last subframe with min_pings..N-1 pings
  uint64_t dropped_short_tails = 0;   // a line's last pings, fewer than min_pings: dropped
  uint64_t dropped_tail_pings = 0;
  uint64_t curved_pieces = 0;         // lines that left their heading within one subframe: turns
};

// The ids the builder gives next. A restarted subframe buffer resumes them from its state file:
// subframe ids must stay unique within a mission (the optimiser refuses a duplicate), and a line
// id must not name two lines (the matcher matches only subframes of different lines).
struct SubframeNumbering {
  int64_t next_subframe_id = 0;
  int next_line_id = 0;
};

// Pings must come in time order (PingNavFusion releases them so). A subframe is emitted as soon
// as its N-th ping arrives; when a line ends (turn, heading change, gap, finish()), its remaining
// pings form a last subframe if there are at least min_pings of them (centre = middle of those
// pings), else they are dropped and counted: a short tail would give a weakly constrained centre.
class SubframeBuilder {
 public:
  SubframeBuilder(const LineSegmenterOptions& line_options, const SubframeOptions& options,
                  const SubframeGeometry& geometry);

  void addPing(CanonicalPing ping, std::vector<Subframe>& out);
  void finish(std::vector<Subframe>& out);

  // Line of the newest ping; -1 while turning or before a line opened.
  int currentLineId() const { return line_open_ ? line_id_ : -1; }
  // After the subframes emitted so far: the next subframe's id, and the id of the next line to
  // open (the open line's pings, lost in a restart, cannot continue its id).
  SubframeNumbering numbering() const { return {next_subframe_id_, line_id_ + 1}; }
  // Before the first ping: continue the numbering of an earlier run.
  void resumeNumbering(const SubframeNumbering& numbering);
  const SubframeBuilderCounters& counters() const { return counters_; }
  size_t memoryBytes() const;

 private:
  void closeLine(std::vector<Subframe>& out);
  void appendToLine(CanonicalPing&& ping, std::vector<Subframe>& out);
  void emit(std::vector<Subframe>& out);
  bool deviates(double heading_rad) const;

  LineSegmenterOptions line_options_;
  SubframeOptions options_;
  SubframeGeometry geometry_;
  bool line_open_ = false;
  int line_id_ = -1;
  double line_sin_sum_ = 0.0, line_cos_sum_ = 0.0;  // circular mean heading of the line
  bool line_emitted_ = false;                       // the open line has emitted a subframe
  std::vector<CanonicalPing> candidate_;            // steady pings before the line opens
  std::vector<CanonicalPing> current_;              // pings of the subframe being filled
  int64_t last_utime_us_ = 0;
  int64_t next_subframe_id_ = 0;
  SubframeBuilderCounters counters_;
};

}  // namespace sss::subframe
