// One subframe pair from images to relative pose: geo-referenced images under the current poses
// (DR or optimised), dense PatchMatch, then the RANSAC relative pose with a DR prior.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/config.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/matcher/dense_matcher.hpp"
#include "pipeline/matcher/relative_pose.hpp"
#include "pipeline/core/subframe_types.hpp"

namespace sss::matcher {

// Dense matching defaults for subframe pairs at the matching resolution below (0.5 m pixels):
// a 21-pixel patch (10 m, the paper's 13 at its finer pixels covers less seabed than speckle
// needs) and ZNCC >= 0.75. On simulated anti-parallel / parallel pairs: 88 % / 81 % of matches
// within 2 px of the truth (patch 13, ZNCC 0.6: 54 % / 58 %).
inline DenseMatcherOptions subframePairDenseDefaults() {
  DenseMatcherOptions options;
  options.patch_size = 21;
  options.min_zncc = 0.75;
  // Patches of one straight feature slide along it; on a seed-6 survey whose texture is mostly
  // trawl marks the whole field of two pairs slid by a pixel (closures 1 m off). 0.2 keeps 2/3 of
  // the matches: default survey closures along 0.50 -> 0.18 m RMS there, neutral on seed 1.
  options.min_structure_ratio = 0.2;
  return options;
}

// Relative-pose defaults for dense matches at that resolution. Measured on the default simulated
// survey over a flat seabed, where the estimator fed true correspondences is exact (0.007 m), so
// the error left comes from the matches: plain least squares with sigma_r 0.1 m gave along /
// lateral errors of 0.27 / 0.17 m RMS; a matched column is good to about half a 0.5 m pixel
// (sigma_r 0.2 m) and a Cauchy loss at 0.5 sigma follows the bulk of the matches: 0.11 / 0.07 m.
inline RelativePoseOptions subframePairPoseDefaults() {
  RelativePoseOptions options;
  options.range_sigma_m = 0.2;
  options.robust_loss_scale = 0.5;
  return options;
}

struct PairMatcherOptions {
  DenseMatcherOptions dense = subframePairDenseDefaults();
  RelativePoseOptions pose = subframePairPoseDefaults();
  // Matching resolution. Speckle is independent between two looks at the seabed; only texture
  // larger than a few speckle cells correlates. Bins are averaged across track to about this size
  // (the canonical 0.06 m bins against 0.5 m between pings: near-square pixels) and smoothed by a
  // Gaussian of smoothing_sigma_px (masked, normalised) before PatchMatch. Measured on simulated
  // pairs: ZNCC at the true match rises from ~0 (native bins) to a median of ~0.65.
  double matching_bin_size_m = 0.5;   // ~ the ping spacing at 2 m/s and 4 pings/s
  double smoothing_sigma_px = 1.5;
  // Relief looks inverted from its two sides: a trawl mark or a boulder seen from the other line
  // has its highlight and its shadow swapped, and matching raw intensity aligns highlight with
  // highlight, a wall's width (1-3 px) off the true match. A second dense pass matches the
  // rectified contrast |I - local mean| (masked Gaussian mean of this sigma, after smoothing),
  // which a highlight-shadow pair gives alike from either side but which drops the sign that
  // sediment texture carries. The two are merged per pixel of A: one match kept as it is, two
  // that agree within 1 px kept as the raw one, two that disagree as the rectified one.
  // Measured on whole simulated missions (sss-process --write-matches, sss-eval --matches),
  // within 2 px / recall: 40 m line spacing, parallel 0.78 / 0.21 -> 0.83 / 0.29, anti-parallel
  // 0.88 / 0.17 -> 0.88 / 0.21; default mission 0.86 / 0.30 -> 0.89 / 0.41; 3 lines + 2 cross
  // lines, crossing 0.85 / 0.26 -> 0.86 / 0.34. Without the simulator's trawl marks raw
  // intensity alone gave 0.89 / 0.95 within 2 px. 0: raw intensity only.
  double rectify_sigma_px = 8.0;
  // DR uncertainty of the relative pose between two centre pings (1 sigma), from the distance d
  // travelled between them: horizontal sqrt(fixed^2 + (per_m * d)^2). A conservative INS/DVL
  // drifts 0.1-0.5 % of distance; 1 % keeps the prior weak, so the sonar decides.
  double dr_horizontal_sigma_fixed_m = 1.0;
  double dr_horizontal_sigma_per_m = 0.01;
  double dr_depth_sigma_m = 0.05;             // pressure depth: absolute, a few cm
  // Heading: an INS holds relative heading between two lines to about 0.1 deg; a looser prior let
  // seabed-model errors turn closures by 0.3 deg RMS (0.18 deg with this one, default mission).
  double dr_heading_sigma_fixed_rad = 0.002;
  double dr_heading_sigma_per_m = 2e-6;
  double dr_roll_pitch_sigma_rad = 0.005;     // measured absolutely by the INS
  int min_matches = 100;                      // fewer dense matches: rejected before RANSAC
  // The relative pose's Ceres covariance treats every correspondence as independent; dense matches
  // on a smoothed image are not (neighbours share texture and the same seabed-model error), so
  // it is far too small: on simulated surveys the horizontal NEES averaged ~60 per axis. The
  // published covariance is scaled by this factor and floored, calibrated on those surveys
  // (matcher_engine_test prints the batch NEES).
  // 30 with the robust refinement: mean horizontal NEES 1.4 (default mission), 2.4 (cross-line
  // survey) by sss-eval --closures; 0.5 on the flat 3-line survey of matcher_engine_test; 1.5-7.6
  // on randomised missions. With RelativePoseOptions::covariance_cluster_m > 0 the covariance comes
  // from the residuals instead: set this to 1 then.
  double covariance_scale = 30.0;
  double min_translation_sigma_m = 0.05;
  double min_rotation_sigma_rad = 0.001;
  // Matches over a raised feature seen from opposite sides (Correspondence::opposed_relief) pair
  // the faces, or the shadows, each line sees: far out, where a shadow is many times the feature's
  // width, that moves the two lines closer together or apart by about a feature's width, and every
  // such match of the pair alike. Seabed texture around the features looks the same from both
  // sides. With this on (matchPair gives the dense matcher GeoImage::relief to mark them) a pair whose inliers
  // include such matches is estimated again without them, and the two poses are compared
  // (Hausman): d = pose without - pose with, over the horizontal position and heading, against
  // C_without - C_with, the extra spread of an estimate from fewer matches. Beyond the chi-square
  // quantile below (3 degrees of freedom) the features biased the pose: the one without them is
  // published. Within it both agree and the pose from all the matches is kept; so it is where the
  // matches without features are too few to be estimated alone.
  bool test_opposed_relief = true;
  double opposed_relief_chi2 = 11.34;  // 3 degrees of freedom, 99 %
  // Relief seen from opposite sides at low grazing biases the two passes opposite ways: raw
  // intensity pairs each line's lit face and shadow with the other's, so the feature appears
  // nearer to each line and the lines come out closer; rectified contrast pairs each line's
  // highlight-and-shadow blob, which lies beyond the feature as seen from each line, so they come
  // out further apart. Measured on far-range boulder fields (lines 184 m apart): raw 1.0-1.4 m
  // short, rectified 0.6-1.3 m long, on the same pair. With this on, an accepted pair is estimated
  // from each pass's matches alone; where the two differ beyond their own spreads (chi-square,
  // 3 degrees of freedom over horizontal position and heading), the truth lies between them
  // somewhere the data cannot say, and the published covariance grows by d d' (d: their
  // difference), so that the graph takes the closure's lateral word for what it is worth.
  // Off by default: on boulder_field-3815565661 it widened 9 far-range closures and SLAM went from
  // 2.02 to 2.66 m (DR 1.73 m; publishing the two passes' midpoint instead: 2.58 m), the survey
  // stretched further (scale 1.0034 -> 1.0045): those closures' shortening was offsetting a
  // lengthening elsewhere (README, "Raw and rectified passes").
  bool test_pass_agreement = false;
  double pass_agreement_chi2 = 11.34;
};

void readPairMatcherOptions(sss::core::ConfigSection& section, PairMatcherOptions& options);

std::vector<std::string> validatePairMatcherOptions(const PairMatcherOptions& options);

// The Hausman statistic of test_opposed_relief: d' D^-1 d over the horizontal position and heading
// of d (a [dt, dr] tangent vector: the estimate from a subset of the matches minus the one from
// all), D = C_subset - C_all, the spread the subset's estimate adds. D is floored at a tenth of
// C_subset (in C_subset's whitened frame): the difference of two finite-sample covariances need not
// be positive definite. Chi-square with 3 degrees of freedom when the subset and the rest agree;
// -1 when C_subset is not positive definite.
double hausmanStatistic(const sss::core::Vector6d& d, const sss::core::Matrix6d& c_subset,
                        const sss::core::Matrix6d& c_all);

// Covariance of the DR relative pose after `distance_m` of travel, tangent [dt, dr].
sss::core::Matrix6d drRelativeCovariance(double distance_m, const PairMatcherOptions& options);

// Bins averaged per matching pixel for a subframe's ground-range axis (>= 1).
int columnDecimation(const sss::core::SubframeGeometry& geometry, const PairMatcherOptions& options);
// Full-resolution (fractional) column of the centre of matching column k.
double fullResolutionColumn(const sss::core::SubframeGeometry& geometry, int decimation, double k);

// The subframe's image at the matching resolution (columns averaged by `decimation`, a pixel
// valid only when all its bins are; smoothed within the mask), every pixel geo-referenced under
// the given per-row poses. decimation 1 and smoothing 0: the image as it is.
GeoImage toGeoImage(const sss::core::Subframe& subframe, const std::vector<sss::core::Pose>& T_world_body,
                    int decimation = 1, double smoothing_sigma_px = 0.0);

// The image with its intensity replaced by the rectified contrast |I - masked Gaussian mean of
// sigma_px| on valid pixels (see PairMatcherOptions::rectify_sigma_px).
GeoImage rectifiedContrast(const GeoImage& image, double sigma_px);

// Raw-intensity and rectified-contrast matches of the same pair merged per pixel of A (see
// PairMatcherOptions::rectify_sigma_px): a pixel matched once keeps its match, twice within 1 px
// the raw one, twice further apart the rectified one. Sorted by A's row, then column.
std::vector<Correspondence> mergeMatches(const std::vector<Correspondence>& raw,
                                         const std::vector<Correspondence>& rectified);

struct PairMatch {
  bool accepted = false;
  std::string reason;                  // why rejected
  std::vector<Correspondence> matches; // dense matches A -> B, full-resolution columns
  int decimation = 1;                  // bins per matching pixel
  MatchTimings dense_timings;          // both dense passes (raw and rectified contrast) summed
  RelativePoseResult pose;             // T_a_b between the centre pings, covariance, inliers
  double mean_zncc = 0.0;
  // test_opposed_relief: inliers over opposed relief, and the test (negative: not run, because
  // no inlier is over such relief, or the rest could not be estimated alone).
  int opposed_relief_inliers = 0;
  double opposed_relief_statistic = -1.0;
  bool opposed_relief_replaced = false;   // the pose published is the one without them
  // test_pass_agreement: the test (negative: not run, because the rectified pass is off or either
  // pass alone could not be estimated), the horizontal distance between the two passes' poses, and
  // whether the published covariance was widened by it.
  double pass_agreement_statistic = -1.0;
  double pass_disagreement_m = 0.0;
  bool pass_disagreement_widened = false;
  double georeference_s = 0.0;
  double seconds = 0.0;                // the whole pair
};

// Matches B against A with the given poses (one per row; DR or optimised) and estimates the
// relative pose of B's centre ping in A's. Never throws for field data.
PairMatch matchPair(const sss::core::Subframe& a, const std::vector<sss::core::Pose>& poses_a,
                    const sss::core::Subframe& b, const std::vector<sss::core::Pose>& poses_b,
                    const DenseMatcher& dense, const PairMatcherOptions& options);

}  // namespace sss::matcher
