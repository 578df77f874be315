// Correspondence accuracy against the simulator's ray-cast truth: end-point error of every match
// in pixels of the matching image and in metres, the fraction within 2 px, recall at 2 px, by pair
// type. In process (sss-bench-matcher) or from sss-process's matches.csv (sss-eval).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/core/status.hpp"

// Only references here, so the report code can include this without the simulator and the matcher.
namespace sss::sim {
class Mission;
struct SimulatedSurvey;
}  // namespace sss::sim
namespace sss::core {
struct Subframe;
}
namespace sss::matcher {
struct Correspondence;
}

namespace sss::eval {

enum class PairType { kParallel = 0, kAntiParallel = 1, kCrossing = 2 };
constexpr int kPairTypes = 3;

// From the two subframes' centre headings: |difference| <= 30 deg parallel, >= 150 deg
// anti-parallel, else crossing.
PairType classifyPair(double heading_a_rad, double heading_b_rad);
PairType classifyPair(const sss::core::Subframe& a, const sss::core::Subframe& b);
// "parallel", "anti_parallel", "crossing" (the JSON key suffixes). Inline: the report uses it
// without linking the simulator.
inline const char* pairTypeName(PairType type) {
  switch (type) {
    case PairType::kParallel: return "parallel";
    case PairType::kAntiParallel: return "anti_parallel";
    case PairType::kCrossing: return "crossing";
  }
  return "?";
}

struct MatchEvaluation {
  long matches = 0;
  long evaluated = 0;      // matches whose A pixel has a true B pixel
  long within_2px = 0;
  long probes = 0;         // valid A pixels where recall is probed
  long matchable = 0;      // probes whose true B pixel is valid with a full patch, times recall_step^2
  double error_sum_px = 0.0;
  double error_sum_m = 0.0;
  // Signed, to tell a systematic offset from scatter: the truth's B row minus the match's, in
  // metres along B's track (positive: the truth is later in B), and the truth's ground range in B
  // minus the match's (positive: the match is nearer B's track than the truth).
  double along_error_sum_m = 0.0;
  double outward_error_sum_m = 0.0;
  double withinFraction() const { return evaluated ? double(within_2px) / evaluated : 0.0; }
  double recall() const { return matchable ? double(within_2px) / matchable : 0.0; }
  double meanErrorPx() const { return evaluated ? error_sum_px / evaluated : 0.0; }
  double meanErrorM() const { return evaluated ? error_sum_m / evaluated : 0.0; }
  double meanAlongErrorM() const { return evaluated ? along_error_sum_m / evaluated : 0.0; }
  double meanOutwardErrorM() const { return evaluated ? outward_error_sum_m / evaluated : 0.0; }
  MatchEvaluation& operator+=(const MatchEvaluation& other);
};

// The pixels (row, full-resolution column) of A where recall is probed: every recall_step-th node
// of the matching stride grid (rows every stride * recall_step, columns every stride * recall_step
// * decimation bins) that is valid in A's mask (rows x cols).
// (Inline: sss-process's matches.csv writer uses it without the simulator.)
inline std::vector<std::pair<int, int>> recallProbes(int rows, int cols, const std::vector<uint8_t>& mask, int stride,
                                                     int decimation, int recall_step) {
  std::vector<std::pair<int, int>> probes;
  const int step = stride * recall_step;
  for (int r = 0; r < rows; r += step) {
    for (int c = 0; c < cols; c += step * decimation) {
      if (mask[static_cast<size_t>(r) * cols + c] == 0) probes.emplace_back(r, c);
    }
  }
  return probes;
}

// Errors are measured in pixels of the matching image: rows = pings, columns = `decimation`
// canonical bins (match columns are full-resolution); in metres as along-track (row error times
// the true ping spacing) and ground-range error. Recall = matches within 2 px over the matchable
// probes scaled back to the stride grid (bounded ray casts). Subframe pings' ping_number must be
// the mission's ping index.
MatchEvaluation evaluateMatches(const sss::sim::Mission& mission, const sss::core::Subframe& a,
                                const sss::core::Subframe& b,
                                const std::vector<sss::matcher::Correspondence>& matches, int decimation,
                                const std::vector<std::pair<int, int>>& probes, int recall_step);
// The same with the probes of A's mask.
MatchEvaluation evaluateMatches(const sss::sim::SimulatedSurvey& survey, const sss::core::Subframe& a,
                                const sss::core::Subframe& b,
                                const std::vector<sss::matcher::Correspondence>& matches, int stride, int decimation,
                                int recall_step = 4);

// ---- matches.csv (sss-process --write-matches; format in tools/process/match_writer.hpp) ----------

struct PairMatchReport {
  int64_t subframe_a = 0;
  int64_t subframe_b = 0;
  int round = 0;
  double heading_a_rad = 0.0;  // centre headings (DR) the type comes from
  double heading_b_rad = 0.0;
  PairType type = PairType::kParallel;
  MatchEvaluation evaluation;
};

struct MatchFileEvaluation {
  std::string path;
  std::string mission_dir;
  int decimation = 1;
  int stride = 1;
  int probe_step = 1;
  double matching_pixel_m = 0.0;  // bin size * decimation: a column of the matching image
  size_t subframes = 0;
  std::vector<PairMatchReport> pairs;  // in file order of first appearance
  long pairs_by_type[kPairTypes] = {0, 0, 0};
  MatchEvaluation by_type[kPairTypes];
  MatchEvaluation overall;
};

// Reads matches.csv and evaluates every match and probe against the truth rebuilt from
// MISSION_DIR/mission.yaml. Fails with "FILE[:LINE]: ..." for unusable input.
sss::core::Status evaluateMatchFile(const std::string& matches_path, const std::string& mission_dir,
                                    MatchFileEvaluation& result);

}  // namespace sss::eval
