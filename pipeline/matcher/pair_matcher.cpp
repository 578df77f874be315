// One subframe pair from images to relative pose.
#include "pipeline/matcher/pair_matcher.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <sstream>

#include "pipeline/core/georeference.hpp"

namespace sss::matcher {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

}  // namespace

void readPairMatcherOptions(sss::core::ConfigSection& section, PairMatcherOptions& options) {
  using sss::core::atLeast;
  using sss::core::inRange;
  sss::core::ConfigSection dense = section.section("dense");
  readDenseMatcherOptions(dense, options.dense);
  dense.rejectUnknownKeys();
  sss::core::ConfigSection pose = section.section("relative_pose");
  readRelativePoseOptions(pose, options.pose);
  pose.rejectUnknownKeys();
  section.optional("dr_horizontal_sigma_fixed_m", options.dr_horizontal_sigma_fixed_m, {inRange(0.01, 1000.0)});
  section.optional("dr_horizontal_sigma_per_m", options.dr_horizontal_sigma_per_m, {inRange(0.0, 1.0)});
  section.optional("dr_depth_sigma_m", options.dr_depth_sigma_m, {inRange(0.001, 100.0)});
  section.optional("dr_heading_sigma_fixed_rad", options.dr_heading_sigma_fixed_rad, {inRange(1e-5, 1.0)});
  section.optional("dr_heading_sigma_per_m", options.dr_heading_sigma_per_m, {inRange(0.0, 0.01)});
  section.optional("dr_roll_pitch_sigma_rad", options.dr_roll_pitch_sigma_rad, {inRange(1e-5, 1.0)});
  section.optional("min_matches", options.min_matches, {atLeast(0)});
  section.optional("matching_bin_size_m", options.matching_bin_size_m, {inRange(0.0, 10.0)});
  section.optional("smoothing_sigma_px", options.smoothing_sigma_px, {inRange(0.0, 20.0)});
  section.optional("rectify_sigma_px", options.rectify_sigma_px, {inRange(0.0, 100.0)});
  section.optional("covariance_scale", options.covariance_scale, {inRange(1e-3, 1e6)});
  section.optional("min_translation_sigma_m", options.min_translation_sigma_m, {inRange(0.0, 100.0)});
  section.optional("min_rotation_sigma_rad", options.min_rotation_sigma_rad, {inRange(0.0, 1.0)});
  section.optional("test_opposed_relief", options.test_opposed_relief);
  section.optional("opposed_relief_chi2", options.opposed_relief_chi2, {inRange(0.0, 1e6)});
  section.optional("test_pass_agreement", options.test_pass_agreement);
  section.optional("pass_agreement_chi2", options.pass_agreement_chi2, {inRange(0.0, 1e6)});
}

std::vector<std::string> validatePairMatcherOptions(const PairMatcherOptions& o) {
  std::vector<std::string> problems = validateDenseMatcherOptions(o.dense);
  for (const std::string& p : validateRelativePoseOptions(o.pose)) problems.push_back(p);
  if (!(o.dr_horizontal_sigma_fixed_m > 0.0)) problems.push_back("dr_horizontal_sigma_fixed_m must be > 0");
  if (!(o.dr_horizontal_sigma_per_m >= 0.0)) problems.push_back("dr_horizontal_sigma_per_m must be >= 0");
  if (!(o.dr_depth_sigma_m > 0.0)) problems.push_back("dr_depth_sigma_m must be > 0");
  if (!(o.dr_heading_sigma_fixed_rad > 0.0)) problems.push_back("dr_heading_sigma_fixed_rad must be > 0");
  if (!(o.dr_heading_sigma_per_m >= 0.0)) problems.push_back("dr_heading_sigma_per_m must be >= 0");
  if (!(o.dr_roll_pitch_sigma_rad > 0.0)) problems.push_back("dr_roll_pitch_sigma_rad must be > 0");
  if (o.min_matches < 0) problems.push_back("min_matches must be >= 0");
  if (!(o.matching_bin_size_m >= 0.0)) problems.push_back("matching_bin_size_m must be >= 0");
  if (!(o.smoothing_sigma_px >= 0.0)) problems.push_back("smoothing_sigma_px must be >= 0");
  if (!(o.rectify_sigma_px >= 0.0)) problems.push_back("rectify_sigma_px must be >= 0");
  return problems;
}

