// Simulated seabed: a heightmap (depth, NED z down) and a reflectivity map on a regular grid in
// the mission's local NED plane, generated deterministically from a seed, with bilinear lookup.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace sss::sim {

// An object placed on the seabed by hand (tests, demos): a smooth mound that casts a shadow.
struct SeabedObject {
  double north_m = 0.0;
  double east_m = 0.0;
  double radius_m = 1.0;
  double height_m = 1.0;      // above the surrounding seabed
  double reflectivity = 1.0;  // backscatter coefficient of its surface (sediment is ~0.2-0.6)
};

struct SeabedOptions {
  uint64_t seed = 1;
  // Grid extent in local NED: cell (row, col) is at north = north_min_m + row * resolution_m,
  // east = east_min_m + col * resolution_m.
  double north_min_m = -100.0;
  double east_min_m = -100.0;
  double size_north_m = 200.0;
  double size_east_m = 200.0;
  double resolution_m = 0.15;  // finer than the sonar's ~0.2 m along-track footprint at mid range

  double mean_depth_m = 60.0;
  double slope_deg = 2.0;                  // large-scale plane; the issue allows up to ~5 deg
  double undulation_amplitude_m = 1.5;     // metre-scale hills
  double undulation_wavelength_m = 80.0;
  double ripple_amplitude_m = 0.04;        // sand ripples, only inside ripple fields
  double ripple_wavelength_m = 1.2;
  double ripple_fraction = 0.3;            // share of the area covered by ripple fields
  int trawl_mark_count = 12;               // long furrows crossing the area
  double trawl_mark_depth_m = 0.25;
  double trawl_mark_width_m = 1.2;
  double boulders_per_hectare = 6.0;
  double boulder_min_radius_m = 0.3;
  double boulder_max_radius_m = 1.5;
  double sediment_patch_scale_m = 40.0;    // size of mud/sand/gravel patches
  // Sediment backscatter: reflectivity = scale x (mud 0.15 + patch_contrast x (sand/gravel
  // steps of 0.22 and 0.25)) x (1 + texture_contrast x grain noise). Mud: low scale, weak
  // contrast and texture.
  double reflectivity_scale = 1.0;
  double patch_contrast = 1.0;
  double texture_contrast = 0.3;
  // A second, longer ripple set (megaripples, 3-20 m) inside the same ripple fields.
  double megaripple_amplitude_m = 0.0;
  double megaripple_wavelength_m = 8.0;
  // Rock outcrops: bright, rough, ridged relief over this share of the area, in patches of about
  // outcrop_scale_m.
  double outcrop_fraction = 0.0;
  double outcrop_relief_m = 1.0;
  double outcrop_scale_m = 60.0;
  std::vector<SeabedObject> objects;       // extra hand-placed objects

  // Switches for tests that need a clean scene (a flat bed with one object).
  bool enable_texture = true;  // slope, undulation, ripples, trawl marks, boulders, patches
};

class Seabed {
 public:
  explicit Seabed(const SeabedOptions& options);

  // Seabed depth (NED z, positive down) at a horizontal position; clamps outside the grid.
  double depthM(double north_m, double east_m) const;
  // Backscatter coefficient in [0, ~1.5].
  double reflectivity(double north_m, double east_m) const;
  // The large-scale depth only (plane + undulation): what a terrain-following vehicle tracks.
  double smoothDepthM(double north_m, double east_m) const;
  // Upward unit normal in NED (z component negative) from central differences of the heightmap.
  Eigen::Vector3d normal(double north_m, double east_m) const;
  bool contains(double north_m, double east_m) const;

  int rows() const { return rows_; }
  int cols() const { return cols_; }
  const SeabedOptions& options() const { return options_; }
  const std::vector<float>& depthGrid() const { return depth_; }  // row-major, row = north
  const std::vector<float>& reflectivityGrid() const { return reflectivity_; }

 private:
  double bilinear(const std::vector<float>& grid, double north_m, double east_m) const;
  void addMound(const SeabedObject& object);

  SeabedOptions options_;
  int rows_ = 0;
  int cols_ = 0;
  Eigen::Vector2d slope_gradient_ = Eigen::Vector2d::Zero();  // d depth / d (north, east)
  std::vector<float> depth_;
  std::vector<float> reflectivity_;
};

// Deterministic smooth value noise in [-1, 1] (used by the seabed and the vehicle motion).
double valueNoise2d(uint64_t seed, double x, double y);
double fractalNoise2d(uint64_t seed, double x, double y, int octaves);
uint64_t mixSeed(uint64_t a, uint64_t b);

}  // namespace sss::sim
