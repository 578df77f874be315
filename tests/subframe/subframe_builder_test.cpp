// Line segmentation and subframe cutting on synthetic rows: subframe boundaries and centre
// pings at line ends, lines shorter than N, turns and heading changes.
#include "pipeline/subframe/subframe_builder.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <map>

namespace sss::subframe {
namespace {

struct Rows {
  int64_t next_number = 0;
  int64_t utime_us = 1780300800000000;
  std::vector<Subframe> out;
  SubframeBuilder builder;

  explicit Rows(const SubframeOptions& options = {}, const LineSegmenterOptions& line_options = {})
      : builder(line_options, options, SubframeGeometry{4, 0.1, 0.0, {}}) {}

  void add(int count, double heading_rad, bool turn = false) {
    for (int i = 0; i < count; ++i) {
      CanonicalPing row;
      row.fused.ping.ping_number = next_number++;
      row.fused.ping.utime_us = utime_us;
      utime_us += 250000;
      row.fused.heading_rad = heading_rad;
      row.fused.steady_heading_rad = heading_rad;
      row.turn = turn;
      row.intensity.assign(8, static_cast<float>(row.fused.ping.ping_number));
      row.mask.assign(8, turn ? kMaskTurn : kMaskValid);
      builder.addPing(std::move(row), out);
    }
  }
};

TEST(SubframeBuilder, CutsFullSubframesAndEmitsALongEnoughTailWithItsOwnCentre) {
  Rows rows;
  rows.add(530, 0.0);  // 200 + 200 + 130
  ASSERT_EQ(rows.out.size(), 2u);  // emitted as soon as the 200th ping arrives
  rows.add(60, 0.0, true);         // turn: the line ends
  ASSERT_EQ(rows.out.size(), 3u);
  const Subframe& a = rows.out[0];
  const Subframe& b = rows.out[1];
  const Subframe& tail = rows.out[2];
  EXPECT_EQ(a.pings.front().ping_number, 0);
  EXPECT_EQ(a.pings.back().ping_number, 199);
  EXPECT_EQ(a.centre_ping_index, 100);
  EXPECT_EQ(b.pings.front().ping_number, 200);
  EXPECT_EQ(tail.rows(), 130);
  EXPECT_EQ(tail.pings.front().ping_number, 400);
  EXPECT_EQ(tail.centre_ping_index, 65);
  EXPECT_EQ(tail.centre().ping_number, 465);
  EXPECT_EQ(tail.image[static_cast<size_t>(65) * 8], 465.0f);  // rows carry their own pings
  EXPECT_EQ(a.id, 0);
  EXPECT_EQ(tail.id, 2);
  EXPECT_EQ(a.line_id, tail.line_id);
  EXPECT_EQ(rows.builder.counters().partial_subframes, 1u);
}

// A restarted subframe buffer: the numbering saved after the last emitted subframe is resumed, so
// ids never repeat and the line cut by the restart continues under a new line id.
TEST(SubframeBuilder, ResumedNumberingNeverReusesASubframeOrLineId) {
  Rows before;
  before.add(20, 0.0, true);
  before.add(450, 0.0);  // line 0: subframes 0, 1; 50 pings in the open subframe
  ASSERT_EQ(before.out.size(), 2u);
  const SubframeNumbering saved = before.builder.numbering();
  EXPECT_EQ(saved.next_subframe_id, 2);
  EXPECT_EQ(saved.next_line_id, 1);
  before.add(30, 1.5);  // the process is killed here: the open line's pings are lost

  Rows after;
  after.utime_us = before.utime_us;
  after.builder.resumeNumbering(saved);
  after.add(450, 1.5);   // the rest of that line: a new line id
  after.add(20, 1.5, true);
  after.add(210, -1.5);  // the next line
  ASSERT_EQ(after.out.size(), 4u);
  EXPECT_EQ(after.out[0].id, 2);
  EXPECT_EQ(after.out[0].line_id, 1);
  EXPECT_EQ(after.out[1].id, 3);
  EXPECT_EQ(after.out[2].id, 4);  // the line's tail of 50 pings (min_pings) at the turn
  EXPECT_EQ(after.out[2].line_id, 1);
  EXPECT_EQ(after.out[3].id, 5);
  EXPECT_EQ(after.out[3].line_id, 2);
  EXPECT_EQ(after.builder.numbering().next_subframe_id, 6);
  EXPECT_EQ(after.builder.numbering().next_line_id, 3);
}

TEST(SubframeBuilder, ShortLinesGiveOnePartialSubframeOrAreDroppedAndCounted) {
  Rows rows;
  rows.add(150, 0.0);        // line 0: shorter than N but >= min_pings
  rows.add(40, 0.0, true);
  rows.add(45, M_PI);        // line 1: < min_pings (50)
  rows.add(40, 0.0, true);
  rows.add(210, 0.0);        // line 2: 200 + 10
  rows.builder.finish(rows.out);
  ASSERT_EQ(rows.out.size(), 2u);
  EXPECT_EQ(rows.out[0].line_id, 0);
  EXPECT_EQ(rows.out[0].rows(), 150);
  EXPECT_EQ(rows.out[0].centre().ping_number, 75);
  EXPECT_EQ(rows.out[1].line_id, 2);
  EXPECT_EQ(rows.out[1].rows(), 200);
  EXPECT_EQ(rows.out[1].pings.front().ping_number, 275);  // 150 + 40 + 45 + 40
  const auto& c = rows.builder.counters();
  EXPECT_EQ(c.lines, 3u);
  EXPECT_EQ(c.dropped_short_tails, 2u);
  EXPECT_EQ(c.dropped_tail_pings, 55u);
  EXPECT_EQ(c.turn_pings, 80u);
}

TEST(SubframeBuilder, AHeadingChangeOrAPingGapEndsTheLine) {
  Rows rows;
  rows.add(120, 0.0);
  rows.add(120, 0.5);  // > 0.1 rad off the line's heading without a turn signature
  rows.utime_us += 10000000;  // 10 s without pings
  rows.add(120, 0.5);
  rows.builder.finish(rows.out);
  ASSERT_EQ(rows.out.size(), 3u);
  EXPECT_EQ(rows.out[0].line_id, 0);
  EXPECT_EQ(rows.out[1].line_id, 1);
  EXPECT_EQ(rows.out[2].line_id, 2);
  EXPECT_EQ(rows.out[1].pings.front().ping_number, 120);
}

// A wide turn below the turn-rate mask (0.015 rad/s at 4 Hz: 0.00375 rad per ping) between two
// lines: its pieces leave their heading within one subframe having turned through it, so they are
// turn pings, not lines; the lines on either side keep every subframe, and a straight piece ended
// by a sudden heading change (AHeadingChangeOrAPingGapEndsTheLine) stays a line.
TEST(SubframeBuilder, PiecesOfASlowTurnAreTurnPingsNotLines) {
  for (const bool pieces_are_turns : {true, false}) {
    LineSegmenterOptions line_options;
    line_options.curved_pieces_are_turns = pieces_are_turns;
    Rows rows(SubframeOptions{}, line_options);
    rows.add(400, 0.0);  // line: two subframes
    const int turn_pings = 838;  // pi rad at 0.00375 rad per ping
    for (int i = 1; i <= turn_pings; ++i) rows.add(1, 0.00375 * i);
    rows.add(400, M_PI);  // the next line, back the other way
    rows.builder.finish(rows.out);
    const auto& c = rows.builder.counters();
    std::map<int, int> rows_per_line;
    for (const Subframe& s : rows.out) rows_per_line[s.line_id] += s.rows();
    int short_lines = 0;
    for (const auto& [line, count] : rows_per_line) short_lines += count < 200;
    std::printf("pieces are turns: %d; lines %zu (%d shorter than a subframe), curved pieces %llu, turn pings %llu\n",
                pieces_are_turns, rows_per_line.size(), short_lines, (unsigned long long)c.curved_pieces,
                (unsigned long long)c.turn_pings);
    if (pieces_are_turns) {
      EXPECT_LE(short_lines, 2);       // at most the ends of the turn, each a tail of a line
      EXPECT_GE(c.curved_pieces, 10u);  // pi rad in pieces of ~0.2 rad
      EXPECT_GE(c.turn_pings, 600u);
    } else {
      EXPECT_GE(short_lines, 10);  // the turn as lines
      EXPECT_EQ(c.curved_pieces, 0u);
    }
    EXPECT_GE(rows_per_line.begin()->second, 400);   // the first line whole
    EXPECT_GE(rows_per_line.rbegin()->second, 400);  // and the last
  }
}

TEST(SubframeBuilder, ASteadyBlipInsideATurnDoesNotOpenALine) {
  Rows rows;
  rows.add(30, 0.0, true);
  rows.add(5, 1.0);  // fewer than min_steady_pings (8)
  rows.add(30, 0.0, true);
  rows.builder.finish(rows.out);
  EXPECT_TRUE(rows.out.empty());
  EXPECT_EQ(rows.builder.counters().lines, 0u);
  EXPECT_EQ(rows.builder.counters().turn_pings, 65u);
}

}  // namespace
}  // namespace sss::subframe

