// Correspondence accuracy against the simulator's ray-cast truth, in process and from matches.csv.
#include "tools/eval/match_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>

#include "pipeline/core/config.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/core/subframe_types.hpp"
#include "pipeline/matcher/dense_matcher.hpp"
#include "pipeline/subframe/canonical_transform.hpp"
#include "tools/eval/csv_fields.hpp"
#include "tools/sim/simulated_survey.hpp"

namespace sss::eval {

using sss::core::Status;
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kHalfPatchPx = 6;  // a patch must fit inside B around the true pixel

// Horizontal distance between the true positions of the two pings around a fractional row of B.
double pingSpacingM(const sss::sim::Mission& mission, const sss::core::Subframe& b, double row) {
  if (b.rows() < 2) return 0.0;
  const int r0 = std::clamp(static_cast<int>(std::floor(row)), 0, b.rows() - 2);
  const Eigen::Vector3d p0 = mission.truthAtPing(static_cast<size_t>(b.pings[r0].ping_number)).T_world_body.translation;
  const Eigen::Vector3d p1 = mission.truthAtPing(static_cast<size_t>(b.pings[r0 + 1].ping_number)).T_world_body.translation;
  return (p1 - p0).head<2>().norm();
}

}  // namespace

PairType classifyPair(double heading_a_rad, double heading_b_rad) {
  const double difference = std::abs(sss::core::wrapAngle(heading_b_rad - heading_a_rad));
  if (difference <= 30.0 * kPi / 180.0) return PairType::kParallel;
  if (difference >= 150.0 * kPi / 180.0) return PairType::kAntiParallel;
  return PairType::kCrossing;
}

PairType classifyPair(const sss::core::Subframe& a, const sss::core::Subframe& b) {
  const auto centreHeadingRad = [](const sss::core::Subframe& s) {
    return sss::core::eulerFromQuaternion(s.centre().T_world_body.rotation).heading_rad;
  };
  return classifyPair(centreHeadingRad(a), centreHeadingRad(b));
}

MatchEvaluation& MatchEvaluation::operator+=(const MatchEvaluation& other) {
  matches += other.matches;
  evaluated += other.evaluated;
  within_2px += other.within_2px;
  probes += other.probes;
  matchable += other.matchable;
  error_sum_px += other.error_sum_px;
  error_sum_m += other.error_sum_m;
  along_error_sum_m += other.along_error_sum_m;
  outward_error_sum_m += other.outward_error_sum_m;
  return *this;
}

MatchEvaluation evaluateMatches(const sss::sim::Mission& mission, const sss::core::Subframe& a,
                                const sss::core::Subframe& b,
                                const std::vector<sss::matcher::Correspondence>& matches, int decimation,
                                const std::vector<std::pair<int, int>>& probes, int recall_step) {
  const sss::sim::SubframeTruth truth(mission);
  const std::vector<sss::core::Pose> b_sonar = truth.sonarPoses(b);
  MatchEvaluation e;
  e.matches = static_cast<long>(matches.size());
  for (const auto& m : matches) {
    const auto point = truth.seabedPoint(a, static_cast<int>(std::lround(m.row_a)), m.col_a);
    if (!point) continue;
    const auto pixel = truth.pixelOf(b, *point, b_sonar);
    if (!pixel) continue;
    const double row_error = pixel->x() - m.row_b;
    const double error = std::hypot(row_error, (pixel->y() - m.col_b) / decimation);
    ++e.evaluated;
    e.error_sum_px += error;
    const double along_error_m = row_error * pingSpacingM(mission, b, pixel->x());
    const double truth_ground_m = b.geometry.signedGroundRangeM(pixel->y());
    const double match_ground_m = b.geometry.signedGroundRangeM(m.col_b);
    e.error_sum_m += std::hypot(along_error_m, truth_ground_m - match_ground_m);
    e.along_error_sum_m += along_error_m;
    e.outward_error_sum_m += std::abs(truth_ground_m) - std::abs(match_ground_m);
    if (error <= 2.0) ++e.within_2px;
  }
  long sampled = 0;
  for (const auto& [r, c] : probes) {
    const auto point = truth.seabedPoint(a, r, c);
    if (!point) continue;
    const auto pixel = truth.pixelOf(b, *point, b_sonar);
    if (!pixel) continue;
    const int br = static_cast<int>(std::lround(pixel->x())), bc = static_cast<int>(std::lround(pixel->y()));
    if (br < kHalfPatchPx || bc < kHalfPatchPx * decimation || br >= b.rows() - kHalfPatchPx ||
        bc >= b.cols() - kHalfPatchPx * decimation)
      continue;
    if (b.mask[static_cast<size_t>(br) * b.cols() + bc] != 0) continue;
    ++sampled;
  }
  e.probes = static_cast<long>(probes.size());
  e.matchable = sampled * recall_step * recall_step;
  return e;
}

