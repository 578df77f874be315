// Synthetic geo-referenced side-scan image pairs with exact ground truth, for the dense matcher's
// tests and benchmark: a procedural seabed seen from two straight survey lines with DR error.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "pipeline/matcher/dense_matcher.hpp"

namespace sss::matcher::synthetic {

// A raised feature (boulder) on the seabed: seen from a sonar, the half facing it is bright, the
// far half dark, and it casts a shadow away from the sonar (length height x range / (altitude -
// height)). Two lines on opposite sides therefore see mirror images of it.
struct Boulder {
  Eigen::Vector2d centre_ne_m = Eigen::Vector2d::Zero();
  double radius_m = 1.0;
  double height_m = 1.0;
};

// Seabed reflectivity: multi-scale value noise (0.4 m to 12.8 m cells), deterministic per seed,
// with texture_contrast scaling its log-amplitude; flat = true gives a texture-free seabed of
// constant reflectivity. Boulders add relief whose appearance depends on where the sonar is.
struct Seabed {
  std::uint64_t seed = 1;
  bool flat = false;
  double texture_contrast = 1.0;
  std::vector<Boulder> boulders;
  double reflectivity(double north_m, double east_m) const;
  // Backscatter of the seabed point seen from a sonar at sonar_ne_m, altitude_m above the seabed.
  double backscatter(const Eigen::Vector2d& point_ne_m, const Eigen::Vector2d& sonar_ne_m, double altitude_m) const;
};

// Boulders of radius [min_radius_m, max_radius_m] (height = radius) at random positions in the
// north/east box, about one per spacing_m x spacing_m, deterministic per seed.
std::vector<Boulder> scatterBoulders(std::uint64_t seed, const Eigen::Vector2d& min_ne_m, const Eigen::Vector2d& max_ne_m,
                                     double spacing_m, double min_radius_m, double max_radius_m);

// A straight survey line: row = ping along heading, column = ground-range bin, port mirrored
// left of nadir (columns [0, columns_per_side) port, the rest starboard).
struct SurveyLine {
  Eigen::Vector2d start_ne_m = Eigen::Vector2d::Zero();
  double heading_rad = 0.0;  // clockwise from north
  int rows = 200;
  int columns_per_side = 1300;
  double row_spacing_m = 0.5;  // 2 m/s at 4 pings/s
  double bin_size_m = 0.13;    // 170 m range in 1300 bins
  int nadir_bins = 20;         // masked either side of nadir

  Eigen::Vector2d position(double row, double column) const;
  // Inverse of position(): continuous (row, column) of a seabed point.
  Eigen::Vector2d pixel(const Eigen::Vector2d& position_ne_m) const;
};

struct RenderOptions {
  std::uint64_t speckle_seed = 1;
  double speckle_stddev = 0.25;  // multiplicative, independent per image
  double gain = 1.0;             // overall gain (ZNCC must not care)
  int footprint_samples = 4;     // along-track sub-samples averaged per pixel (beam footprint)
  double altitude_m = 10.0;      // of the sonar above the seabed (boulder shadows)
};

// Renders the seabed as seen from the line, geo-referenced with the TRUE positions.
GeoImage render(const Seabed& seabed, const SurveyLine& line, const RenderOptions& options);

// Adds a DR error to the geo-reference: rotation about the image centre, then a shift.
void addDrError(GeoImage& image, const Eigen::Vector2d& shift_ne_m, double rotation_rad);

// Masks a block of rows (a turn, a bad stretch) in the image.
void maskRows(GeoImage& image, int first_row, int last_row);

enum class Direction { kParallel, kAntiParallel };

// Line B of a lawnmower pair: line_spacing_m to starboard of A, same or opposite direction, over
// the same stretch of seabed shifted by along_track_shift_m.
SurveyLine secondLine(const SurveyLine& a, Direction direction, double line_spacing_m, double along_track_shift_m);

// Match quality against ground truth: true positions come from the lines, not the geo-reference.
struct Evaluation {
  long matches = 0;
  long within_tolerance = 0;
  long matchable = 0;  // stride-grid valid A pixels whose true B pixel is valid with a full patch inside B
  double withinFraction() const { return matches ? double(within_tolerance) / matches : 0.0; }
  double recall() const { return matchable ? double(within_tolerance) / matchable : 0.0; }
};
Evaluation evaluate(const std::vector<Correspondence>& matches, const SurveyLine& line_a, const GeoImage& a,
                    const SurveyLine& line_b, const GeoImage& b, int stride, int patch_size, double tolerance_px);

}  // namespace sss::matcher::synthetic
