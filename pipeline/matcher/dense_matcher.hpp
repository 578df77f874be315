// Dense matching of two geo-referenced side-scan images: DR-initialised PatchMatch with a masked
// ZNCC patch distance (paper Sec. "Data Association", Alg. 1), at any relative heading.
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

#include "pipeline/core/config.hpp"

namespace sss::matcher {

// One canonical side-scan image with its geo-reference: row = ping, column = ground-range bin
// (port mirrored left of nadir, starboard right). All matrices have the image's size except
// heading_rad (rows x 1).
struct GeoImage {
  cv::Mat1f intensity;      // normalised intensities
  cv::Mat1b valid;          // 255 where the pixel may be matched (masks: nadir, far range, turns)
  cv::Mat2f position_ne_m;  // local north/east of every pixel's seabed point (DR or optimised poses)
  cv::Mat1f heading_rad;    // per-row vehicle heading (rows x 1), clockwise from north; unused here
  cv::Mat1f side;           // optional, unused
  // Optional (empty: none): 255 where a raised feature shows its lit face or its shadow
  // (findReliefFeatures), both of which depend on the side the feature is seen from. Given for
  // both images, the matches between opposed views over such a pixel are marked
  // (Correspondence::opposed_relief), or dropped with reject_shadowed_relief.
  cv::Mat1b relief;
};

struct DenseMatcherOptions {
  int patch_size = 13;   // paper: 13 (odd); the subframe pair matcher uses 21 (see PairMatcherOptions)
  int iterations = 10;   // paper: 10 rounds of random search + propagation
  // Stop before `iterations` once fewer than this fraction of the field changed in a round.
  double min_update_fraction = 0.005;
  // Search window around the geo-referenced initial guess, per image axis: max_offset_px (the
  // paper's o_max, 5 px) plus max_dr_error_m converted to pixels with A's own pixel spacing along
  // that axis. The paper's 5 px assumes DR error below a few pixels; lines of an AUV survey
  // differ by metres, so the DR term dominates (5 m at 0.13 m bins is ~38 columns).
  double max_offset_px = 5.0;
  double max_dr_error_m = 5.0;
  // A pixel of A whose nearest valid geo-referenced pixel of B is farther than this has no
  // overlap with B and is not matched.
  double max_init_distance_m = 1.0;
  double min_zncc = 0.6;             // matches below are dropped
  double min_valid_fraction = 0.8;   // of a patch's pixels valid in both images
  double min_patch_stddev = 1e-3;    // texture-free patches (intensity units) never match
  bool forward_backward_check = true;
  double max_fb_error_px = 1.5;
  // Of a match's 8 lattice neighbours, how many must have an offset within 1 px of its own.
  int min_coherent_neighbours = 4;
  // Aperture problem: a patch whose texture is one straight feature (a trawl mark, a sediment
  // edge) matches equally well anywhere along it, and the forward-backward and coherence checks
  // cannot tell (the whole field slides along it). Such patches are not matched: the ratio of the
  // small to the large eigenvalue of A's patch structure tensor must reach this (0: no check).
  double min_structure_ratio = 0.0;
  // Raised relief seen from opposite sides (any two lines with their overlap between them): a
  // boulder or rock shows each line the face turned towards it and casts its shadow away from it,
  // so the two views of it are mirror images along the look direction. Their best ZNCC pairs the
  // two lit faces (the lines come out closer) or the two shadows (farther), and every closure
  // between the two lines is shifted alike. A match between views whose look directions are more
  // than 135 deg apart is dropped when A's patch correlates better with B's patch mirrored along
  // the look direction, about any point of it, than with B's patch as it is; so are the matches
  // whose patch overlaps such a centre. What survives is seabed texture that looks the same from
  // both sides (reflectivity, sediment), which carries no such bias.
  bool reject_mirrored_relief = false;
  // The mirror test needs the two views to be mirror images; at far range a boulder's shadow is
  // many times its width and its lit face a pixel or two, and what survives the test still pairs
  // faces (a boulder field seen at 10 deg grazing: closures 1.4 m RMS off across track with the
  // test on). A feature's lit face and shadow stand out of the seabed's own statistics
  // (findReliefFeatures); their contrast outweighs the seabed texture's in any patch they enter and
  // pulls its ZNCC peak towards the side the feature is seen from (measured on the far-range
  // synthetic field: patches with a feature on a quarter of their contrast still biased). So a
  // match between views whose look directions are more than 135 deg apart is dropped when a
  // feature pixel lies in A's patch or in B's. Needs GeoImage::relief; views from one side keep all.
  bool reject_shadowed_relief = false;
  // Relief seen from opposite sides at low grazing is contrast-inverted: the slope lit for one line
  // is the one in shadow for the other. On periodic relief (sand waves, megaripples) the inverted
  // pattern correlates best half a wavelength off the truth, with a ZNCC as high as a true match's,
  // and the forward-backward and coherence checks pass (the whole field shifts alike: randomised
  // sand_ripples seed 3798961521, 7.6 m megaripples, mean match error 3.7 m on a pair). A match
  // between views whose look directions are more than 135 deg apart is dropped when A's patch also
  // matches B's contrast inverted (-ZNCC >= min_zncc) somewhere within the search window (a second
  // PatchMatch, on -ZNCC, over those nodes). Seabed texture (reflectivity) does not invert and keeps.
  bool reject_inverted_relief = false;
  // Periodic seabed (sand ripples, sand waves) correlates almost as well one or more wavelengths
  // off the truth as at it, and the forward-backward and coherence checks pass: the whole field
  // shifts alike (randomised sand_ripples seed 1897484053, lines matched at 65-99 m ground range
  // over 14 m megaripples: 1 % of one pair's matches within 2 px, a closure 6.9 m off). Every match
  // that passes the other checks is scored at every offset of the search window; following the
  // score's superlevel sets down from the best (union-find over the window's cells), the first
  // level at which a second, separate peak appears is that peak's score (a shoulder of the peak
  // itself is not separate). A match is kept only when its peak stands at least this much ZNCC
  // above it, and when it is the window's best (0: no check).
  double min_peak_margin = 0.0;
  bool subpixel = true;              // parabola fit of ZNCC around the integer optimum
  double random_search_ratio = 0.5;  // Barnes et al.: window shrinks by this factor per sample
  int stride = 2;                    // match every stride-th row and column of A
  int threads = 2;
  std::uint64_t seed = 1;            // random search is seeded per pixel: same output for any threads
};

// A match from pixel (row_a, col_a) of A to the continuous position (row_b, col_b) of B.
struct Correspondence {
  float row_a = 0.0f;
  float col_a = 0.0f;
  float row_b = 0.0f;
  float col_b = 0.0f;
  float zncc = 0.0f;
  // How sharply the ZNCC score falls across range either side of the peak: 2 s(0) - s(-1) - s(+1),
  // in matching-grid columns (0 when not measured: no sub-pixel step or a peak at the grid's edge).
  // A sharp peak locates the match in range better than a flat one (measured on simulated
  // missions: the median range error halves from the flattest to the sharpest quarter).
  float peak_curvature_col = 0.0f;
  // Seen from opposite sides with a raised feature's face or shadow in either patch (only set when
  // both images carry GeoImage::relief): the match may be biased towards the side each line sees
  // the feature from (PairMatcherOptions::test_opposed_relief tests it against the rest).
  bool opposed_relief = false;
};

// Wall-clock seconds of each stage of one match() call and the pixel counts behind them.
struct MatchTimings {
  double kd_tree_s = 0.0;         // building the kd-tree over B's valid geo-referenced pixels
  double initialisation_s = 0.0;  // kd-tree queries and resampling B onto A's pixel grid
  double patch_match_s = 0.0;     // random search + propagation, forward (A -> B) and inverted
  double consistency_s = 0.0;     // backward PatchMatch (B -> A), FB check, sub-pixel, thresholds
  double total_s = 0.0;
  long overlapping_pixels = 0;    // valid A pixels on the stride grid with a B pixel within reach
  long matches = 0;
  long mirrored_relief_rejected = 0;  // matches dropped by reject_mirrored_relief
  long shadowed_relief_rejected = 0;  // matches dropped by reject_shadowed_relief
  long shadowed_relief_marked = 0;    // matches marked as opposed_relief (before the later checks)
  long inverted_relief_rejected = 0;  // matches dropped by reject_inverted_relief
  long ambiguous_rejected = 0;        // matches dropped by min_peak_margin (another peak in the window)
};

class DenseMatcher {
 public:
  // Throws std::invalid_argument for options validateDenseMatcherOptions rejects.
  explicit DenseMatcher(DenseMatcherOptions options);