MatchEvaluation evaluateMatches(const sss::sim::SimulatedSurvey& survey, const sss::core::Subframe& a,
                                const sss::core::Subframe& b,
                                const std::vector<sss::matcher::Correspondence>& matches, int stride, int decimation,
                                int recall_step) {
  return evaluateMatches(*survey.mission, a, b, matches, decimation,
                         recallProbes(a.rows(), a.cols(), a.mask, stride, decimation, recall_step), recall_step);
}

// ---- matches.csv -------------------------------------------------------------------------------

namespace {

const char* kExpectedHeader =
    "kind,subframe_a,subframe_b,round,row_a,col_a,row_b,col_b,utime_a_us,utime_b_us,side_a,side_b,ground_a_m,"
    "ground_b_m,altitude_a_m,altitude_b_m,zncc,heading_a_rad,heading_b_rad,matched,valid_columns (sss-process "
    "--write-matches)";

struct FileParameters {
  std::map<std::string, std::string> values;
  bool found = false;
};

// The "# parameters: key=value ..." comment line.
sss::core::Status readParameters(const std::string& path, FileParameters& parameters) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return sss::core::Status::error(path + ": cannot open; check the path");
  }
  const std::string prefix = "# parameters:";
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(prefix, 0) != 0) continue;
    std::istringstream tokens(line.substr(prefix.size()));
    for (std::string token; tokens >> token;) {
      const size_t equals = token.find('=');
      if (equals != std::string::npos) parameters.values[token.substr(0, equals)] = token.substr(equals + 1);
    }
    parameters.found = true;
    return sss::core::Status::success();
  }
  return sss::core::Status::success();
}

bool numbersOf(const std::string& text, size_t count, std::vector<double>& values) {
  values.clear();
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, ';')) {
    double value = 0.0;
    if (!parseFiniteDouble(item, value)) return false;
    values.push_back(value);
  }
  return values.size() == count;
}

struct PingRow {
  int64_t utime_us = 0;
  double altitude_m = 0.0;
  std::vector<std::pair<int, int>> valid_runs;
  int line = 0;
  bool present = false;
};

struct PairRows {
  int64_t a = 0, b = 0;
  int round = 0;
  double heading_a_rad = 0.0, heading_b_rad = 0.0;
  std::vector<sss::matcher::Correspondence> matches;
  std::vector<std::pair<int, int>> probes;
};

}  // namespace