sss::core::Matrix6d drRelativeCovariance(double distance_m, const PairMatcherOptions& o) {
  const double d = std::abs(distance_m);
  const double horizontal = std::hypot(o.dr_horizontal_sigma_fixed_m, o.dr_horizontal_sigma_per_m * d);
  const double heading = o.dr_heading_sigma_fixed_rad + o.dr_heading_sigma_per_m * d;
  sss::core::Matrix6d covariance = sss::core::Matrix6d::Zero();
  covariance.diagonal() << horizontal * horizontal, horizontal * horizontal, o.dr_depth_sigma_m * o.dr_depth_sigma_m,
      o.dr_roll_pitch_sigma_rad * o.dr_roll_pitch_sigma_rad, o.dr_roll_pitch_sigma_rad * o.dr_roll_pitch_sigma_rad,
      heading * heading;
  return covariance;
}

int columnDecimation(const sss::core::SubframeGeometry& geometry, const PairMatcherOptions& options) {
  if (!(geometry.bin_size_m > 0.0)) return 1;
  const int decimation = static_cast<int>(std::lround(options.matching_bin_size_m / geometry.bin_size_m));
  return std::clamp(decimation, 1, std::max(1, geometry.bins_per_side / 16));
}

double fullResolutionColumn(const sss::core::SubframeGeometry& geometry, int decimation, double k) {
  // Port matching column k < per covers bins [B - per*f + k*f, ... + f); starboard k >= per covers
  // [B + (k - per)*f, ... + f); the outermost B - per*f bins of each side are dropped.
  const int per = geometry.bins_per_side / decimation;
  const double centre = 0.5 * (decimation - 1);
  if (k < per - 0.5) return geometry.bins_per_side - per * decimation + k * decimation + centre;
  return geometry.bins_per_side + (k - per) * decimation + centre;
}

double hausmanStatistic(const sss::core::Vector6d& d, const sss::core::Matrix6d& c_subset,
                        const sss::core::Matrix6d& c_all) {
  constexpr int kPlanar[3] = {0, 1, 5};  // horizontal position and heading of [dt, dr]
  Eigen::Vector3d dp;
  Eigen::Matrix3d cs, ca;
  for (int i = 0; i < 3; ++i) {
    dp(i) = d(kPlanar[i]);
    for (int j = 0; j < 3; ++j) {
      cs(i, j) = c_subset(kPlanar[i], kPlanar[j]);
      ca(i, j) = c_all(kPlanar[i], kPlanar[j]);
    }
  }
  // Whitened by C_subset first, so that the floor is the same in every unit (m, rad).
  const Eigen::LLT<Eigen::Matrix3d> chol(cs);
  if (chol.info() != Eigen::Success) return -1.0;
  const Eigen::Matrix3d l_inv = chol.matrixL().solve(Eigen::Matrix3d::Identity());
  const Eigen::Matrix3d difference = Eigen::Matrix3d::Identity() - l_inv * ca * l_inv.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(0.5 * (difference + difference.transpose()));
  const Eigen::Vector3d z = eigen.eigenvectors().transpose() * (l_inv * dp);
  double statistic = 0.0;
  for (int i = 0; i < 3; ++i) statistic += z(i) * z(i) / std::max(eigen.eigenvalues()(i), 0.1);
  return statistic;
}

