// Synthetic geo-referenced side-scan image pairs with exact ground truth, for the dense matcher's
// tests and benchmark: a procedural seabed seen from two straight survey lines with DR error.
#include "pipeline/matcher/synthetic_pair.hpp"

#include <algorithm>
#include <cmath>

namespace sss::matcher::synthetic {
namespace {

std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}
double unit(std::uint64_t h) { return static_cast<double>(h >> 11) / 9007199254740992.0; }  // [0, 1)

double latticeValue(std::uint64_t seed, std::int64_t i, std::int64_t j) {
  return 2.0 * unit(mix(seed ^ mix(static_cast<std::uint64_t>(i) * 0x632be59bd9b4e019ULL ^
                                   static_cast<std::uint64_t>(j)))) - 1.0;
}
double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

// Smoothly interpolated lattice noise in [-1, 1] with one lattice cell per cell_m.
double valueNoise(std::uint64_t seed, double x, double y, double cell_m) {
  const double u = x / cell_m, v = y / cell_m;
  const double fu = std::floor(u), fv = std::floor(v);
  const auto i = static_cast<std::int64_t>(fu), j = static_cast<std::int64_t>(fv);
  const double s = fade(u - fu), t = fade(v - fv);
  const double a = latticeValue(seed, i, j), b = latticeValue(seed, i + 1, j);
  const double c = latticeValue(seed, i, j + 1), d = latticeValue(seed, i + 1, j + 1);
  return (1 - t) * ((1 - s) * a + s * b) + t * ((1 - s) * c + s * d);
}

// Standard normal from two hashes (Box-Muller).
double gaussian(std::uint64_t h) {
  const double u1 = std::max(unit(mix(h)), 1e-12), u2 = unit(mix(h ^ 0xabcdefULL));
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

}  // namespace

double Seabed::reflectivity(double north_m, double east_m) const {
  if (flat) return 1.0;
  double sum = 0.0;
  double cell_m = 0.4;
  for (int octave = 0; octave < 6; ++octave, cell_m *= 2.0)
    sum += std::pow(cell_m, 0.5) * valueNoise(seed + static_cast<std::uint64_t>(octave) * 7919, north_m, east_m, cell_m);
  return std::exp(0.5 * texture_contrast * sum);
}

double Seabed::backscatter(const Eigen::Vector2d& point_ne_m, const Eigen::Vector2d& sonar_ne_m,
                           double altitude_m) const {
  const double value = reflectivity(point_ne_m.x(), point_ne_m.y());
  if (boulders.empty()) return value;
  const Eigen::Vector2d to_point = point_ne_m - sonar_ne_m;
  const double range_m = to_point.norm();
  if (!(range_m > 0.0)) return value;
  const Eigen::Vector2d look = to_point / range_m;
  for (const Boulder& boulder : boulders) {
    const Eigen::Vector2d d = point_ne_m - boulder.centre_ne_m;
    const double along = d.dot(look);                            // away from the sonar
    const double across = std::abs(d.x() * look.y() - d.y() * look.x());
    if (across >= boulder.radius_m) continue;
    if (d.norm() < boulder.radius_m) return along < 0.0 ? 4.0 * value : 0.3 * value;  // lit face / far face
    const double shadow_m = boulder.height_m * range_m / std::max(altitude_m - boulder.height_m, 0.1);
    if (along > 0.0 && along < boulder.radius_m + shadow_m) return 0.05 * value;
  }
  return value;
}

std::vector<Boulder> scatterBoulders(std::uint64_t seed, const Eigen::Vector2d& min_ne_m, const Eigen::Vector2d& max_ne_m,
                                     double spacing_m, double min_radius_m, double max_radius_m) {
  std::vector<Boulder> boulders;
  const Eigen::Vector2d size = max_ne_m - min_ne_m;
  const int count = static_cast<int>(std::lround(size.x() * size.y() / (spacing_m * spacing_m)));
  for (int i = 0; i < count; ++i) {
    const std::uint64_t h = mix(seed ^ mix(static_cast<std::uint64_t>(i) + 0x5151ULL));
    Boulder boulder;
    boulder.centre_ne_m = min_ne_m + Eigen::Vector2d(unit(mix(h)) * size.x(), unit(mix(h + 1)) * size.y());
    boulder.radius_m = min_radius_m + unit(mix(h + 2)) * (max_radius_m - min_radius_m);
    boulder.height_m = boulder.radius_m;
    boulders.push_back(boulder);
  }
  return boulders;
}

Eigen::Vector2d SurveyLine::position(double row, double column) const {
  const Eigen::Vector2d forward(std::cos(heading_rad), std::sin(heading_rad));
  const Eigen::Vector2d starboard(-std::sin(heading_rad), std::cos(heading_rad));
  return start_ne_m + row * row_spacing_m * forward + (column + 0.5 - columns_per_side) * bin_size_m * starboard;
}

Eigen::Vector2d SurveyLine::pixel(const Eigen::Vector2d& position_ne_m) const {
  const Eigen::Vector2d forward(std::cos(heading_rad), std::sin(heading_rad));
  const Eigen::Vector2d starboard(-std::sin(heading_rad), std::cos(heading_rad));
  const Eigen::Vector2d d = position_ne_m - start_ne_m;
  return {d.dot(forward) / row_spacing_m, d.dot(starboard) / bin_size_m + columns_per_side - 0.5};
}

GeoImage render(const Seabed& seabed, const SurveyLine& line, const RenderOptions& options) {
  const int cols = 2 * line.columns_per_side;
  GeoImage image;
  image.intensity.create(line.rows, cols);
  image.valid.create(line.rows, cols);
  image.position_ne_m.create(line.rows, cols);
  image.heading_rad = cv::Mat1f(line.rows, 1, static_cast<float>(line.heading_rad));
  const int samples = std::max(1, options.footprint_samples);
  const double nadir_column = line.columns_per_side - 0.5;
  for (int r = 0; r < line.rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      double sum = 0.0;
      for (int s = 0; s < samples; ++s) {
        // The beam footprint spans about one ping spacing along track.
        const double row = r + (s + 0.5) / samples - 0.5;
        const Eigen::Vector2d p = line.position(row, c);
        sum += seabed.backscatter(p, line.position(row, nadir_column), options.altitude_m);
      }
      const std::uint64_t h = mix(options.speckle_seed ^ mix(static_cast<std::uint64_t>(r) * 100003ULL + c));
      const double speckle = std::max(0.05, 1.0 + options.speckle_stddev * gaussian(h));
      image.intensity(r, c) = static_cast<float>(options.gain * speckle * sum / samples);
      const Eigen::Vector2d p = line.position(r, c);
      image.position_ne_m(r, c) = cv::Vec2f(static_cast<float>(p.x()), static_cast<float>(p.y()));
      image.valid(r, c) = std::abs(c + 0.5 - line.columns_per_side) < line.nadir_bins ? 0 : 255;
    }
  }
  return image;
}

