// matches.csv of sss-process --write-matches: every dense match of every pair the matcher tried (each
// association round), the subframes' rows and recall probes, enough to evaluate the matches against
// the simulator's truth without the pipeline (sss-eval --matches FILE --mission DIR).
//
// Comment lines: a description, then "# parameters: key=value ..." with bins_per_side, bin_size_m,
// first_bin_range_m (the canonical ground-range axis), decimation (bins per matching column),
// stride (of the matching grid), probe_step and sonar_position_body_m / sonar_orientation_body_wxyz
// (x;y;z and w;x;y;z). Then one header and rows of three kinds:
//   ping:  a row of a subframe: subframe_a, row_a, utime_a_us, altitude_a_m (the altitude its canonical
//          transform used), heading_a_rad (DR), valid_columns ("first-last;..." runs of valid
//          full-resolution columns).
//   match: A(row_a, col_a) -> B(row_b, col_b), full-resolution columns; A's ping and B's fractional row
//          as times (utime_b_us interpolated), side, signed ground range and altitude of either pixel
//          (slant = hypot(ground, altitude), the canonical transform), zncc, the two subframes' centre
//          headings (DR), matched = 1.
//   probe: a valid A pixel on every probe_step-th node of the matching grid (recall), with its time,
//          side, ground range, altitude; matched = 1 when a match starts within one matching column.
// Unused fields are empty.
#pragma once

#include <cstdio>
#include <set>
#include <string>

#include "pipeline/core/status.hpp"
#include "pipeline/matcher/pair_matcher.hpp"
#include "pipeline/subframe/subframe_builder.hpp"

namespace sss::offline {

class MatchCsvWriter {
 public:
  MatchCsvWriter() = default;
  MatchCsvWriter(const MatchCsvWriter&) = delete;
  MatchCsvWriter& operator=(const MatchCsvWriter&) = delete;
  ~MatchCsvWriter();

  // Creates the file; fails with a message.
  sss::core::Status open(const std::string& path, int stride, int probe_step);
  // One pair of one association round (rows of subframes not written yet, matches, probes).
  void addPair(const sss::core::Subframe& a, const sss::core::Subframe& b, int association_round,
               const sss::matcher::PairMatch& match);
  // Flushes and closes; fails with a message when anything failed to write.
  sss::core::Status close();

 private:
  void writePreamble(const sss::core::SubframeGeometry& geometry, int decimation);
  void writePings(const sss::core::Subframe& subframe);

  std::FILE* file_ = nullptr;
  std::string path_;
  int stride_ = 2;
  int probe_step_ = 4;
  bool preamble_written_ = false;
  std::set<int64_t> subframes_written_;
};

}  // namespace sss::offline