namespace {

// Gaussian of the valid pixels only (normalised convolution: smoothed intensity x mask over the
// smoothed mask).
cv::Mat1f maskedGaussian(const GeoImage& image, double sigma_px) {
  cv::Mat1f weight, weighted;
  image.valid.convertTo(weight, CV_32F, 1.0 / 255.0);
  weighted = image.intensity.mul(weight);
  cv::GaussianBlur(weighted, weighted, cv::Size(0, 0), sigma_px, sigma_px, cv::BORDER_REPLICATE);
  cv::GaussianBlur(weight, weight, cv::Size(0, 0), sigma_px, sigma_px, cv::BORDER_REPLICATE);
  return weighted / cv::max(weight, 1e-6f);
}

void addTimings(MatchTimings& total, const MatchTimings& pass) {
  total.kd_tree_s += pass.kd_tree_s;
  total.initialisation_s += pass.initialisation_s;
  total.patch_match_s += pass.patch_match_s;
  total.consistency_s += pass.consistency_s;
  total.total_s += pass.total_s;
  total.overlapping_pixels = std::max(total.overlapping_pixels, pass.overlapping_pixels);
  total.mirrored_relief_rejected += pass.mirrored_relief_rejected;
  total.shadowed_relief_rejected += pass.shadowed_relief_rejected;
  total.inverted_relief_rejected += pass.inverted_relief_rejected;
  total.ambiguous_rejected += pass.ambiguous_rejected;
  total.shadowed_relief_marked += pass.shadowed_relief_marked;
}

// The covariance a closure publishes: the matches' model scaled (covariance_scale), the relief
// term as it is, floored.
void publishedCovariance(RelativePoseResult& pose, const PairMatcherOptions& options) {
  sss::core::Matrix6d& covariance = pose.covariance;
  // The scale calibrates the matches' model; the relief term is already a physical size.
  covariance = options.covariance_scale * (covariance - pose.relief_covariance) + pose.relief_covariance;
  for (int i = 0; i < 6; ++i) {
    const double floor = i < 3 ? options.min_translation_sigma_m : options.min_rotation_sigma_rad;
    covariance(i, i) = std::max(covariance(i, i), floor * floor);
  }
}

// test_opposed_relief (see PairMatcherOptions): the pose again without the matches over opposed
// relief; published instead when the two differ beyond what the fewer matches explain.
void testOpposedRelief(const RelativePoseInput& input, const PairMatcherOptions& options, PairMatch& result) {
  for (int i : result.pose.all_inlier_indices) result.opposed_relief_inliers += input.matches[i].opposed_relief;
  if (result.opposed_relief_inliers == 0) return;
  RelativePoseInput without = input;
  without.matches.clear();
  std::vector<int> index_in_all;
  for (size_t i = 0; i < input.matches.size(); ++i) {
    if (input.matches[i].opposed_relief) continue;
    without.matches.push_back(input.matches[i]);
    index_in_all.push_back(static_cast<int>(i));
  }
  if (static_cast<int>(without.matches.size()) < options.min_matches) return;
  RelativePoseResult pose = estimateRelativePose(without, options.pose);
  if (!pose.accepted) return;
  publishedCovariance(pose, options);
  const sss::core::Vector6d d = sss::core::boxMinus(pose.T_a_b, result.pose.T_a_b);
  result.opposed_relief_statistic = hausmanStatistic(d, pose.covariance, result.pose.covariance);
  if (!(result.opposed_relief_statistic > options.opposed_relief_chi2)) return;
  // The indices of the pose's inliers are into the matches it was given: map them back.
  for (int& i : pose.inlier_indices) i = index_in_all[i];
  for (int& i : pose.all_inlier_indices) i = index_in_all[i];
  pose.seconds += result.pose.seconds;
  result.pose = std::move(pose);
  result.opposed_relief_replaced = true;
}

// test_pass_agreement (see PairMatcherOptions): the pose from the raw-intensity matches alone and
// from the rectified-contrast matches alone; where they differ beyond both their spreads, the
// published covariance widens by their difference.
void testPassAgreement(const RelativePoseInput& input, const std::vector<Correspondence>& raw,
                       const std::vector<Correspondence>& rectified, const PairMatcherOptions& options,
                       PairMatch& result) {
  RelativePoseInput one = input;
  one.matches = raw;
  RelativePoseResult raw_pose = estimateRelativePose(one, options.pose);
  one.matches = rectified;
  RelativePoseResult rectified_pose = estimateRelativePose(one, options.pose);
  result.pose.seconds += raw_pose.seconds + rectified_pose.seconds;
  if (!raw_pose.accepted || !rectified_pose.accepted) return;
  publishedCovariance(raw_pose, options);
  publishedCovariance(rectified_pose, options);
  sss::core::Vector6d d = sss::core::boxMinus(rectified_pose.T_a_b, raw_pose.T_a_b);
  d(2) = d(3) = d(4) = 0.0;  // depth, roll and pitch: the pressure sensor and the INS, not the passes
  // Two estimates from (mostly) different pixels: d' (C_raw + C_rectified)^-1 d; hausmanStatistic
  // with a zero C_all is that.
  result.pass_agreement_statistic =
      hausmanStatistic(d, raw_pose.covariance + rectified_pose.covariance, sss::core::Matrix6d::Zero());
  result.pass_disagreement_m = d.head<2>().norm();
  if (!(result.pass_agreement_statistic > options.pass_agreement_chi2)) return;
  result.pose.covariance += d * d.transpose();
  result.pass_disagreement_widened = true;
}

}  // namespace