void addDrError(GeoImage& image, const Eigen::Vector2d& shift_ne_m, double rotation_rad) {
  const cv::Vec2f centre = image.position_ne_m(image.position_ne_m.rows / 2, image.position_ne_m.cols / 2);
  const double c = std::cos(rotation_rad), s = std::sin(rotation_rad);
  for (int r = 0; r < image.position_ne_m.rows; ++r) {
    for (int col = 0; col < image.position_ne_m.cols; ++col) {
      const cv::Vec2f d = image.position_ne_m(r, col) - centre;
      image.position_ne_m(r, col) =
          cv::Vec2f(static_cast<float>(centre[0] + c * d[0] - s * d[1] + shift_ne_m.x()),
                    static_cast<float>(centre[1] + s * d[0] + c * d[1] + shift_ne_m.y()));
    }
  }
}

void maskRows(GeoImage& image, int first_row, int last_row) {
  for (int r = std::max(0, first_row); r <= std::min(last_row, image.valid.rows - 1); ++r) image.valid.row(r).setTo(0);
}

SurveyLine secondLine(const SurveyLine& a, Direction direction, double line_spacing_m, double along_track_shift_m) {
  SurveyLine b = a;
  const Eigen::Vector2d forward(std::cos(a.heading_rad), std::sin(a.heading_rad));
  const Eigen::Vector2d starboard(-std::sin(a.heading_rad), std::cos(a.heading_rad));
  b.start_ne_m = a.start_ne_m + line_spacing_m * starboard + along_track_shift_m * forward;
  if (direction == Direction::kAntiParallel) {
    b.heading_rad = a.heading_rad + M_PI;
    b.start_ne_m += (a.rows - 1) * a.row_spacing_m * forward;
  }
  return b;
}

Evaluation evaluate(const std::vector<Correspondence>& matches, const SurveyLine& line_a, const GeoImage& a,
                    const SurveyLine& line_b, const GeoImage& b, int stride, int patch_size, double tolerance_px) {
  Evaluation result;
  result.matches = static_cast<long>(matches.size());
  for (const Correspondence& m : matches) {
    const Eigen::Vector2d truth = line_b.pixel(line_a.position(m.row_a, m.col_a));
    if (std::hypot(truth.x() - m.row_b, truth.y() - m.col_b) <= tolerance_px) ++result.within_tolerance;
  }
  const int half = patch_size / 2;
  for (int r = 0; r < a.valid.rows; r += stride) {
    for (int c = 0; c < a.valid.cols; c += stride) {
      if (!a.valid(r, c)) continue;
      const Eigen::Vector2d truth = line_b.pixel(line_a.position(r, c));
      const int br = static_cast<int>(std::lround(truth.x())), bc = static_cast<int>(std::lround(truth.y()));
      if (br < half || bc < half || br >= b.valid.rows - half || bc >= b.valid.cols - half) continue;
      if (b.valid(br, bc)) ++result.matchable;
    }
  }
  return result;
}

}  // namespace sss::matcher::synthetic