Status evaluateMatchFile(const std::string& matches_path, const std::string& mission_dir,
                         MatchFileEvaluation& result) {
  result = MatchFileEvaluation{};
  result.path = matches_path;
  result.mission_dir = mission_dir;
  FileParameters parameters;
  if (const Status read = readParameters(matches_path, parameters); !read) return read;

  // Rows, streamed (a survey's file holds millions of matches).
  std::map<int64_t, std::vector<PingRow>> pings;
  std::map<std::tuple<int64_t, int64_t, int>, size_t> pair_index;
  std::vector<PairRows> pairs;
  const std::vector<std::string> required = {"kind", "subframe_a", "subframe_b", "round", "row_a", "col_a", "row_b",
                                             "col_b", "utime_a_us", "altitude_a_m", "zncc", "heading_a_rad",
                                             "heading_b_rad", "valid_columns"};
  CsvTable table;
  const auto onRow = [&](const CsvTable& t, CsvRow& row) -> Status {
    std::string bad_column;  // the first field that did not parse, with what it should be
    const auto number = [&](const char* name, double& value) {
      if (parseFiniteDouble(t.field(row, name), value)) return true;
      bad_column = "column " + std::string(name) + " is not a number: '" + t.field(row, name) + "'";
      return false;
    };
    const auto integer = [&](const char* name, int64_t& value) {
      if (parseInteger64(t.field(row, name), value)) return true;
      bad_column = "column " + std::string(name) + " is not an integer: '" + t.field(row, name) + "'";
      return false;
    };
    const auto bad = [&] { return Status::error(t.where(row) + bad_column); };
    const std::string& kind = t.field(row, "kind");
    int64_t id_a = 0, id_b = 0, round = 0, utime = 0;
    double row_a = 0.0, col_a = 0.0;
    if (!integer("subframe_a", id_a) || !number("row_a", row_a)) return bad();
    if (kind == "ping") {
      PingRow ping;
      ping.line = row.line;
      ping.present = true;
      if (!integer("utime_a_us", ping.utime_us) || !number("altitude_a_m", ping.altitude_m)) return bad();
      std::istringstream runs(t.field(row, "valid_columns"));
      for (std::string run; std::getline(runs, run, ';');) {
        const size_t dash = run.find('-');
        int64_t first = 0, last = 0;
        if (dash == std::string::npos || !parseInteger64(run.substr(0, dash), first) ||
            !parseInteger64(run.substr(dash + 1), last) || first > last) {
          return Status::error(t.where(row) + "valid_columns expects runs FIRST-LAST;..., got '" +
                               t.field(row, "valid_columns") + "'");
        }
        ping.valid_runs.emplace_back(static_cast<int>(first), static_cast<int>(last));
      }
      if (row_a < 0 || row_a > 100000 || row_a != std::floor(row_a)) {
        return Status::error(t.where(row) + "row_a of a ping row must be a row number, got '" + t.field(row, "row_a") +
                             "'");
      }
      std::vector<PingRow>& rows = pings[id_a];
      const size_t r = static_cast<size_t>(row_a);
      if (rows.size() <= r) rows.resize(r + 1);
      if (rows[r].present) {
        return Status::error(t.where(row) + "subframe " + std::to_string(id_a) + " row " + std::to_string(r) +
                             " is listed twice");
      }
      rows[r] = std::move(ping);
      return Status::success();
    }
    if (kind != "match" && kind != "probe") {
      return Status::error(t.where(row) + "kind '" + kind + "' is not ping, match or probe");
    }
    double heading_a = 0.0, heading_b = 0.0;
    if (!integer("subframe_b", id_b) || !integer("round", round) || !number("col_a", col_a) ||
        !integer("utime_a_us", utime) || !number("heading_a_rad", heading_a) || !number("heading_b_rad", heading_b))
      return bad();
    const auto key = std::make_tuple(id_a, id_b, static_cast<int>(round));
    auto [it, inserted] = pair_index.emplace(key, pairs.size());
    if (inserted) pairs.push_back({id_a, id_b, static_cast<int>(round), heading_a, heading_b, {}, {}});
    PairRows& pair = pairs[it->second];
    if (kind == "probe") {
      pair.probes.emplace_back(static_cast<int>(std::lround(row_a)), static_cast<int>(std::lround(col_a)));
      return Status::success();
    }
    double row_b = 0.0, col_b = 0.0, zncc = 0.0;
    if (!number("row_b", row_b) || !number("col_b", col_b) || !number("zncc", zncc)) return bad();
    sss::matcher::Correspondence m;
    m.row_a = static_cast<float>(row_a);
    m.col_a = static_cast<float>(col_a);
    m.row_b = static_cast<float>(row_b);
    m.col_b = static_cast<float>(col_b);
    m.zncc = static_cast<float>(zncc);
    pair.matches.push_back(m);
    return Status::success();
  };
  if (const Status read = forEachCsvRow(matches_path, required, kExpectedHeader, table, onRow); !read) return read;
  if (pairs.empty()) return Status::success();  // the matcher tried no pair: nothing to evaluate

  // Parameters of the matching image.
  if (!parameters.found) {
    return Status::error(matches_path + ": no '# parameters:' line; was it written by sss-process --write-matches?");
  }
  std::string missing_parameter;
  const auto parameter = [&](const std::string& name, double& value) {
    const auto it = parameters.values.find(name);
    if (it != parameters.values.end() && parseFiniteDouble(it->second, value)) return true;
    missing_parameter = name;
    return false;
  };
  double bins = 0, bin_size = 0, first_bin = 0, decimation = 0, stride = 0, probe_step = 0;
  if (!parameter("bins_per_side", bins) || !parameter("bin_size_m", bin_size) ||
      !parameter("first_bin_range_m", first_bin) || !parameter("decimation", decimation) ||
      !parameter("stride", stride) || !parameter("probe_step", probe_step))
    return Status::error(matches_path + ": the parameters line has no number " + missing_parameter);
  std::vector<double> position, orientation;
  if (!numbersOf(parameters.values["sonar_position_body_m"], 3, position) ||
      !numbersOf(parameters.values["sonar_orientation_body_wxyz"], 4, orientation)) {
    return Status::error(matches_path + ": the parameters line needs sonar_position_body_m=x;y;z and "
                                        "sonar_orientation_body_wxyz=w;x;y;z");
  }
  if (bins < 1 || bins > 1e6 || !(bin_size > 0) || decimation < 1 || stride < 1 || probe_step < 1) {
    return Status::error(matches_path +
                         ": parameters out of range (bins_per_side, bin_size_m, decimation, stride, probe_step)");
  }
  sss::core::SubframeGeometry geometry;
  geometry.bins_per_side = static_cast<int>(bins);
  geometry.bin_size_m = bin_size;
  geometry.first_bin_range_m = first_bin;
  geometry.T_body_sonar = sss::core::Pose(
      Eigen::Quaterniond(orientation[0], orientation[1], orientation[2], orientation[3]).normalized(),
      Eigen::Vector3d(position[0], position[1], position[2]));
  result.decimation = static_cast<int>(decimation);
  result.stride = static_cast<int>(stride);
  result.probe_step = static_cast<int>(probe_step);
  result.matching_pixel_m = bin_size * decimation;

  // The mission's truth.
  const std::string mission_yaml = mission_dir + "/mission.yaml";
  if (!std::ifstream(mission_yaml)) {
    return Status::error(mission_yaml +
                         ": cannot open; --mission expects the sss-sim output folder the matches come from");
  }
  sss::core::Config config = sss::core::Config::fromFile(mission_yaml);
  if (config.ok() && !config.root().has("sim")) {
    return Status::error(mission_yaml + ": no `sim` section; --mission expects an sss-sim output folder");
  }
  sss::sim::SimOptions sim;
  if (config.ok()) sss::sim::readSimOptions(config.section("sim"), sim);
  if (!config.ok()) {
    std::string report_text = config.problemReport();
    while (!report_text.empty() && report_text.back() == '\n') report_text.pop_back();
    return Status::error(mission_yaml + ": " + report_text);
  }
  const std::vector<std::string> problems = sss::sim::validateSimOptions(sim);
  if (!problems.empty()) {
    return Status::error(mission_yaml + ": " + problems.front());
  }
  const sss::sim::Mission mission(sim);

  // Subframes as the truth needs them: mission ping of every row, altitudes, geometry, mask.
  std::map<int64_t, sss::core::Subframe> subframes;
  const double rate_hz = sim.sonar.ping_rate_hz;
  for (const auto& [id, rows] : pings) {
    sss::core::Subframe& s = subframes[id];
    s.id = id;
    s.geometry = geometry;
    s.mask.assign(rows.size() * static_cast<size_t>(geometry.columns()), sss::core::kMaskNadir);
    for (size_t r = 0; r < rows.size(); ++r) {
      if (!rows[r].present) {
        return Status::error(matches_path + ": subframe " + std::to_string(id) + " has no ping row " +
                             std::to_string(r));
      }
      const double t_s = 1e-6 * static_cast<double>(rows[r].utime_us - sim.start_utime_us);
      const long long ping = std::llround(t_s * rate_hz);
      if (ping < 0 || ping >= static_cast<long long>(mission.pingCount()) ||
          std::llabs(mission.pingUtimeUs(static_cast<size_t>(ping)) - rows[r].utime_us) > 1000) {
        return Status::error(matches_path + ":" + std::to_string(rows[r].line) + ": utime " +
                             std::to_string(rows[r].utime_us) + " is not a ping time of the mission in " + mission_dir +
                             "; is it the right mission?");
      }
      sss::core::SubframePing p;
      p.utime_us = rows[r].utime_us;
      p.ping_number = ping;
      p.altitude_m = rows[r].altitude_m;
      s.pings.push_back(p);
      for (const auto& [first, last] : rows[r].valid_runs) {
        if (first < 0 || last >= geometry.columns()) {
          return Status::error(matches_path + ":" + std::to_string(rows[r].line) + ": valid columns " +
                               std::to_string(first) + "-" + std::to_string(last) + " outside the " +
                               std::to_string(geometry.columns()) + " columns");
        }
        std::fill(s.mask.begin() + static_cast<long>(r * geometry.columns() + first),
                  s.mask.begin() + static_cast<long>(r * geometry.columns() + last + 1), sss::core::kMaskValid);
      }
    }
  }
  result.subframes = subframes.size();

  for (const PairRows& pair : pairs) {
    const auto a = subframes.find(pair.a), b = subframes.find(pair.b);
    if (a == subframes.end() || b == subframes.end() || a->second.rows() < 2 || b->second.rows() < 2) {
      return Status::error(matches_path + ": pair " + std::to_string(pair.a) + "-" + std::to_string(pair.b) +
                           " has matches but no ping rows for its subframes");
    }
    PairMatchReport report;
    report.subframe_a = pair.a;
    report.subframe_b = pair.b;
    report.round = pair.round;
    report.heading_a_rad = pair.heading_a_rad;
    report.heading_b_rad = pair.heading_b_rad;
    report.type = classifyPair(pair.heading_a_rad, pair.heading_b_rad);
    report.evaluation =
        evaluateMatches(mission, a->second, b->second, pair.matches, result.decimation, pair.probes, result.probe_step);
    const int type = static_cast<int>(report.type);
    ++result.pairs_by_type[type];
    result.by_type[type] += report.evaluation;
    result.overall += report.evaluation;
    result.pairs.push_back(std::move(report));
  }
  return Status::success();
}


}  // namespace sss::eval