GeoImage rectifiedContrast(const GeoImage& image, double sigma_px) {
  GeoImage rectified = image;
  rectified.intensity = image.intensity.clone();
  const cv::Mat1f local_mean = maskedGaussian(image, sigma_px);
  for (int r = 0; r < image.intensity.rows; ++r) {
    for (int c = 0; c < image.intensity.cols; ++c) {
      if (image.valid(r, c)) rectified.intensity(r, c) = std::abs(image.intensity(r, c) - local_mean(r, c));
    }
  }
  return rectified;
}

std::vector<Correspondence> mergeMatches(const std::vector<Correspondence>& raw,
                                         const std::vector<Correspondence>& rectified) {
  std::map<std::pair<float, float>, Correspondence> by_pixel_a;  // the stride lattice: exact values
  for (const Correspondence& m : raw) by_pixel_a[{m.row_a, m.col_a}] = m;
  for (const Correspondence& m : rectified) {
    const auto [it, inserted] = by_pixel_a.try_emplace({m.row_a, m.col_a}, m);
    if (!inserted && std::hypot(it->second.row_b - m.row_b, it->second.col_b - m.col_b) > 1.0f) it->second = m;
  }
  std::vector<Correspondence> merged;
  merged.reserve(by_pixel_a.size());
  for (const auto& entry : by_pixel_a) merged.push_back(entry.second);
  return merged;
}

GeoImage toGeoImage(const sss::core::Subframe& subframe, const std::vector<sss::core::Pose>& T_world_body,
                    int decimation, double smoothing_sigma_px) {
  decimation = std::max(1, decimation);
  const int per_side = subframe.geometry.bins_per_side / decimation;
  const int rows = subframe.rows(), cols = 2 * per_side, full_cols = subframe.cols();
  GeoImage image;
  image.intensity.create(rows, cols);
  image.valid = cv::Mat1b::zeros(rows, cols);
  image.position_ne_m = cv::Mat2f(rows, cols, cv::Vec2f(0.0f, 0.0f));
  image.heading_rad.create(rows, 1);
  image.intensity.setTo(0.0f);
  if (static_cast<int>(T_world_body.size()) != rows ||
      subframe.image.size() != static_cast<size_t>(rows) * full_cols || subframe.mask.size() != subframe.image.size()) {
    return image;  // nothing valid: a malformed subframe never matches
  }
  for (int r = 0; r < rows; ++r) {
    image.heading_rad(r, 0) = static_cast<float>(sss::core::eulerFromQuaternion(T_world_body[r].rotation).heading_rad);
    const size_t offset = static_cast<size_t>(r) * full_cols;
    for (int k = 0; k < cols; ++k) {
      const double centre = fullResolutionColumn(subframe.geometry, decimation, k);
      const int first = static_cast<int>(std::lround(centre - 0.5 * (decimation - 1)));
      float sum = 0.0f;
      bool valid = true;
      for (int c = first; c < first + decimation; ++c) {
        sum += subframe.image[offset + c];
        valid = valid && subframe.mask[offset + c] == sss::core::kMaskValid;
      }
      image.intensity(r, k) = sum / static_cast<float>(decimation);
      const auto p =
          sss::core::georeferencePixel(subframe.geometry, T_world_body[r], subframe.pings[r].altitude_m, centre);
      if (!p) continue;
      image.position_ne_m(r, k) = cv::Vec2f(static_cast<float>(p->x()), static_cast<float>(p->y()));
      if (valid) image.valid(r, k) = 255;
    }
  }
  if (smoothing_sigma_px > 0.0) {
    // Normalised convolution: masked pixels (nadir, far range) do not bleed into valid ones.
    const cv::Mat1f smooth = maskedGaussian(image, smoothing_sigma_px);
    for (int r = 0; r < rows; ++r) {
      for (int k = 0; k < cols; ++k) {
        if (image.valid(r, k)) image.intensity(r, k) = smooth(r, k);
      }
    }
  }
  return image;
}

