// matches.csv writer; the format is described in match_writer.hpp.
#include "tools/process/match_writer.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "pipeline/core/pose.hpp"
#include "tools/eval/match_metrics.hpp"

namespace sss::offline {
namespace {

const char* kColumns =
    "kind,subframe_a,subframe_b,round,row_a,col_a,row_b,col_b,utime_a_us,utime_b_us,side_a,side_b,ground_a_m,"
    "ground_b_m,altitude_a_m,altitude_b_m,zncc,heading_a_rad,heading_b_rad,matched,valid_columns";

double headingOf(const sss::core::Pose& T_world_body) {
  return sss::core::eulerFromQuaternion(T_world_body.rotation).heading_rad;
}

// Time and altitude of a fractional row, linear between its two pings.
void interpolateRow(const sss::core::Subframe& s, double row, int64_t& utime_us, double& altitude_m) {
  const int r0 = std::clamp(static_cast<int>(std::floor(row)), 0, std::max(0, s.rows() - 2));
  const int r1 = std::min(r0 + 1, s.rows() - 1);
  const double alpha = row - r0;
  utime_us = s.pings[r0].utime_us +
             static_cast<int64_t>(std::llround(alpha * static_cast<double>(s.pings[r1].utime_us - s.pings[r0].utime_us)));
  altitude_m = s.pings[r0].altitude_m + alpha * (s.pings[r1].altitude_m - s.pings[r0].altitude_m);
}

const char* sideName(double ground_m) { return ground_m < 0.0 ? "port" : "starboard"; }

}  // namespace

MatchCsvWriter::~MatchCsvWriter() {
  if (file_) std::fclose(file_);
}

sss::core::Status MatchCsvWriter::open(const std::string& path, int stride, int probe_step) {
  path_ = path;
  stride_ = std::max(1, stride);
  probe_step_ = std::max(1, probe_step);
  file_ = std::fopen(path.c_str(), "w");
  if (!file_) {
    return sss::core::Status::error("cannot write " + path + "; check the output folder is writable");
  }
  return sss::core::Status::success();
}

void MatchCsvWriter::writePreamble(const sss::core::SubframeGeometry& g, int decimation) {
  const Eigen::Vector3d& t = g.T_body_sonar.translation;
  const Eigen::Quaterniond& q = g.T_body_sonar.rotation;
  std::fprintf(file_,
               "# matches.csv (sss-process --write-matches): dense matches of every pair and association round, the\n"
               "# subframes' rows and recall probes; evaluate with sss-eval --matches FILE --mission DIR.\n"
               "# Rows: ping (a subframe row), match (A -> B, full-resolution columns), probe (a valid A pixel on\n"
               "# every probe_step-th matching-grid node); see tools/process/match_writer.hpp for every column.\n"
               "# parameters: bins_per_side=%d bin_size_m=%.17g first_bin_range_m=%.17g decimation=%d stride=%d "
               "probe_step=%d sonar_position_body_m=%.17g;%.17g;%.17g sonar_orientation_body_wxyz=%.17g;%.17g;%.17g;%.17g\n"
               "%s\n",
               g.bins_per_side, g.bin_size_m, g.first_bin_range_m, decimation, stride_, probe_step_, t.x(), t.y(), t.z(),
               q.w(), q.x(), q.y(), q.z(), kColumns);
  preamble_written_ = true;
}

void MatchCsvWriter::writePings(const sss::core::Subframe& s) {
  if (!subframes_written_.insert(s.id).second) return;
  const int cols = s.cols();
  std::string runs;
  for (int row = 0; row < s.rows(); ++row) {
    runs.clear();
    const uint8_t* mask = s.mask.data() + static_cast<size_t>(row) * cols;
    for (int c = 0; c < cols;) {
      if (mask[c] != 0) {
        ++c;
        continue;
      }
      int last = c;
      while (last + 1 < cols && mask[last + 1] == 0) ++last;
      if (!runs.empty()) runs += ';';
      runs += std::to_string(c) + "-" + std::to_string(last);
      c = last + 1;
    }
    const auto& ping = s.pings[row];
    std::fprintf(file_, "ping,%lld,,,%d,,,,%lld,,,,,,%.17g,,,%.9f,,,%s\n", static_cast<long long>(s.id), row,
                 static_cast<long long>(ping.utime_us), ping.altitude_m, headingOf(ping.T_world_body), runs.c_str());
  }
}

void MatchCsvWriter::addPair(const sss::core::Subframe& a, const sss::core::Subframe& b, int association_round,
                             const sss::matcher::PairMatch& match) {
  if (!file_ || a.rows() < 2 || b.rows() < 2) return;
  if (!preamble_written_) writePreamble(a.geometry, match.decimation);
  writePings(a);
  writePings(b);
  const double heading_a = headingOf(a.centre().T_world_body), heading_b = headingOf(b.centre().T_world_body);
  const long long id_a = a.id, id_b = b.id;
  std::map<int, std::vector<float>> match_columns;  // A row -> match columns, for the probes' flag
  for (const sss::matcher::Correspondence& m : match.matches) {
    const int row_a = std::clamp(static_cast<int>(std::lround(m.row_a)), 0, a.rows() - 1);
    match_columns[row_a].push_back(m.col_a);
    const double ground_a = a.geometry.signedGroundRangeM(m.col_a), ground_b = b.geometry.signedGroundRangeM(m.col_b);
    int64_t utime_b = 0;
    double altitude_b = 0.0;
    interpolateRow(b, m.row_b, utime_b, altitude_b);
    std::fprintf(file_,
                 "match,%lld,%lld,%d,%.9g,%.9g,%.9g,%.9g,%lld,%lld,%s,%s,%.6f,%.6f,%.17g,%.6f,%.4f,%.9f,%.9f,1,\n",
                 id_a, id_b, association_round, m.row_a, m.col_a, m.row_b, m.col_b,
                 static_cast<long long>(a.pings[row_a].utime_us), static_cast<long long>(utime_b), sideName(ground_a),
                 sideName(ground_b), ground_a, ground_b, a.pings[row_a].altitude_m, altitude_b, m.zncc, heading_a,
                 heading_b);
  }
  for (const auto& [row, col] :
       sss::eval::recallProbes(a.rows(), a.cols(), a.mask, stride_, match.decimation, probe_step_)) {
    bool matched = false;
    const auto it = match_columns.find(row);
    if (it != match_columns.end()) {
      for (float c : it->second) matched = matched || std::abs(c - col) <= match.decimation;
    }
    const double ground = a.geometry.signedGroundRangeM(col);
    std::fprintf(file_, "probe,%lld,%lld,%d,%d,%d,,,%lld,,%s,,%.6f,,%.17g,,,%.9f,%.9f,%d,\n", id_a, id_b,
                 association_round, row, col, static_cast<long long>(a.pings[row].utime_us), sideName(ground), ground,
                 a.pings[row].altitude_m, heading_a, heading_b, matched ? 1 : 0);
  }
}

sss::core::Status MatchCsvWriter::close() {
  if (!file_) return sss::core::Status::success();
  if (!preamble_written_) {
    std::fprintf(file_, "# matches.csv (sss-process --write-matches): the matcher tried no pair.\n%s\n", kColumns);
  }
  const bool ok = std::ferror(file_) == 0;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!ok || !closed) {
    return sss::core::Status::error("cannot write " + path_ + "; is the disk full?");
  }
  return sss::core::Status::success();
}

}  // namespace sss::offline