  // Correspondences from A to B, at most one per stride-grid pixel of A. Returns none when the
  // images do not overlap according to their geo-references. Throws std::invalid_argument when
  // the matrices of an image disagree in size or type (a programming error upstream).
  std::vector<Correspondence> match(const GeoImage& a, const GeoImage& b, MatchTimings* timings = nullptr) const;

  const DenseMatcherOptions& options() const { return options_; }

 private:
  DenseMatcherOptions options_;
};

// The pixels of a raised feature's lit face and shadow: valid pixels whose log intensity lies more
// than outlier_sigmas robust standard deviations (1.4826 x the median absolute deviation of the
// image's valid pixels) from the image's median, then grown by one pixel. The image's own
// statistics set the scale: speckle and sediment texture stay inside, a shadow (no echo) and a
// face turned to the sonar fall far outside. Empty result when fewer than 100 pixels are valid.
cv::Mat1b findReliefFeatures(const GeoImage& image, double outlier_sigmas = 4.0);

// Empty when the options are usable; otherwise what is wrong with which field.
std::vector<std::string> validateDenseMatcherOptions(const DenseMatcherOptions& options);

// Fills options from a YAML section (keys = field names) and records every problem in it.
void readDenseMatcherOptions(sss::core::ConfigSection& section, DenseMatcherOptions& options);

}  // namespace sss::matcher
