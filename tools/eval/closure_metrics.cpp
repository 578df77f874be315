// Loop-closure accuracy against ground truth. See closure_metrics.hpp.
#include "tools/eval/closure_metrics.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include "tools/eval/csv_fields.hpp"

namespace sss::eval {

using sss::core::Status;
namespace {

SignedErrorStatistics signedStatistics(const std::vector<double>& values) {
  SignedErrorStatistics stats;
  std::vector<double> magnitudes;
  double sum = 0.0;
  for (double v : values) {
    magnitudes.push_back(std::abs(v));
    sum += v;
  }
  stats.abs = errorStatistics(magnitudes);
  if (!values.empty()) stats.bias = sum / static_cast<double>(values.size());
  return stats;
}

}  // namespace

sss::core::Status readClosureCsv(const std::string& path, std::vector<ClosureRecord>& closures) {
  const std::vector<const char*> kIntegers = {"subframe_id_a", "subframe_id_b", "utime_a_us", "utime_b_us"};
  const std::vector<const char*> kNumbers = {"dx_m", "dy_m", "dz_m", "dheading_rad"};
  const std::vector<const char*> kCovariance = {"cov_xx_m2", "cov_xy_m2", "cov_yy_m2"};
  std::vector<std::string> required(kIntegers.begin(), kIntegers.end());
  required.insert(required.end(), kNumbers.begin(), kNumbers.end());
  CsvTable table;
  if (const Status read = readCsvTable(
          path, required,
          "the loop_closures.csv of sss-process: subframe_id_a,subframe_id_b,utime_a_us,utime_b_us,round,"
          "status,rejection,dx_m,dy_m,dz_m,droll_rad,dpitch_rad,dheading_rad,...",
          table);
      !read) {
    return read;
  }
  const bool has_covariance = table.has("cov_xx_m2") && table.has("cov_xy_m2") && table.has("cov_yy_m2");
  closures.clear();
  for (const CsvRow& row : table.rows) {
    ClosureRecord record;
    record.line = row.line;
    int64_t integers[4];
    double numbers[4];
    if (const Status parsed = parseIntegerColumns(table, row, kIntegers, integers); !parsed) return parsed;
    if (const Status parsed = parseNumberColumns(table, row, kNumbers, numbers); !parsed) return parsed;
    record.subframe_id_a = integers[0];
    record.subframe_id_b = integers[1];
    record.utime_a_us = integers[2];
    record.utime_b_us = integers[3];
    record.translation_m = Eigen::Vector3d(numbers[0], numbers[1], numbers[2]);
    record.heading_rad = numbers[3];
    if (table.has("round")) {
      int64_t round = 0;
      if (const Status parsed = parseIntegerColumns(table, row, {"round"}, &round); !parsed) return parsed;
      record.round = static_cast<int>(round);
    }
    record.status = table.has("status") ? table.field(row, "status") : "unknown";
    if (record.status.empty()) record.status = "unknown";
    if (table.has("rejection")) record.rejection = table.field(row, "rejection");
    if (has_covariance) {
      double c[3];
      if (const Status parsed = parseNumberColumns(table, row, kCovariance, c); !parsed) return parsed;
      record.horizontal_covariance_m2 << c[0], c[1], c[1], c[2];
      record.has_covariance = true;
    }
    closures.push_back(std::move(record));
  }
  return Status::success();
}

RelativePoseXyzHeading relativePose(const sss::core::Pose& T_world_a, const sss::core::Pose& T_world_b) {
  const sss::core::Pose T_a_b = T_world_a.inverse() * T_world_b;
  // Heading as the closure file writes it: the Euler heading of T_a_b's rotation.
  return {T_a_b.translation, sss::core::eulerFromQuaternion(T_a_b.rotation).heading_rad};
}

RelativePoseError relativePoseError(const RelativePoseXyzHeading& estimate, const RelativePoseXyzHeading& truth) {
  const Eigen::Vector3d d = estimate.translation_m - truth.translation_m;
  return {d.x(), d.y(), d.z(), sss::core::wrapAngle(estimate.heading_rad - truth.heading_rad)};
}

RelativePoseErrorStatistics relativePoseErrorStatistics(const std::vector<RelativePoseError>& errors) {
  std::vector<double> along, lateral, depth, heading_deg, horizontal;
  for (const RelativePoseError& e : errors) {
    along.push_back(e.along_m);
    lateral.push_back(e.lateral_m);
    depth.push_back(e.depth_m);
    heading_deg.push_back(e.heading_rad * 180.0 / M_PI);
    horizontal.push_back(std::hypot(e.along_m, e.lateral_m));
  }
  RelativePoseErrorStatistics stats;
  stats.along_m = signedStatistics(along);
  stats.lateral_m = signedStatistics(lateral);
  stats.depth_m = signedStatistics(depth);
  stats.heading_deg = signedStatistics(heading_deg);
  stats.horizontal_m = errorStatistics(horizontal);
  return stats;
}

ClosureEvaluation evaluateClosures(const std::vector<ClosureRecord>& closures, const Trajectory& truth,
                                   const Trajectory* dr, double max_gap_s) {
  ClosureEvaluation result;
  for (const ClosureRecord& record : closures) {
    ClosureError entry;
    entry.closure = record;
    const std::optional<sss::core::Pose> truth_a = poseAtTime(truth, record.utime_a_us, max_gap_s);
    const std::optional<sss::core::Pose> truth_b = poseAtTime(truth, record.utime_b_us, max_gap_s);
    if (truth_a && truth_b) {
      entry.has_truth = true;
      entry.truth = relativePose(*truth_a, *truth_b);
      entry.closure_error = relativePoseError({record.translation_m, record.heading_rad}, entry.truth);
      if (record.has_covariance) {
        const Eigen::Vector2d e(entry.closure_error.along_m, entry.closure_error.lateral_m);
        const Eigen::LDLT<Eigen::Matrix2d> ldlt(record.horizontal_covariance_m2);
        if (ldlt.info() == Eigen::Success && ldlt.isPositive() && record.horizontal_covariance_m2.determinant() > 0.0)
          entry.horizontal_nees = e.dot(ldlt.solve(e));
      }
      if (dr) {
        const std::optional<sss::core::Pose> dr_a = poseAtTime(*dr, record.utime_a_us, max_gap_s);
        const std::optional<sss::core::Pose> dr_b = poseAtTime(*dr, record.utime_b_us, max_gap_s);
        if (dr_a && dr_b) {
          entry.has_dr = true;
          entry.dr_error = relativePoseError(relativePose(*dr_a, *dr_b), entry.truth);
        } else {
          ++result.without_dr;
        }
      }
    } else {
      ++result.without_truth;
    }
    result.closures.push_back(entry);
  }

  // Groups in a fixed order of the statuses sss-process writes, then any other status as found.
  std::vector<std::string> statuses = {"accepted", "rejected", "superseded", "pending"};
  for (const ClosureError& e : result.closures) {
    if (std::find(statuses.begin(), statuses.end(), e.closure.status) == statuses.end()) {
      statuses.push_back(e.closure.status);
    }
  }
  for (const std::string& status : statuses) {
    std::vector<RelativePoseError> closure_errors, dr_errors;
    double nees_sum = 0.0;
    size_t nees_count = 0;
    for (const ClosureError& e : result.closures) {
      if (e.closure.status != status || !e.has_truth) continue;
      closure_errors.push_back(e.closure_error);
      if (e.has_dr) dr_errors.push_back(e.dr_error);
      if (std::isfinite(e.horizontal_nees)) {
        nees_sum += e.horizontal_nees;
        ++nees_count;
      }
    }
    if (closure_errors.empty()) continue;
    ClosureGroup group;
    group.status = status;
    group.count = closure_errors.size();
    group.closure = relativePoseErrorStatistics(closure_errors);
    group.dr = relativePoseErrorStatistics(dr_errors);
    group.nees_count = nees_count;
    if (nees_count) group.mean_horizontal_nees = nees_sum / static_cast<double>(nees_count);
    result.groups.push_back(group);
  }
  return result;
}

}  // namespace sss::eval