PairMatch matchPair(const sss::core::Subframe& a, const std::vector<sss::core::Pose>& poses_a,
                    const sss::core::Subframe& b, const std::vector<sss::core::Pose>& poses_b,
                    const DenseMatcher& dense, const PairMatcherOptions& options) {
  const auto start = Clock::now();
  PairMatch result;
  if (a.rows() == 0 || b.rows() == 0 || static_cast<int>(poses_a.size()) != a.rows() ||
      static_cast<int>(poses_b.size()) != b.rows()) {
    result.reason = "subframe without pings or with a pose count different from its rows";
    return result;
  }
  if (a.geometry.bins_per_side != b.geometry.bins_per_side || a.geometry.bin_size_m != b.geometry.bin_size_m ||
      a.geometry.first_bin_range_m != b.geometry.first_bin_range_m) {
    result.reason = "subframes with different ground-range axes (bins, bin size): not matched";
    return result;
  }
  result.decimation = columnDecimation(a.geometry, options);
  GeoImage image_a = toGeoImage(a, poses_a, result.decimation, options.smoothing_sigma_px);
  GeoImage image_b = toGeoImage(b, poses_b, result.decimation, options.smoothing_sigma_px);
  if (dense.options().reject_shadowed_relief || options.test_opposed_relief) {  // smoothed, both passes
    image_a.relief = findReliefFeatures(image_a);
    image_b.relief = findReliefFeatures(image_b);
  }
  result.georeference_s = secondsSince(start);
  result.matches = dense.match(image_a, image_b, &result.dense_timings);
  std::vector<Correspondence> raw_matches, rectified_matches;  // each pass alone, for test_pass_agreement
  if (options.rectify_sigma_px > 0.0) {
    MatchTimings rectified_timings;
    const std::vector<Correspondence> rectified =
        dense.match(rectifiedContrast(image_a, options.rectify_sigma_px),
                    rectifiedContrast(image_b, options.rectify_sigma_px), &rectified_timings);
    addTimings(result.dense_timings, rectified_timings);
    if (options.test_pass_agreement) {
      raw_matches = result.matches;
      rectified_matches = rectified;
    }
    result.matches = mergeMatches(result.matches, rectified);
    result.dense_timings.matches = static_cast<long>(result.matches.size());
  }
  for (std::vector<Correspondence>* list : {&result.matches, &raw_matches, &rectified_matches}) {
    for (Correspondence& m : *list) {
      m.col_a = static_cast<float>(fullResolutionColumn(a.geometry, result.decimation, m.col_a));
      m.col_b = static_cast<float>(fullResolutionColumn(b.geometry, result.decimation, m.col_b));
    }
  }
  double zncc_sum = 0.0;
  for (const Correspondence& m : result.matches) zncc_sum += m.zncc;
  if (!result.matches.empty()) result.mean_zncc = zncc_sum / static_cast<double>(result.matches.size());
  if (static_cast<int>(result.matches.size()) < options.min_matches) {
    std::ostringstream text;
    text << result.matches.size() << " dense matches, below min_matches " << options.min_matches
         << " (little overlap or texture)";
    result.reason = text.str();
    result.seconds = secondsSince(start);
    return result;
  }

  RelativePoseInput input;
  input.dr_poses_a = poses_a;
  input.dr_poses_b = poses_b;
  for (const auto& ping : a.pings) input.altitude_a_m.push_back(ping.altitude_m);
  for (const auto& ping : b.pings) input.altitude_b_m.push_back(ping.altitude_m);
  input.centre_a = a.centre_ping_index;
  input.centre_b = b.centre_ping_index;
  input.geometry = a.geometry;
  input.matches = result.matches;
  input.dr_covariance_ab =
      drRelativeCovariance(b.centre().distance_travelled_m - a.centre().distance_travelled_m, options);
  result.pose = estimateRelativePose(input, options.pose);
  if (result.pose.accepted) publishedCovariance(result.pose, options);
  if (result.pose.accepted && options.test_opposed_relief) testOpposedRelief(input, options, result);
  if (result.pose.accepted && options.test_pass_agreement && !rectified_matches.empty()) {
    testPassAgreement(input, raw_matches, rectified_matches, options, result);
  }
  result.accepted = result.pose.accepted;
  result.reason = result.pose.reason;
  result.seconds = secondsSince(start);
  return result;
}

}  // namespace sss::matcher
