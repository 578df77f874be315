// Relative pose of a subframe pair on hand-built geometry: two survey lines over a flat seabed,
// exact correspondences with pixel noise and outliers, DR error between the lines.
#include "pipeline/matcher/relative_pose.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <random>

namespace sss::matcher {
namespace {

using sss::core::Pose;

constexpr double kSeabedDepthM = 58.0;
constexpr double kAltitudeM = 18.0;
constexpr int kPings = 200;
constexpr double kPingSpacingM = 0.5;
constexpr int kBinsPerSide = 700;
constexpr double kBinSizeM = 0.1;
constexpr double kLineSpacingM = 60.0;
// Seabed relief about the flat seabed, i.i.d. per point. At 0.3 m the per-landmark depths (nuisance
// parameters, Neyman-Scott) bias the lateral estimate by ~0.2 m (see the report); 0.1 m is a flat
// seabed in the sense of the canonical transform.
constexpr double kReliefSigmaM = 0.1;

struct SyntheticPair {
  RelativePoseInput input;
  Pose T_a_b_true;
};

Pose linePose(double north_m, double east_m, double heading_rad) {
  return Pose(sss::core::quaternionFromEuler(0.0, 0.0, heading_rad),
              Eigen::Vector3d(north_m, east_m, kSeabedDepthM - kAltitudeM));
}

// Column of a ground range on a side (+1 starboard, -1 port): port is mirrored left of nadir.
double columnOf(double ground_range_m, int side) {
  const double bin = ground_range_m / kBinSizeM;
  return side > 0 ? kBinsPerSide + bin : kBinsPerSide - 1 - bin;
}

// Line A heads north at east 0; line B runs at east 60 m, heading north (parallel) or south.
// B's DR poses are its true poses moved rigidly by 3 m along-track, 2 m laterally and 0.005 rad
// of heading about its centre: the DR error between the lines that the estimator must remove.
// Seabed-model errors shared by neighbouring matches (relief the flat seabed does not hold, a
// shadow seen from the other side): every match whose seabed point falls in the same square patch
// of seabed gets the same extra ground-range error in B, drawn per patch.
struct PatchErrors {
  double sigma_m = 0.0;         // per-patch ground-range error of B's column, 1 sigma
  double patch_m = 20.0;
  double east_min_m = 20.0;     // the overlap strip the matches are drawn from (A's starboard)
  double east_max_m = 40.0;
  double strip_slope = 0.0;     // the seabed under the matches rises this much per metre north
  // Every matched pixel lies this much nearer each sonar (slant range) than the seabed point both
  // lines see: a raised feature's face turned towards each line.
  double relief_range_bias_m = 0.0;
};

SyntheticPair makePair(bool anti_parallel, std::uint64_t seed, int num_matches = 1000, double outlier_fraction = 0.2,
                       bool all_random = false, const PatchErrors& patch_errors = {}) {
  std::mt19937_64 rng(seed);
  std::mt19937_64 patch_rng(seed ^ 0x9e3779b97f4a7c15ULL);
  std::normal_distribution<double> patch_noise(0.0, 1.0);
  std::map<std::pair<int, int>, double> patch_error_m;
  std::normal_distribution<double> pixel_noise(0.0, 0.5);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> relief(0.0, kReliefSigmaM);
  SyntheticPair pair;
  RelativePoseInput& in = pair.input;
  const double b_heading = anti_parallel ? M_PI : 0.0;
  std::vector<Pose> true_b;
  for (int i = 0; i < kPings; ++i) {
    const double s = -50.0 + kPingSpacingM * i;
    in.dr_poses_a.push_back(linePose(s, 0.0, 0.0));
    true_b.push_back(linePose(anti_parallel ? -s : s, kLineSpacingM, b_heading));
    in.altitude_a_m.push_back(kAltitudeM);
    in.altitude_b_m.push_back(kAltitudeM);
  }
  in.centre_a = in.centre_b = kPings / 2;
  const Eigen::Vector3d centre_b = true_b[in.centre_b].translation;
  const Eigen::Quaterniond heading_error = sss::core::quaternionFromEuler(0.0, 0.0, 0.005);
  const Pose T_error(heading_error, centre_b + Eigen::Vector3d(3.0, 2.0, 0.0) - heading_error * centre_b);
  for (const Pose& p : true_b) in.dr_poses_b.push_back(T_error * p);
  pair.T_a_b_true = in.dr_poses_a[in.centre_a].inverse() * true_b[in.centre_b];

  in.geometry.T_body_sonar = Pose::identity();
  in.geometry.bin_size_m = kBinSizeM;
  in.geometry.first_bin_range_m = 0.0;
  in.geometry.bins_per_side = kBinsPerSide;
  sss::core::Matrix6d cov = sss::core::Matrix6d::Zero();
  cov.diagonal() << 16.0, 16.0, 0.25, 1e-4, 1e-4, 4e-4;  // 4 m horizontal, 0.5 m depth, 0.02 rad heading
  in.dr_covariance_ab = cov;

  // Seabed points in the overlap; each is seen by the ping whose fan plane (constant northing)
  // contains it. A sees it to starboard; B to port (parallel) or to starboard (anti-parallel).
  for (int k = 0; k < num_matches; ++k) {
    const double north = -40.0 + 80.0 * uniform(rng);
    const double east =
        patch_errors.east_min_m + (patch_errors.east_max_m - patch_errors.east_min_m) * uniform(rng);
    double shared_error_m = 0.0;
    if (patch_errors.sigma_m > 0.0) {
      const std::pair<int, int> patch{static_cast<int>(std::floor(north / patch_errors.patch_m)),
                                      static_cast<int>(std::floor(east / patch_errors.patch_m))};
      auto [it, inserted] = patch_error_m.try_emplace(patch, 0.0);
      if (inserted) it->second = patch_errors.sigma_m * patch_noise(patch_rng);
      shared_error_m = it->second;
    }
    // Seabed relief about the flat seabed, what the landmark depth prior allows for.
    const double height_m = kAltitudeM + relief(rng) - patch_errors.strip_slope * north;
    // The canonical image's column is the flat-seabed ground range of the true slant range.
    auto canonicalGroundRange = [&](double across_m) {
      const double slant_m = std::sqrt(across_m * across_m + height_m * height_m) - patch_errors.relief_range_bias_m;
      return std::sqrt(slant_m * slant_m - kAltitudeM * kAltitudeM);
    };
    Correspondence c;
    c.row_a = static_cast<float>((north + 50.0) / kPingSpacingM + pixel_noise(rng));
    c.col_a = static_cast<float>(columnOf(canonicalGroundRange(east), +1) + pixel_noise(rng));
    c.row_b = static_cast<float>((anti_parallel ? 50.0 - north : north + 50.0) / kPingSpacingM + pixel_noise(rng));
    c.col_b = static_cast<float>(
        columnOf(canonicalGroundRange(kLineSpacingM - east) + shared_error_m, anti_parallel ? +1 : -1) +
        pixel_noise(rng));
    if (all_random) {
      c.row_a = static_cast<float>((kPings - 1) * uniform(rng));
      c.row_b = static_cast<float>((kPings - 1) * uniform(rng));
      c.col_a = static_cast<float>((2 * kBinsPerSide - 1) * uniform(rng));
      c.col_b = static_cast<float>((2 * kBinsPerSide - 1) * uniform(rng));
    } else if (uniform(rng) < outlier_fraction) {
      c.col_b = static_cast<float>((2 * kBinsPerSide - 1) * uniform(rng));
    }
    c.zncc = 0.9f;
    in.matches.push_back(c);
  }
  return pair;
}

RelativePoseOptions testOptions() {
  RelativePoseOptions options;
  EXPECT_EQ(options.covariance_cluster_m, 0.0);  // Ceres' covariance unless asked
  options.range_sigma_m = 0.05;  // the simulated column noise: 0.5 bin of 0.1 m
  options.seabed_sigma_m = kReliefSigmaM;
  // The synthetic seabed has no raised features: the range-bias term (on by default) is tested on
  // its own (ReliefRangeBiasIsPredictedAndCoveredByItsCovarianceTerm).
  EXPECT_TRUE(options.range_bias_covariance);
  options.range_bias_covariance = false;
  // No wall-clock cap (the default): the full RANSAC budget (200 hypotheses) whatever the machine
  // speed, so the test checks the estimator, not the machine.
  EXPECT_EQ(options.time_limit_s, 0.0);
  return options;
}

// The covariance from the residuals: 20 m seabed patches as clusters.
RelativePoseOptions clusterRobustOptions() {
  RelativePoseOptions options = testOptions();
  options.covariance_cluster_m = 20.0;
  return options;
}

struct Errors {
  Eigen::Vector3d translation_m;  // estimate - truth, in A's centre body frame (x along, y lateral)
  double nees_translation = 0.0;
  double nees_full = 0.0;
};

Errors errorsOf(const SyntheticPair& pair, const RelativePoseResult& result) {
  Errors e;
  e.translation_m = result.T_a_b.translation - pair.T_a_b_true.translation;
  // The covariance lives in the tangent at the estimate: delta = boxMinus(truth, estimate).
  const sss::core::Vector6d delta = sss::core::boxMinus(pair.T_a_b_true, result.T_a_b);
  e.nees_translation = delta.head<3>().dot(result.covariance.topLeftCorner<3, 3>().ldlt().solve(delta.head<3>()));
  e.nees_full = delta.dot(result.covariance.ldlt().solve(delta));
  return e;
}

void expectRecoversDrError(bool anti_parallel) {
  const SyntheticPair pair = makePair(anti_parallel, 7);
  const RelativePoseResult result = estimateRelativePose(pair.input, testOptions());
  ASSERT_TRUE(result.accepted) << result.reason;
  const Errors e = errorsOf(pair, result);
  std::printf("[%s] inliers %d, error along %.3f m lateral %.3f m depth %.3f m, sigma along %.3f lateral %.3f, "
              "costs range %.2f plane %.2f, %.3f s (%d RANSAC iterations)\n",
              anti_parallel ? "anti-parallel" : "parallel", result.num_inliers, e.translation_m.x(),
              e.translation_m.y(), e.translation_m.z(), std::sqrt(result.covariance(0, 0)),
              std::sqrt(result.covariance(1, 1)), result.range_cost, result.plane_cost, result.seconds,
              result.ransac_iterations_run);
  // DR error was 3 m along and 2 m lateral; the issue asks for 0.3 m in both directions.
  EXPECT_LT(std::abs(e.translation_m.x()), 0.3);
  EXPECT_LT(std::abs(e.translation_m.y()), 0.3);
  // 80 % of 1000 matches are true; a few noisy ones fall outside 3 sigma.
  EXPECT_GT(result.num_inliers, 700);
  EXPECT_LT(result.num_inliers, 850);
  // Every inlier goes to the point cloud, not only the (sampled) refined ones, each with a
  // landmark on the seabed: A is level at kAltitudeM above it, and the relief is kReliefSigmaM.
  ASSERT_EQ(result.all_inlier_indices.size(), static_cast<size_t>(result.num_inliers));
  ASSERT_EQ(result.all_inlier_landmarks_a.size(), result.all_inlier_indices.size());
  EXPECT_LT(result.inlier_indices.size(), result.all_inlier_indices.size());
  int off_seabed = 0;
  for (const Eigen::Vector3d& landmark : result.all_inlier_landmarks_a)
    off_seabed += !(std::abs(landmark.z() - kAltitudeM) < 5.0 * kReliefSigmaM);
  EXPECT_LT(off_seabed, result.num_inliers / 50) << "landmarks more than 5 relief sigmas off the seabed";
}

TEST(RelativePose, RecoversAlongTrackAndLateralDrErrorParallel) { expectRecoversDrError(false); }

TEST(RelativePose, RecoversAlongTrackAndLateralDrErrorAntiParallel) { expectRecoversDrError(true); }

// On a flat seabed, range and plane residuals from two parallel lines fix a landmark given the
// two sonar positions, wherever B is laterally: a lateral shift is absorbed by landmark depth.
// The seabed prior from altimetry pins the depths and so the lateral offset.
TEST(RelativePose, SeabedPriorMakesLateralOffsetObservable) {
  const SyntheticPair pair = makePair(false, 11);
  const double dr_lateral_sigma_m = std::sqrt(pair.input.dr_covariance_ab(1, 1));
  RelativePoseOptions with_prior = testOptions();
  RelativePoseOptions without_prior = testOptions();
  without_prior.use_seabed_prior = false;
  const RelativePoseResult a = estimateRelativePose(pair.input, with_prior);
  const RelativePoseResult b = estimateRelativePose(pair.input, without_prior);
  ASSERT_TRUE(a.accepted) << a.reason;
  const Errors ea = errorsOf(pair, a);
  const Eigen::Vector3d eb = b.T_a_b.translation - pair.T_a_b_true.translation;
  const double sigma_with = std::sqrt(a.covariance(1, 1));
  const double sigma_without = std::sqrt(b.covariance(1, 1));
  std::printf("with seabed prior: lateral error %.3f m sigma %.3f m; without: lateral error %.3f m sigma %.3f m "
              "(accepted %d: %s); DR lateral sigma %.1f m\n",
              ea.translation_m.y(), sigma_with, eb.y(), sigma_without, b.accepted, b.reason.c_str(), dr_lateral_sigma_m);
  EXPECT_LT(std::abs(ea.translation_m.y()), 0.3);
  EXPECT_LT(sigma_with, 0.1 * dr_lateral_sigma_m);
  // Without the prior the lateral offset stays at the DR guess, with the DR prior's uncertainty.
  EXPECT_GT(std::abs(eb.y()), 1.0);
  EXPECT_GT(sigma_without, 0.5 * dr_lateral_sigma_m);
}

// Normalised estimation error squared over a batch of noise/outlier/RANSAC seeds: near its
// dimension when the reported covariance is consistent.
TEST(RelativePose, CovarianceIsConsistentOverSeeds) {
  double nees_translation = 0.0, nees_full = 0.0, seconds = 0.0;
  int runs = 0;
  for (std::uint64_t seed = 100; seed < 120; ++seed) {
    const SyntheticPair pair = makePair(seed % 2 == 1, seed);
    RelativePoseOptions options = testOptions();
    options.seed = seed;
    const RelativePoseResult result = estimateRelativePose(pair.input, options);
    ASSERT_TRUE(result.accepted) << "seed " << seed << ": " << result.reason;
    const Errors e = errorsOf(pair, result);
    std::printf("seed %d err %.3f %.3f %.3f sig %.3f %.3f %.3f rot err %.4f %.4f %.4f sig %.4f %.4f %.4f\n", int(seed),
                  e.translation_m.x(), e.translation_m.y(), e.translation_m.z(), std::sqrt(result.covariance(0, 0)),
                  std::sqrt(result.covariance(1, 1)), std::sqrt(result.covariance(2, 2)),
                  sss::core::boxMinus(pair.T_a_b_true, result.T_a_b)(3), sss::core::boxMinus(pair.T_a_b_true, result.T_a_b)(4),
                  sss::core::boxMinus(pair.T_a_b_true, result.T_a_b)(5), std::sqrt(result.covariance(3, 3)),
                  std::sqrt(result.covariance(4, 4)), std::sqrt(result.covariance(5, 5)));
    nees_translation += e.nees_translation;
    nees_full += e.nees_full;
    seconds += result.seconds;
    ++runs;
  }
  nees_translation /= runs;
  nees_full /= runs;
  std::printf("mean NEES over %d pairs: translation %.2f (dof 3), full pose %.2f (dof 6); %.3f s per pair\n", runs,
              nees_translation, nees_full, seconds / runs);
  EXPECT_GT(nees_translation, 0.3 * 3);
  EXPECT_LT(nees_translation, 3.0 * 3);
  EXPECT_GT(nees_full, 0.3 * 6);
  EXPECT_LT(nees_full, 3.0 * 6);
}

// Cluster-robust estimates over a run of seeds (parallel and anti-parallel alternately): every
// pair must be accepted; `visit` sees each pair with its result.
template <typename Visit>
int forEachClusterRobustPair(std::uint64_t first_seed, int count, const PatchErrors& errors, Visit visit) {
  for (std::uint64_t seed = first_seed; seed < first_seed + count; ++seed) {
    const SyntheticPair pair = makePair(seed % 2 == 1, seed, 1000, 0.2, false, errors);
    RelativePoseOptions options = clusterRobustOptions();
    options.seed = seed;
    const RelativePoseResult result = estimateRelativePose(pair.input, options);
    EXPECT_TRUE(result.accepted) << "seed " << seed << ": " << result.reason;
    if (!result.accepted) return 0;
    visit(pair, result);
  }
  return count;
}

// Errors shared by the matches of one patch of seabed: Ceres' covariance, which counts every
// match as an independent look, is far too small; the cluster-robust covariance takes the spread
// between patches from the residuals and stays consistent. 20 seeds, a 40 m wide overlap strip
// (12-15 patches of 20 m), 0.1 m of shared ground-range error per patch. Measured: NEES 3.15
// against Ceres' 12.4; the sandwich from a dozen clusters is still a little narrow (a known
// small-sample bias), hence the bound at twice the consistent value.
TEST(RelativePose, ClusterRobustCovarianceHoldsWhenNeighbouringMatchesShareTheirError) {
  PatchErrors shared;
  shared.sigma_m = 0.1;  // twice the assumed range sigma: inside the RANSAC band
  shared.east_min_m = 10.0;
  shared.east_max_m = 50.0;
  double nees_robust = 0.0, nees_model = 0.0, seconds = 0.0;
  double sigma_ratio = 0.0;
  auto accumulate = [&](const SyntheticPair& pair, const RelativePoseResult& result) {
    EXPECT_GE(result.covariance_clusters, 8);
    const sss::core::Vector6d delta = sss::core::boxMinus(pair.T_a_b_true, result.T_a_b);
    const Eigen::Vector2d horizontal = delta.head<2>();
    nees_robust += horizontal.dot(result.covariance.topLeftCorner<2, 2>().ldlt().solve(horizontal));
    nees_model += horizontal.dot(result.model_covariance.topLeftCorner<2, 2>().ldlt().solve(horizontal));
    sigma_ratio += std::sqrt(result.covariance(1, 1) / result.model_covariance(1, 1));
    seconds += result.seconds;
  };
  const int runs = forEachClusterRobustPair(200, 20, shared, accumulate);
  ASSERT_EQ(runs, 20);
  nees_robust /= runs;
  nees_model /= runs;
  sigma_ratio /= runs;
  std::printf("shared patch errors: mean horizontal NEES cluster-robust %.2f, Ceres %.2f (2 when consistent); "
              "lateral sigma robust / Ceres %.1f; %.3f s per pair\n",
              nees_robust, nees_model, sigma_ratio, seconds / runs);
  EXPECT_GT(nees_model, 10.0) << "the shared errors should make Ceres' independent-match covariance overconfident";
  EXPECT_GT(nees_robust, 0.5 * 2);
  EXPECT_LT(nees_robust, 2.0 * 2);
  EXPECT_GT(sigma_ratio, 2.0);
}

// Independent matches whose noise is what the options assume: the covariance from the residuals
// agrees with Ceres' (same information; the spread between patches is what the sigmas predict).
TEST(RelativePose, ClusterRobustCovarianceAgreesWithCeresForIndependentMatches) {
  PatchErrors wide;
  wide.east_min_m = 10.0;
  wide.east_max_m = 50.0;
  double log_ratio = 0.0;
  auto accumulate = [&](const SyntheticPair&, const RelativePoseResult& result) {
    log_ratio += 0.5 * std::log(result.covariance(1, 1) / result.model_covariance(1, 1));
  };
  const int runs = forEachClusterRobustPair(300, 10, wide, accumulate);
  ASSERT_EQ(runs, 10);
  const double ratio = std::exp(log_ratio / runs);
  std::printf("independent matches: lateral sigma cluster-robust / Ceres, geometric mean %.2f\n", ratio);
  EXPECT_GT(ratio, 0.5);
  EXPECT_LT(ratio, 2.0);
}

// The seabed under both lines undulates by +-0.5 m over 40 m (RMS 0.354 m), as their altimetry
// records it; the matches' seabed is left as it was.
void addUndulatingAltimetry(SyntheticPair& pair) {
  for (int i = 0; i < kPings; ++i) {
    const double undulation_m = 0.5 * std::sin(2.0 * M_PI * i * kPingSpacingM / 40.0);
    pair.input.altitude_a_m[i] += undulation_m;
    pair.input.altitude_b_m[i] -= undulation_m;
  }
}

// Relief between two lines moves every landmark alike, which no spread between clusters shows:
// the altimetry of both lines says how rough the seabed is, and the lateral sigma widens with it.
// A flat seabed (constant altitude at constant depth) adds nothing.
TEST(RelativePose, RoughSeabedUnderTheLinesWidensTheLateralSigma) {
  const SyntheticPair flat = makePair(false, 13);
  SyntheticPair rough = flat;
  addUndulatingAltimetry(rough);
  RelativePoseOptions options = clusterRobustOptions();
  const RelativePoseResult on_flat = estimateRelativePose(flat.input, options);
  const RelativePoseResult on_rough = estimateRelativePose(rough.input, options);
  options.seabed_relief_covariance = false;
  const RelativePoseResult rough_without = estimateRelativePose(rough.input, options);
  ASSERT_TRUE(on_flat.accepted) << on_flat.reason;
  ASSERT_TRUE(on_rough.accepted) << on_rough.reason;
  ASSERT_TRUE(rough_without.accepted) << rough_without.reason;
  std::printf("seabed relief from altimetry: flat %.3f m, rough %.3f m; lateral sigma rough %.3f m (%.3f m without "
              "the relief term), flat %.3f m\n",
              on_flat.seabed_relief_sigma_m, on_rough.seabed_relief_sigma_m, std::sqrt(on_rough.covariance(1, 1)),
              std::sqrt(rough_without.covariance(1, 1)), std::sqrt(on_flat.covariance(1, 1)));
  EXPECT_LT(on_flat.seabed_relief_sigma_m, 1e-6);
  EXPECT_NEAR(on_rough.seabed_relief_sigma_m, 0.5 / std::sqrt(2.0), 0.05);  // RMS of a sine of 0.5 m
  // A seabed dz higher than assumed, seen at ground range g from altitude h, is placed h dz / g
  // further out, by each line towards its own nadir: B's lateral offset moves by
  // h dz (1 / g_a + 1 / g_b) = 18 x 0.354 x (1/30 + 1/30) = 0.42 m (matches 20-40 m from either line).
  const double expected_lateral_m = kAltitudeM * (0.5 / std::sqrt(2.0)) * (2.0 / 30.0);
  EXPECT_NEAR(std::sqrt(on_rough.covariance(1, 1)), expected_lateral_m, 0.1 * expected_lateral_m + 0.04);
  EXPECT_GT(on_rough.covariance(1, 1), 4.0 * rough_without.covariance(1, 1));
}

// The same relief term on Ceres' covariance (the deployed default): it is reported on its own
// (relief_covariance) so that PairMatcherOptions::covariance_scale, a calibration of the matches'
// model, does not scale a physical size; the lateral sigma reaches the relief's
// h dz (1 / g_a + 1 / g_b), and on a flat seabed nothing is added.
TEST(RelativePose, RoughSeabedWidensCeresCovarianceToo) {
  const SyntheticPair flat = makePair(false, 13);
  SyntheticPair rough = flat;
  addUndulatingAltimetry(rough);
  RelativePoseOptions options = testOptions();
  ASSERT_TRUE(options.seabed_relief_covariance) << "on by default";
  const RelativePoseResult on_flat = estimateRelativePose(flat.input, options);
  const RelativePoseResult on_rough = estimateRelativePose(rough.input, options);
  ASSERT_TRUE(on_flat.accepted) << on_flat.reason;
  ASSERT_TRUE(on_rough.accepted) << on_rough.reason;
  EXPECT_LT(on_flat.relief_covariance.norm(), 1e-9);
  EXPECT_LT((on_flat.covariance - on_flat.model_covariance).norm(), 1e-12);
  EXPECT_LT((on_rough.covariance - on_rough.model_covariance - on_rough.relief_covariance).norm(),
            1e-9 * on_rough.covariance.norm());
  const double expected_lateral_m = kAltitudeM * (0.5 / std::sqrt(2.0)) * (2.0 / 30.0);
  std::printf("Ceres covariance: lateral sigma model %.3f m, relief %.3f m (expected %.3f m), total %.3f m\n",
              std::sqrt(on_rough.model_covariance(1, 1)), std::sqrt(on_rough.relief_covariance(1, 1)),
              expected_lateral_m, std::sqrt(on_rough.covariance(1, 1)));
  EXPECT_NEAR(std::sqrt(on_rough.relief_covariance(1, 1)), expected_lateral_m, 0.1 * expected_lateral_m + 0.04);
  EXPECT_GT(on_rough.covariance(1, 1), 4.0 * on_rough.model_covariance(1, 1));
}

// Relief between the lines that rises along the strip they share (an undulation of about the
// subframe's length) is a lateral ramp in the ranges, so a heading error, and nothing in the
// residuals shows it: the tilt term widens the heading (and, through it, the along-track) sigma
// by the slope the altimetry's relief allows over the subframe, relief sqrt(12) / L.
TEST(RelativePose, SeabedRisingAlongTheStripWidensTheHeadingSigma) {
  PatchErrors strip;
  const double relief_m = 0.5 / std::sqrt(2.0);                   // RMS of the altimetry's undulation
  const double length_m = (kPings - 1) * kPingSpacingM;
  strip.strip_slope = relief_m * std::sqrt(12.0) / length_m;      // a one-sigma ramp of that relief
  SyntheticPair pair = makePair(false, 13, 1000, 0.2, false, strip);
  addUndulatingAltimetry(pair);
  RelativePoseOptions options = testOptions();
  ASSERT_TRUE(options.seabed_tilt_covariance) << "on by default";
  const RelativePoseResult with = estimateRelativePose(pair.input, options);
  options.seabed_tilt_covariance = false;
  const RelativePoseResult without = estimateRelativePose(pair.input, options);
  ASSERT_TRUE(without.accepted) << without.reason;
  ASSERT_TRUE(with.accepted) << with.reason;
  const double heading_error_rad = sss::core::boxMinus(pair.T_a_b_true, with.T_a_b)(5);
  // Each line places a point dz higher h dz / g nearer its nadir: the strip's ramp k turns B by
  // h k (1 / g_a + 1 / g_b) = 18 x k x 2 / 30 (matches 20-40 m from either line).
  const double expected_heading_rad = kAltitudeM * strip.strip_slope * (2.0 / 30.0);
  std::printf("strip slope %.4f: heading error %.4f rad (expected about %.4f); heading sigma %.4f rad without the "
              "tilt term, %.4f with it (tilt sigma %.4f)\n",
              strip.strip_slope, heading_error_rad, expected_heading_rad, std::sqrt(without.covariance(5, 5)),
              std::sqrt(with.covariance(5, 5)), with.seabed_tilt_sigma);
  EXPECT_NEAR(with.seabed_tilt_sigma, strip.strip_slope, 0.1 * strip.strip_slope);
  EXPECT_NEAR(std::abs(heading_error_rad), expected_heading_rad, 0.3 * expected_heading_rad);
  EXPECT_GT(std::abs(heading_error_rad), 3.0 * std::sqrt(without.covariance(5, 5)));  // overconfident without
  EXPECT_LT(std::abs(heading_error_rad), 2.0 * std::sqrt(with.covariance(5, 5)));     // covered with it
  EXPECT_NEAR(std::sqrt(with.relief_covariance(5, 5)), expected_heading_rad, 0.3 * expected_heading_rad);
}

// Raised features show each line the face turned towards it: every matched pixel lies nearer both
// sonars than the point the two lines share. Between parallel lines looking at the strip between
// them that is a lateral offset (the lines come out closer together) and no residual shows it. The
// estimator reports the pose's sensitivity to such a bias, which predicts the shift it causes, and
// range_bias_covariance adds it to the covariance so that the biased closure is covered.
TEST(RelativePose, ReliefRangeBiasIsPredictedAndCoveredByItsCovarianceTerm) {
  PatchErrors faces;
  faces.relief_range_bias_m = 0.3;
  const SyntheticPair clean = makePair(false, 13);
  const SyntheticPair biased = makePair(false, 13, 1000, 0.2, false, faces);  // the same draws
  RelativePoseOptions options = testOptions();  // without the term
  const RelativePoseResult clean_result = estimateRelativePose(clean.input, options);
  const RelativePoseResult biased_without = estimateRelativePose(biased.input, options);
  options.range_bias_covariance = true;
  options.range_bias_sigma_m = faces.relief_range_bias_m;
  const RelativePoseResult biased_with = estimateRelativePose(biased.input, options);
  const RelativePoseResult clean_with = estimateRelativePose(clean.input, options);
  for (const RelativePoseResult* r : {&clean_result, &biased_without, &biased_with, &clean_with})
    ASSERT_TRUE(r->accepted) << r->reason;

  // A slant range short by b at ground range g is a ground range short by b r / g; both lines see
  // the strip 20-40 m out, so B comes b (r_a / g_a + r_b / g_b) nearer: the sensitivity is that mean.
  double expected_sensitivity = 0.0;
  const int steps = 200;
  for (int i = 0; i < steps; ++i) {
    const double g = 20.0 + 20.0 * (i + 0.5) / steps;
    expected_sensitivity += 2.0 * std::hypot(g, kAltitudeM) / g / steps;
  }
  const double sensitivity = biased_with.range_bias_sensitivity(1);
  const double shift_m = biased_without.T_a_b.translation.y() - clean_result.T_a_b.translation.y();
  const Errors with = errorsOf(biased, biased_with);
  const Errors without = errorsOf(biased, biased_without);
  std::printf("relief range bias 0.3 m: lateral shift %.3f m, predicted %.3f m (sensitivity %.3f, geometry %.3f); "
              "lateral sigma %.3f -> %.3f m, translation NEES %.1f -> %.1f; clean pair's lateral sigma %.3f -> %.3f m\n",
              shift_m, -faces.relief_range_bias_m * sensitivity, sensitivity, expected_sensitivity,
              std::sqrt(biased_without.covariance(1, 1)), std::sqrt(biased_with.covariance(1, 1)),
              without.nees_translation, with.nees_translation, std::sqrt(clean_result.covariance(1, 1)),
              std::sqrt(clean_with.covariance(1, 1)));
  EXPECT_NEAR(sensitivity, expected_sensitivity, 0.15 * expected_sensitivity);
  EXPECT_NEAR(shift_m, -faces.relief_range_bias_m * sensitivity, 0.15 * faces.relief_range_bias_m * sensitivity);
  // Without the term the closure is many sigmas off; with it, covered (chi-square 3 dof, 99 %).
  EXPECT_GT(without.nees_translation, 30.0);
  EXPECT_LT(with.nees_translation, 11.34);
  EXPECT_LT(std::abs(with.translation_m.y()), 2.0 * std::sqrt(biased_with.covariance(1, 1)));
  // The term is the sensitivity times the sigma, added whatever the matches (its price on a clean pair).
  const double added_m = faces.relief_range_bias_m * sensitivity;
  EXPECT_NEAR(clean_with.covariance(1, 1) - clean_result.covariance(1, 1), added_m * added_m, 0.05 * added_m * added_m);
  // Along track it costs next to nothing: the bias moves the lines apart, not along.
  EXPECT_LT(std::abs(biased_with.range_bias_sensitivity(0)), 0.1 * sensitivity);
}

// Matches located by ZNCC peaks of varied sharpness: each match's range error grows as its peak
// flattens (sigma ~ 1/sqrt(curvature), curvatures spread over 36x: 0.4-2.4x the median match's
// error). Weighting each match by its peak (range_sigma_from_peak) is what a least-squares estimate
// should do with such errors: over 20 pairs the lateral error is smaller than with one sigma for
// all, and the covariance stays consistent.
TEST(RelativePose, SharpPeaksWeighMoreThanFlatOnes) {
  double squared_lateral_with = 0.0, squared_lateral_without = 0.0, nees_with = 0.0;
  const int runs = 20;
  for (std::uint64_t seed = 500; seed < 500 + runs; ++seed) {
    SyntheticPair pair = makePair(seed % 2 == 1, seed, 1000, 0.1);
    std::mt19937_64 rng(seed * 31 + 7);
    std::uniform_real_distribution<double> log_curvature(std::log(0.01), std::log(0.36));
    std::normal_distribution<double> unit(0.0, 1.0);
    const double median_curvature = 0.06;  // exp of the middle of the log range above
    for (Correspondence& c : pair.input.matches) {
      c.peak_curvature_col = static_cast<float>(std::exp(log_curvature(rng)));
      const double error_m = 0.3 * std::sqrt(median_curvature / c.peak_curvature_col) * unit(rng);
      c.col_b += static_cast<float>(error_m / kBinSizeM);
    }
    RelativePoseOptions with = testOptions();
    with.range_sigma_m = 0.22;  // the median match's range error per slant range (0.31 m on the difference)
    with.seed = seed;
    with.range_sigma_from_peak = true;  // off by default (see RelativePoseOptions)
    RelativePoseOptions without = with;
    without.range_sigma_from_peak = false;
    const RelativePoseResult a = estimateRelativePose(pair.input, with);
    const RelativePoseResult b = estimateRelativePose(pair.input, without);
    ASSERT_TRUE(a.accepted) << "seed " << seed << ": " << a.reason;
    ASSERT_TRUE(b.accepted) << "seed " << seed << ": " << b.reason;
    const Errors ea = errorsOf(pair, a), eb = errorsOf(pair, b);
    squared_lateral_with += ea.translation_m.y() * ea.translation_m.y() / runs;
    squared_lateral_without += eb.translation_m.y() * eb.translation_m.y() / runs;
    nees_with += ea.nees_translation / runs;
  }
  std::printf("peak-weighted ranges: lateral RMS %.3f m (one sigma for all: %.3f m), translation NEES %.2f (dof 3)\n",
              std::sqrt(squared_lateral_with), std::sqrt(squared_lateral_without), nees_with);
  EXPECT_LT(std::sqrt(squared_lateral_with), 0.85 * std::sqrt(squared_lateral_without));
  EXPECT_GT(nees_with, 0.3 * 3);
  EXPECT_LT(nees_with, 3.0 * 3);
}

TEST(RelativePose, TooFewPatchesOfSeabedAreRejectedWithAReason) {
  PatchErrors narrow;
  narrow.east_min_m = 21.0;  // one 20 m patch across, and the matches only 15 m along track
  narrow.east_max_m = 39.0;
  SyntheticPair pair = makePair(false, 9, 1000, 0.0, false, narrow);
  for (Correspondence& c : pair.input.matches) {
    c.row_a = 100.0f + std::fmod(c.row_a, 30.0f);  // A's rows 100-130: north 0-15 m
    c.row_b = c.row_a;
  }
  const RelativePoseResult result = estimateRelativePose(pair.input, clusterRobustOptions());
  EXPECT_FALSE(result.accepted);
  EXPECT_LT(result.covariance_clusters, 4);
  EXPECT_NE(result.reason.find("seabed patches"), std::string::npos) << result.reason;
}

TEST(RelativePose, RejectsGeometricallyInconsistentMatches) {
  const SyntheticPair pair = makePair(false, 5, 1000, 0.0, /*all_random=*/true);
  const RelativePoseResult result = estimateRelativePose(pair.input, testOptions());
  std::printf("random matches: accepted %d, %d inliers, reason: %s\n", result.accepted, result.num_inliers,
              result.reason.c_str());
  EXPECT_FALSE(result.accepted);
  EXPECT_FALSE(result.reason.empty());
}

TEST(RelativePose, RejectsTooFewMatchesWithAReason) {
  SyntheticPair pair = makePair(false, 3, 10);
  const RelativePoseResult result = estimateRelativePose(pair.input, testOptions());
  EXPECT_FALSE(result.accepted);
  EXPECT_NE(result.reason.find("usable correspondences"), std::string::npos) << result.reason;
}

}  // namespace
}  // namespace sss::matcher