#include "pipeline/subframe/subframe_buffer.hpp"

namespace sss::subframe {
namespace {

TEST(SubframeBufferOptions, ReadsEverySubSectionAndRejectsTyposAndBadValues) {
  sss::core::Config config = sss::core::Config::fromString(R"(
subframe_buffer:
  fusion: {sonar_position_body_m: [1.2, 0.0, 0.4], max_nav_gap_s: 0.3}
  canonical: {bins_per_side: 1500, bin_size_m: 0.05}
  lines: {min_steady_pings: 12}
  subframes: {pings_per_subframe: 100, min_pings: 40, intensity_bits: 8}
)");
  sss::core::ConfigSection section = config.section("subframe_buffer");
  SubframeBufferOptions options;
  readSubframeBufferOptions(section, options);
  ASSERT_TRUE(config.ok()) << config.problemReport();
  EXPECT_DOUBLE_EQ(options.fusion.sonar_position_body_m.x(), 1.2);
  EXPECT_DOUBLE_EQ(options.fusion.max_nav_gap_s, 0.3);
  EXPECT_EQ(options.canonical.bins_per_side, 1500);
  EXPECT_EQ(options.lines.min_steady_pings, 12);
  EXPECT_EQ(options.subframes.pings_per_subframe, 100);
  EXPECT_EQ(options.subframes.intensity_bits, 8);

  sss::core::Config bad = sss::core::Config::fromString(R"(
subframe_buffer:
  canonical: {bin_size: 0.05}
  subframes: {pings_per_subframe: 100, min_pings: 150, intensity_bits: 12}
)");
  sss::core::ConfigSection bad_section = bad.section("subframe_buffer");
  SubframeBufferOptions bad_options;
  readSubframeBufferOptions(bad_section, bad_options);
  const std::string report = bad.problemReport();
  EXPECT_NE(report.find("subframe_buffer.canonical.bin_size"), std::string::npos) << report;
  EXPECT_NE(report.find("subframe_buffer.subframes.intensity_bits"), std::string::npos) << report;
  EXPECT_NE(report.find("subframe_buffer.subframes.min_pings"), std::string::npos) << report;
}

}  // namespace
}  // namespace sss::subframe
