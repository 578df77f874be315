// Dense matching of two geo-referenced side-scan images: DR-initialised PatchMatch with a masked
// ZNCC patch distance (paper Sec. "Data Association", Alg. 1), at any relative heading.
#include "pipeline/matcher/dense_matcher.hpp"

#include <nanoflann.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>

namespace sss::matcher {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

constexpr float kNoScore = -2.0f;  // below any ZNCC: "no usable patch pair"
// Rows of lattice nodes one task of the PatchMatch sweep owns. Fixed (not derived from the thread
// count) so the result does not depend on how many threads run it.
constexpr int kBandRows = 8;

// Runs task(i) for i in [0, count) on up to `threads` threads; tasks are claimed in order.
void parallelFor(int count, int threads, const std::function<void(int)>& task) {
  const int workers = std::max(1, std::min(threads, count));
  if (workers == 1) {
    for (int i = 0; i < count; ++i) task(i);
    return;
  }
  std::atomic<int> next{0};
  auto worker = [&]() {
    for (int i = next++; i < count; i = next++) task(i);
  };
  std::vector<std::thread> pool;
  pool.reserve(workers - 1);
  for (int t = 1; t < workers; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& thread : pool) thread.join();
}

// splitmix64: a counter-based generator, so every (pixel, iteration) has its own stream and the
// random search does not depend on the order in which threads visit pixels.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}
struct Random {
  std::uint64_t state;
  // Uniform in [-1, 1).
  float symmetric() {
    state = mix(state);
    return static_cast<float>(static_cast<double>(state >> 11) * (2.0 / 9007199254740992.0) - 1.0);
  }
};

void checkImage(const GeoImage& image, const char* name) {
  const std::string prefix = std::string("DenseMatcher::match: image ") + name + ": ";
  if (image.intensity.empty()) throw std::invalid_argument(prefix + "intensity is empty");
  if (image.valid.size() != image.intensity.size())
    throw std::invalid_argument(prefix + "valid mask size differs from the intensity size");
  if (image.position_ne_m.size() != image.intensity.size())
    throw std::invalid_argument(prefix + "position_ne_m size differs from the intensity size");
}

// Median distance between neighbouring pixels along rows (pings) and along columns (bins), from
// the geo-reference: converts the DR error in metres into a search window in pixels.
cv::Vec2d pixelSpacing(const cv::Mat2f& position) {
  std::vector<double> along_rows, along_columns;
  const int step_r = std::max(1, position.rows / 32), step_c = std::max(1, position.cols / 32);
  for (int r = 0; r + 1 < position.rows; r += step_r) {
    for (int c = 0; c + 1 < position.cols; c += step_c) {
      along_rows.push_back(cv::norm(position(r + 1, c) - position(r, c)));
      along_columns.push_back(cv::norm(position(r, c + 1) - position(r, c)));
    }
  }
  auto median = [](std::vector<double>& v) {
    if (v.empty()) return 1.0;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return std::max(v[v.size() / 2], 1e-6);
  };
  return {median(along_rows), median(along_columns)};
}

// Derivatives of the geo-reference with respect to row and column at an in-image pixel
// (one-sided at the borders).
void positionJacobian(const cv::Mat2f& position, int r, int c, cv::Vec2f& d_row, cv::Vec2f& d_col) {
  const int r0 = r + 1 < position.rows ? r : r - 1, c0 = c + 1 < position.cols ? c : c - 1;
  d_row = position.rows > 1 ? position(r0 + 1, c) - position(r0, c) : cv::Vec2f(0, 0);
  d_col = position.cols > 1 ? position(r, c0 + 1) - position(r, c0) : cv::Vec2f(0, 0);
}

// Whether A's pixel (ra, ca) and B's pixel (rb, cb) see their seabed point from opposite sides,
// within 45 degrees: the look direction of a column is away from nadir (port columns are the left
// half, starboard the right), along the geo-reference's column axis.
bool opposedLooks(const GeoImage& a, int ra, int ca, const GeoImage& b, int rb, int cb) {
  cv::Vec2f d_row, col_a, col_b;
  positionJacobian(a.position_ne_m, ra, ca, d_row, col_a);
  positionJacobian(b.position_ne_m, rb, cb, d_row, col_b);
  const float side_a = 2 * ca >= a.intensity.cols ? 1.0f : -1.0f;
  const float side_b = 2 * cb >= b.intensity.cols ? 1.0f : -1.0f;
  const float norms = static_cast<float>(cv::norm(col_a) * cv::norm(col_b));
  if (!(norms > 0.0f)) return false;
  return side_a * side_b * col_a.dot(col_b) < -0.70710678f * norms;
}

// Of a patch's contrast about its mean (sum of squared deviations over its valid pixels), the share
// on raised features' pixels.
// Whether a patch holds a raised feature's pixel (grid_relief 255).
bool patchHasRelief(const cv::Mat1b& grid_relief, int r, int c, int half) {
  for (int y = r - half; y <= r + half; ++y) {
    const std::uint8_t* row = grid_relief.ptr<std::uint8_t>(y);
    for (int x = c - half; x <= c + half; ++x)
      if (row[x]) return true;
  }
  return false;
}

// Valid geo-referenced pixels of B as a nanoflann point cloud (positions relative to an origin,
// so float keeps millimetres far from the mission origin).
struct PointCloud {
  std::vector<float> xy;
  std::vector<std::int32_t> pixel;  // row * cols + col
  std::size_t kdtree_get_point_count() const { return pixel.size(); }
  float kdtree_get_pt(std::size_t i, std::size_t dim) const { return xy[2 * i + dim]; }
  template <class BoundingBox>
  bool kdtree_get_bbox(BoundingBox&) const {
    return false;
  }
};
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointCloud>, PointCloud, 2,
                                                   std::uint32_t>;

// An image on the common (padded) pixel grid of A, with the per-patch statistics the fast ZNCC
// path needs. value is 0 and weight 0 where the image is invalid.
struct GridImage {
  cv::Mat1f value;
  cv::Mat1f weight;
  cv::Mat1f mean;      // patch mean where the whole patch is valid
  cv::Mat1f inv_norm;  // 1 / (n * stddev) where the whole patch is valid and textured, else 0
  cv::Mat1b state;     // kPartial, kFull or kFlat
};
enum PatchState : std::uint8_t { kPartial = 0, kFull = 1, kFlat = 2 };

// Per pixel, the ratio of the small to the large eigenvalue of the structure tensor (intensity
// gradient outer products summed over a patch_size box): ~0 for one straight edge or line, up to
// 1 for texture that varies in every direction.
cv::Mat1f structureRatio(const cv::Mat1f& image, int patch_size) {
  cv::Mat1f gx, gy;
  cv::Sobel(image, gx, CV_32F, 1, 0, 3);
  cv::Sobel(image, gy, CV_32F, 0, 1, 3);
  cv::Mat1f jxx, jyy, jxy;
  const cv::Size box(patch_size, patch_size);
  cv::boxFilter(gx.mul(gx), jxx, CV_32F, box);
  cv::boxFilter(gy.mul(gy), jyy, CV_32F, box);
  cv::boxFilter(gx.mul(gy), jxy, CV_32F, box);
  cv::Mat1f ratio(image.size(), 0.0f);
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) {
      const float trace = jxx(r, c) + jyy(r, c);
      const float det = jxx(r, c) * jyy(r, c) - jxy(r, c) * jxy(r, c);
      const float root = std::sqrt(std::max(trace * trace - 4.0f * det, 0.0f));
      if (trace + root > 1e-12f) ratio(r, c) = std::max(trace - root, 0.0f) / (trace + root);
    }
  }
  return ratio;
}

void computePatchStatistics(GridImage& image, int half, double min_stddev) {
  cv::Mat1d sum, sum_sq, count;
  const cv::Mat1f weighted = image.value.mul(image.weight);
  cv::integral(weighted, sum, sum_sq, CV_64F, CV_64F);
  cv::integral(image.weight, count, CV_64F);
  const int rows = image.value.rows, cols = image.value.cols, size = 2 * half + 1;
  const double n = static_cast<double>(size) * size;
  image.mean.create(rows, cols);
  image.inv_norm.create(rows, cols);
  image.state.create(rows, cols);
  image.mean.setTo(0.0f);
  image.inv_norm.setTo(0.0f);
  image.state.setTo(kPartial);
  auto box = [&](const cv::Mat1d& integral, int r, int c) {
    return integral(r + half + 1, c + half + 1) - integral(r - half, c + half + 1) - integral(r + half + 1, c - half) +
           integral(r - half, c - half);
  };
  for (int r = half; r < rows - half; ++r) {
    for (int c = half; c < cols - half; ++c) {
      if (box(count, r, c) < n - 0.5) continue;
      const double mean = box(sum, r, c) / n;
      const double variance = std::max(0.0, box(sum_sq, r, c) / n - mean * mean);
      const double stddev = std::sqrt(variance);
      image.mean(r, c) = static_cast<float>(mean);
      if (stddev < min_stddev) {
        image.state(r, c) = kFlat;
      } else {
        image.state(r, c) = kFull;
        image.inv_norm(r, c) = static_cast<float>(1.0 / (n * stddev));
      }
    }
  }
}

// ZNCC between the patch of `source` centred at (sr, sc) and the patch of `target` at (tr, tc),
// on pixels valid in both (paper: ZNCC is invariant to the gain and offset changes near nadir
// and far range). Both centres must be at least `half` pixels inside the grid.
class PatchScorer {
 public:
  // inverted: the score is -ZNCC (A against B's contrast inverted; see reject_inverted_relief).
  PatchScorer(const GridImage& source, const GridImage& target, int half, double min_valid_fraction,
              double min_stddev, bool inverted = false)
      : source_(source), target_(target), half_(half), size_(2 * half + 1), inverted_(inverted) {
    min_count_ = static_cast<float>(min_valid_fraction * size_ * size_);
    min_variance_ = static_cast<float>(min_stddev * min_stddev);
  }

  float operator()(int sr, int sc, int tr, int tc) const {
    const float zncc = plain(sr, sc, tr, tc);
    return inverted_ && zncc > kNoScore ? -zncc : zncc;
  }

 private:
  float plain(int sr, int sc, int tr, int tc) const {
    const std::uint8_t s_state = source_.state(sr, sc), t_state = target_.state(tr, tc);
    if (s_state == kFlat || t_state == kFlat) return kNoScore;
    if (s_state == kFull && t_state == kFull) return full(sr, sc, tr, tc);
    return masked(sr, sc, tr, tc);
  }

  float full(int sr, int sc, int tr, int tc) const {
    // Per-column accumulators: independent lanes the compiler vectorises without reordering sums.
    float acc[32] = {};
    for (int i = -half_; i <= half_; ++i) {
      const float* s = source_.value.ptr<float>(sr + i) + sc - half_;
      const float* t = target_.value.ptr<float>(tr + i) + tc - half_;
      for (int j = 0; j < size_; ++j) acc[j] += s[j] * t[j];
    }
    float cross = 0.0f;
    for (int j = 0; j < size_; ++j) cross += acc[j];
    const float n = static_cast<float>(size_ * size_);
    return (cross - n * source_.mean(sr, sc) * target_.mean(tr, tc)) * source_.inv_norm(sr, sc) *
           target_.inv_norm(tr, tc) * n;
  }

  float masked(int sr, int sc, int tr, int tc) const {
    float n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    for (int i = -half_; i <= half_; ++i) {
      const float* s = source_.value.ptr<float>(sr + i) + sc - half_;
      const float* sw = source_.weight.ptr<float>(sr + i) + sc - half_;
      const float* t = target_.value.ptr<float>(tr + i) + tc - half_;
      const float* tw = target_.weight.ptr<float>(tr + i) + tc - half_;
      for (int j = 0; j < size_; ++j) {
        const float w = sw[j] * tw[j];
        n += w;
        sx += w * s[j];
        sy += w * t[j];
        sxx += w * s[j] * s[j];
        syy += w * t[j] * t[j];
        sxy += w * s[j] * t[j];
      }
    }
    if (n < min_count_) return kNoScore;
    const float mx = sx / n, my = sy / n;
    const float vx = sxx / n - mx * mx, vy = syy / n - my * my;
    if (vx < min_variance_ || vy < min_variance_) return kNoScore;
    return (sxy / n - mx * my) / std::sqrt(vx * vy);
  }

  const GridImage& source_;
  const GridImage& target_;
  int half_;
  int size_;
  bool inverted_;
  float min_count_;
  float min_variance_;
};

// The best ZNCC of A's patch at (sr, sc) with B's patch at (tr, tc) mirrored along the columns
// (the look direction on A's grid) about any point of it, in half-pixel steps: a raised feature's
// two views are mirror images about the feature, which need not be the patch centre
// (DenseMatcherOptions::reject_mirrored_relief). `score_mirrored` scores A against B's grid
// flipped left-right, where B mirrored about column m is the plain patch at column cols - 1 - m.
float bestMirroredScore(const PatchScorer& score_mirrored, int sr, int sc, int tr, int tc, int half, int grid_cols) {
  float best = kNoScore;
  for (int m = tc - 2 * half; m <= tc + 2 * half; ++m) {  // mirror point (tc + m) / 2
    if (m - half < 0 || m + half >= grid_cols) continue;
    best = std::max(best, score_mirrored(sr, sc, tr, grid_cols - 1 - m));
  }
  return best;
}

// A nearest-neighbour field over a lattice of source pixels (every stride-th grid pixel from
// (row0, col0)): offset to the best target pixel found so far and its ZNCC.
struct Field {
  int row0 = 0, col0 = 0, rows = 0, cols = 0, stride = 1;
  std::vector<std::uint8_t> active;
  std::vector<std::int16_t> d_row, d_col;
  std::vector<float> score;
  int index(int i, int j) const { return i * cols + j; }
  int gridRow(int i) const { return row0 + i * stride; }
  int gridCol(int j) const { return col0 + j * stride; }
};

struct SearchWindow {
  int rows = 0;  // |offset row| <= rows
  int cols = 0;
};

// PatchMatch (Barnes et al. 2009) as modified by the paper: the field starts at zero offset, i.e.
// at the geo-referenced nearest pixel (Sec. "Initialization"), random search stays within the
// search window around it (Sec. "Random Search"), propagation takes a neighbour's offset when it
// scores better (eq. "ppg"); the scan direction alternates every iteration.
void runPatchMatch(Field& field, const PatchScorer& score, const SearchWindow& window, int grid_rows, int grid_cols,
                   int half, const DenseMatcherOptions& options, std::uint64_t stream) {
  const int bands = (field.rows + kBandRows - 1) / kBandRows;
  auto targetInside = [&](int tr, int tc) {
    return tr >= half && tc >= half && tr < grid_rows - half && tc < grid_cols - half;
  };
  // Initialisation: zero offset, i.e. the DR-predicted pixel.
  parallelFor(bands, options.threads, [&](int band) {
    for (int i = band * kBandRows; i < std::min(field.rows, (band + 1) * kBandRows); ++i) {
      for (int j = 0; j < field.cols; ++j) {
        const int k = field.index(i, j);
        field.d_row[k] = field.d_col[k] = 0;
        field.score[k] = field.active[k] ? score(field.gridRow(i), field.gridCol(j), field.gridRow(i), field.gridCol(j))
                                         : kNoScore;
      }
    }
  });

  long active = 0;
  for (std::uint8_t a : field.active) active += a;
  std::vector<std::int16_t> previous_row, previous_col;  // neighbours across band borders
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    previous_row = field.d_row;
    previous_col = field.d_col;
    std::vector<int> updates(bands, 0);
    const bool forward = iteration % 2 == 0;
    const int step = forward ? -1 : 1;  // neighbours already visited in this scan
    parallelFor(bands, options.threads, [&](int band) {
      const int first = band * kBandRows, last = std::min(field.rows, (band + 1) * kBandRows) - 1;
      for (int ii = 0; ii <= last - first; ++ii) {
        const int i = forward ? first + ii : last - ii;
        for (int jj = 0; jj < field.cols; ++jj) {
          const int j = forward ? jj : field.cols - 1 - jj;
          const int k = field.index(i, j);
          if (!field.active[k]) continue;
          const int sr = field.gridRow(i), sc = field.gridCol(j);
          int best_r = field.d_row[k], best_c = field.d_col[k];
          float best = field.score[k];
          auto tryOffset = [&](int dr, int dc) {
            if (dr == best_r && dc == best_c) return;
            if (std::abs(dr) > window.rows || std::abs(dc) > window.cols) return;
            if (!targetInside(sr + dr, sc + dc)) return;
            const float s = score(sr, sc, sr + dr, sc + dc);
            if (s > best) {
              best = s;
              best_r = dr;
              best_c = dc;
            }
          };
          // Propagation from the neighbour in the previous column and row of this scan.
          const int nj = j + step, ni = i + step;
          if (nj >= 0 && nj < field.cols) {
            const int n = field.index(i, nj);
            if (field.active[n]) tryOffset(field.d_row[n], field.d_col[n]);
          }
          if (ni >= 0 && ni < field.rows) {
            const int n = field.index(ni, j);
            const bool same_band = ni >= first && ni <= last;
            if (field.active[n])
              tryOffset(same_band ? field.d_row[n] : previous_row[n], same_band ? field.d_col[n] : previous_col[n]);
          }
          // Random search in a window halving around the current best (Barnes et al.).
          Random random{mix(options.seed ^ mix(stream + static_cast<std::uint64_t>(iteration) * 0x1000193ULL) ^
                            static_cast<std::uint64_t>(k))};
          double radius_r = window.rows, radius_c = window.cols;
          while (radius_r >= 1.0 || radius_c >= 1.0) {
            const int dr = best_r + static_cast<int>(std::lround(radius_r * random.symmetric()));
            const int dc = best_c + static_cast<int>(std::lround(radius_c * random.symmetric()));
            tryOffset(std::clamp(dr, -window.rows, window.rows), std::clamp(dc, -window.cols, window.cols));
            radius_r *= options.random_search_ratio;
            radius_c *= options.random_search_ratio;
          }
          if (best_r != field.d_row[k] || best_c != field.d_col[k]) ++updates[band];
          field.d_row[k] = static_cast<std::int16_t>(best_r);
          field.d_col[k] = static_cast<std::int16_t>(best_c);
          field.score[k] = best;
        }
      }
    });
    // Converged: the paper's fixed 10 rounds mostly re-confirm the field after the first few.
    long changed = 0;
    for (int u : updates) changed += u;
    if (changed < options.min_update_fraction * static_cast<double>(active)) break;
  }
}

// Offset of the vertex of the parabola through (-1, minus), (0, centre), (1, plus), in [-0.5, 0.5].
float parabolaPeak(float minus, float centre, float plus) {
  if (minus <= kNoScore || plus <= kNoScore) return 0.0f;
  const float curvature = minus - 2.0f * centre + plus;
  if (curvature >= 0.0f) return 0.0f;
  return std::clamp(0.5f * (minus - plus) / curvature, -0.5f, 0.5f);
}

// How much ZNCC the best score of A's patch at (sr, sc) over the search window stands above the
// top of any separate peak (DenseMatcherOptions::min_peak_margin). The window's cells join, in
// descending score, their already joined 8-neighbours (union-find, i.e. the superlevel sets from
// the top down); the first cell that is then not in the best cell's component tops a second peak.
// A shoulder of the best peak joins it and is not counted. Zero or negative when the window's best
// lies more than a cell from (dr, dc), the offset PatchMatch settled on; 2 when no other peak exists.
float peakMargin(const PatchScorer& score, int sr, int sc, int dr, int dc, const SearchWindow& window, int grid_rows,
                 int grid_cols, int half) {
  const int height = 2 * window.rows + 1, width = 2 * window.cols + 1;
  std::vector<float> scores(static_cast<std::size_t>(height) * width, kNoScore);
  std::vector<int> order;
  order.reserve(scores.size());
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const int tr = sr + y - window.rows, tc = sc + x - window.cols;
      if (tr < half || tc < half || tr >= grid_rows - half || tc >= grid_cols - half) continue;
      const float s = score(sr, sc, tr, tc);
      if (s <= kNoScore) continue;
      scores[y * width + x] = s;
      order.push_back(y * width + x);
    }
  }
  const int found = (dr + window.rows) * width + (dc + window.cols);
  if (order.empty() || scores[found] <= kNoScore) return -2.0f;
  std::sort(order.begin(), order.end(), [&](int p, int q) { return scores[p] > scores[q] || (scores[p] == scores[q] && p < q); });
  const int best = order.front();
  if (std::abs(best / width - found / width) > 1 || std::abs(best % width - found % width) > 1)
    return scores[found] - scores[best];
  std::vector<int> parent(scores.size(), -1);  // -1: not joined yet
  auto root = [&](int p) {
    while (parent[p] != p) p = parent[p] = parent[parent[p]];
    return p;
  };
  for (const int cell : order) {
    parent[cell] = cell;
    const int y = cell / width, x = cell % width;
    for (int ny = std::max(0, y - 1); ny <= std::min(height - 1, y + 1); ++ny) {
      for (int nx = std::max(0, x - 1); nx <= std::min(width - 1, x + 1); ++nx) {
        const int neighbour = ny * width + nx;
        if (neighbour != cell && parent[neighbour] >= 0) parent[root(neighbour)] = root(cell);
      }
    }
    if (cell != best && root(cell) != root(best)) return scores[best] - scores[cell];
  }
  return 2.0f;
}

}  // namespace

cv::Mat1b findReliefFeatures(const GeoImage& image, double outlier_sigmas) {
  std::vector<float> logs;
  logs.reserve(image.intensity.total());
  float largest = 0.0f;
  for (int r = 0; r < image.intensity.rows; ++r)
    for (int c = 0; c < image.intensity.cols; ++c)
      if (image.valid(r, c)) largest = std::max(largest, image.intensity(r, c));
  // A shadow holds no echo: its intensity may be 0. Floored far below any echo, so it stays an outlier.
  const float floor = std::max(1e-30f, 1e-6f * largest);
  auto logOf = [floor](float v) { return std::log(std::max(v, floor)); };
  for (int r = 0; r < image.intensity.rows; ++r)
    for (int c = 0; c < image.intensity.cols; ++c)
      if (image.valid(r, c)) logs.push_back(logOf(image.intensity(r, c)));
  if (logs.size() < 100) return {};
  const auto middle = logs.begin() + static_cast<std::ptrdiff_t>(logs.size() / 2);
  std::nth_element(logs.begin(), middle, logs.end());
  const float median = *middle;
  for (float& v : logs) v = std::abs(v - median);
  std::nth_element(logs.begin(), middle, logs.end());
  const float sigma = 1.4826f * *middle;
  cv::Mat1b relief = cv::Mat1b::zeros(image.intensity.rows, image.intensity.cols);
  if (!(sigma > 0.0f)) return relief;
  const float limit = static_cast<float>(outlier_sigmas) * sigma;
  for (int r = 0; r < image.intensity.rows; ++r)
    for (int c = 0; c < image.intensity.cols; ++c)
      if (image.valid(r, c) && std::abs(logOf(image.intensity(r, c)) - median) > limit) relief(r, c) = 255;
  cv::dilate(relief, relief, cv::Mat1b::ones(3, 3));
  return relief;
}

DenseMatcher::DenseMatcher(DenseMatcherOptions options) : options_(options) {
  const std::vector<std::string> problems = validateDenseMatcherOptions(options_);
  if (!problems.empty()) throw std::invalid_argument("DenseMatcherOptions: " + problems.front());
}

std::vector<Correspondence> DenseMatcher::match(const GeoImage& a, const GeoImage& b, MatchTimings* timings) const {
  checkImage(a, "A");
  checkImage(b, "B");
  MatchTimings local;
  MatchTimings& t = timings ? *timings : local;
  t = MatchTimings{};
  const auto start = Clock::now();
  const DenseMatcherOptions& o = options_;
  const int half = o.patch_size / 2;

  // ---- kd-tree over B's valid geo-referenced pixels (paper Sec. "Initialization") -------------
  auto stage = Clock::now();
  PointCloud cloud;
  cv::Vec2f origin(0, 0);
  for (int r = 0; r < b.valid.rows; ++r) {
    for (int c = 0; c < b.valid.cols; ++c) {
      if (!b.valid(r, c)) continue;
      if (cloud.pixel.empty()) origin = b.position_ne_m(r, c);
      const cv::Vec2f p = b.position_ne_m(r, c) - origin;
      cloud.xy.push_back(p[0]);
      cloud.xy.push_back(p[1]);
      cloud.pixel.push_back(r * b.valid.cols + c);
    }
  }
  if (cloud.pixel.empty()) {
    t.total_s = secondsSince(start);
    return {};
  }
  const KdTree tree(2, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  t.kd_tree_s = secondsSince(stage);

  // ---- B resampled onto A's pixel grid through the geo-reference -----------------------------
  // Comparing patches on A's grid puts both in a common orientation whatever the relative
  // heading: an anti-parallel line (rows reversed, port and starboard swapped) or a crossing
  // line is resampled so that its patches look like A's, which the reference implementation did
  // not do (measured: 6 % of its anti-parallel matches were within 2 px). The grid is padded by the
  // search window so pixels at A's border can reach B content beyond A's footprint.
  stage = Clock::now();
  const cv::Vec2d spacing_m = pixelSpacing(a.position_ne_m);
  SearchWindow window;
  window.rows = static_cast<int>(std::ceil(o.max_offset_px + o.max_dr_error_m / spacing_m[0]));
  window.cols = static_cast<int>(std::ceil(o.max_offset_px + o.max_dr_error_m / spacing_m[1]));
  window.rows = std::min(window.rows, 2000);
  window.cols = std::min(window.cols, 2000);
  const int pad_r = window.rows + half + 1, pad_c = window.cols + half + 1;
  const int grid_rows = a.intensity.rows + 2 * pad_r, grid_cols = a.intensity.cols + 2 * pad_c;

  GridImage grid_a, grid_b;
  grid_a.value = cv::Mat1f::zeros(grid_rows, grid_cols);
  grid_a.weight = cv::Mat1f::zeros(grid_rows, grid_cols);
  for (int r = 0; r < a.intensity.rows; ++r) {
    for (int c = 0; c < a.intensity.cols; ++c) {
      if (!a.valid(r, c)) continue;
      grid_a.value(r + pad_r, c + pad_c) = a.intensity(r, c);
      grid_a.weight(r + pad_r, c + pad_c) = 1.0f;
    }
  }
  grid_b.value = cv::Mat1f::zeros(grid_rows, grid_cols);
  grid_b.weight = cv::Mat1f::zeros(grid_rows, grid_cols);
  // Raised features' pixels on the grid (marked, or dropped with reject_shadowed_relief), B's
  // where any of the four pixels of its bilinear sample is one.
  const bool test_relief = !a.relief.empty() && !b.relief.empty();
  cv::Mat1b relief_a, relief_b;
  if (test_relief) {
    relief_a = cv::Mat1b::zeros(grid_rows, grid_cols);
    a.relief.copyTo(relief_a(cv::Rect(pad_c, pad_r, a.intensity.cols, a.intensity.rows)));
    relief_b = cv::Mat1b::zeros(grid_rows, grid_cols);
  }
  cv::Mat2f map_to_b(grid_rows, grid_cols, cv::Vec2f(-1.0f, -1.0f));  // continuous (row, col) in B
  cv::Mat1b has_map = cv::Mat1b::zeros(grid_rows, grid_cols);
  const float max_distance_sq = static_cast<float>(o.max_init_distance_m * o.max_init_distance_m);
  const int bands = (grid_rows + kBandRows - 1) / kBandRows;
  parallelFor(bands, o.threads, [&](int band) {
    for (int gr = band * kBandRows; gr < std::min(grid_rows, (band + 1) * kBandRows); ++gr) {
      for (int gc = 0; gc < grid_cols; ++gc) {
        // A's geo-reference, extrapolated linearly into the padding.
        const int ar = gr - pad_r, ac = gc - pad_c;
        const int cr = std::clamp(ar, 0, a.intensity.rows - 1), cc = std::clamp(ac, 0, a.intensity.cols - 1);
        cv::Vec2f p = a.position_ne_m(cr, cc);
        if (cr != ar || cc != ac) {
          cv::Vec2f d_row, d_col;
          positionJacobian(a.position_ne_m, cr, cc, d_row, d_col);
          p += d_row * static_cast<float>(ar - cr) + d_col * static_cast<float>(ac - cc);
        }
        p -= origin;
        std::uint32_t nearest = 0;
        float distance_sq = 0.0f;
        tree.knnSearch(&p[0], 1, &nearest, &distance_sq);
        if (distance_sq > max_distance_sq) continue;
        // Sub-pixel position in B: one Newton step on B's local affine geo-reference.
        const int br = cloud.pixel[nearest] / b.valid.cols, bc = cloud.pixel[nearest] % b.valid.cols;
        cv::Vec2f d_row, d_col;
        positionJacobian(b.position_ne_m, br, bc, d_row, d_col);
        const cv::Vec2f residual = p - (b.position_ne_m(br, bc) - origin);
        const float det = d_row[0] * d_col[1] - d_row[1] * d_col[0];
        float row_b = static_cast<float>(br), col_b = static_cast<float>(bc);
        if (std::abs(det) > 1e-9f) {
          row_b += std::clamp((residual[0] * d_col[1] - residual[1] * d_col[0]) / det, -1.0f, 1.0f);
          col_b += std::clamp((d_row[0] * residual[1] - d_row[1] * residual[0]) / det, -1.0f, 1.0f);
        }
        map_to_b(gr, gc) = cv::Vec2f(row_b, col_b);
        has_map(gr, gc) = 1;
        // Bilinear resampling; only where all four pixels are valid, so masks stay masks.
        const int r0 = static_cast<int>(std::floor(row_b)), c0 = static_cast<int>(std::floor(col_b));
        if (r0 < 0 || c0 < 0 || r0 + 1 >= b.intensity.rows || c0 + 1 >= b.intensity.cols) continue;
        if (!b.valid(r0, c0) || !b.valid(r0 + 1, c0) || !b.valid(r0, c0 + 1) || !b.valid(r0 + 1, c0 + 1)) continue;
        const float fr = row_b - r0, fc = col_b - c0;
        grid_b.value(gr, gc) = (1 - fr) * ((1 - fc) * b.intensity(r0, c0) + fc * b.intensity(r0, c0 + 1)) +
                               fr * ((1 - fc) * b.intensity(r0 + 1, c0) + fc * b.intensity(r0 + 1, c0 + 1));
        grid_b.weight(gr, gc) = 1.0f;
        if (test_relief && (b.relief(r0, c0) || b.relief(r0 + 1, c0) || b.relief(r0, c0 + 1) || b.relief(r0 + 1, c0 + 1)))
          relief_b(gr, gc) = 255;
      }
    }
  });
  computePatchStatistics(grid_a, half, o.min_patch_stddev);
  computePatchStatistics(grid_b, half, o.min_patch_stddev);
  GridImage grid_b_mirrored;  // B's grid flipped left-right, for the mirror test
  if (o.reject_mirrored_relief) {
    cv::flip(grid_b.value, grid_b_mirrored.value, 1);
    cv::flip(grid_b.weight, grid_b_mirrored.weight, 1);
    computePatchStatistics(grid_b_mirrored, half, o.min_patch_stddev);
  }
  const cv::Mat1f structure_ratio_a =
      o.min_structure_ratio > 0.0 ? structureRatio(grid_a.value, 2 * half + 1) : cv::Mat1f();

  // Forward field: every stride-th valid pixel of A that has a geo-referenced B pixel nearby.
  Field forward;
  forward.stride = o.stride;
  forward.row0 = pad_r;
  forward.col0 = pad_c;
  forward.rows = (a.intensity.rows + o.stride - 1) / o.stride;
  forward.cols = (a.intensity.cols + o.stride - 1) / o.stride;
  const std::size_t forward_nodes = static_cast<std::size_t>(forward.rows) * forward.cols;
  forward.active.assign(forward_nodes, 0);
  forward.d_row.assign(forward_nodes, 0);
  forward.d_col.assign(forward_nodes, 0);
  forward.score.assign(forward_nodes, kNoScore);
  for (int i = 0; i < forward.rows; ++i) {
    for (int j = 0; j < forward.cols; ++j) {
      const int gr = forward.gridRow(i), gc = forward.gridCol(j);
      if (grid_a.weight(gr, gc) > 0.0f && has_map(gr, gc)) {
        forward.active[forward.index(i, j)] = 1;
        ++t.overlapping_pixels;
      }
    }
  }
  t.initialisation_s = secondsSince(stage);
  if (t.overlapping_pixels == 0) {
    t.total_s = secondsSince(start);
    return {};
  }

  // ---- PatchMatch A -> B ---------------------------------------------------------------------
  stage = Clock::now();
  const PatchScorer score_ab(grid_a, grid_b, half, o.min_valid_fraction, o.min_patch_stddev);
  const PatchScorer score_mirrored(grid_a, o.reject_mirrored_relief ? grid_b_mirrored : grid_b, half,
                                   o.min_valid_fraction, o.min_patch_stddev);
  runPatchMatch(forward, score_ab, window, grid_rows, grid_cols, half, o, 0x5A5A0001ULL);

  // ---- the same nodes against B's contrast inverted, where the looks are opposed --------------
  Field inverted;
  if (o.reject_inverted_relief) {
    inverted = forward;
    long opposed_nodes = 0;
    for (int i = 0; i < forward.rows; ++i) {
      for (int j = 0; j < forward.cols; ++j) {
        const int k = forward.index(i, j);
        inverted.active[k] = 0;
        if (!forward.active[k] || forward.score[k] < o.min_zncc) continue;
        const int gr = forward.gridRow(i), gc = forward.gridCol(j);
        const cv::Vec2f in_b = map_to_b(gr, gc);
        const int br = std::clamp(static_cast<int>(std::lround(in_b[0])), 0, b.intensity.rows - 1);
        const int bc = std::clamp(static_cast<int>(std::lround(in_b[1])), 0, b.intensity.cols - 1);
        if (!opposedLooks(a, gr - pad_r, gc - pad_c, b, br, bc)) continue;
        inverted.active[k] = 1;
        ++opposed_nodes;
      }
    }
    if (opposed_nodes > 0) {
      const PatchScorer score_inverted(grid_a, grid_b, half, o.min_valid_fraction, o.min_patch_stddev, true);
      runPatchMatch(inverted, score_inverted, window, grid_rows, grid_cols, half, o, 0x1A1A0003ULL);
    }
  }
  t.patch_match_s = secondsSince(stage);

  // ---- forward-backward consistency, sub-pixel refinement, thresholds ------------------------
  stage = Clock::now();
  Field backward;
  const PatchScorer score_ba(grid_b, grid_a, half, o.min_valid_fraction, o.min_patch_stddev);
  if (o.forward_backward_check) {
    // B (on A's grid) -> A over the part of the grid that forward matches can land in; a match
    // survives only if B's own best match points back to where it came from (ambiguous texture
    // and repetitive patterns fail this, correct matches pass it).
    backward.stride = o.stride;
    backward.row0 = half;
    backward.col0 = half;
    backward.rows = (grid_rows - 2 * half + o.stride - 1) / o.stride;
    backward.cols = (grid_cols - 2 * half + o.stride - 1) / o.stride;
    const std::size_t nodes = static_cast<std::size_t>(backward.rows) * backward.cols;
    backward.active.assign(nodes, 0);
    backward.d_row.assign(nodes, 0);
    backward.d_col.assign(nodes, 0);
    backward.score.assign(nodes, kNoScore);
    // Only where forward matches land (and one node around, for propagation).
    for (int i = 0; i < forward.rows; ++i) {
      for (int j = 0; j < forward.cols; ++j) {
        const int k = forward.index(i, j);
        if (!forward.active[k] || forward.score[k] < o.min_zncc) continue;
        const int bi = (forward.gridRow(i) + forward.d_row[k] - backward.row0) / o.stride;
        const int bj = (forward.gridCol(j) + forward.d_col[k] - backward.col0) / o.stride;
        for (int ni = std::max(0, bi - 1); ni <= std::min(backward.rows - 1, bi + 2); ++ni) {
          for (int nj = std::max(0, bj - 1); nj <= std::min(backward.cols - 1, bj + 2); ++nj) {
            const int gr = backward.gridRow(ni), gc = backward.gridCol(nj);
            if (gr < grid_rows - half && gc < grid_cols - half && grid_b.weight(gr, gc) > 0.0f)
              backward.active[backward.index(ni, nj)] = 1;
          }
        }
      }
    }
    runPatchMatch(backward, score_ba, window, grid_rows, grid_cols, half, o, 0xB0B0B002ULL);
  }

  const float max_fb_sq = static_cast<float>(o.max_fb_error_px * o.max_fb_error_px);
  // The checks on the fields alone: score, aperture, forward-backward, coherence.
  auto passesFieldChecks = [&](int i, int j) {
    const int k = forward.index(i, j);
    if (!forward.active[k] || forward.score[k] < o.min_zncc) return false;
    const int sr = forward.gridRow(i), sc = forward.gridCol(j);
    if (!structure_ratio_a.empty() && structure_ratio_a(sr, sc) < o.min_structure_ratio) return false;
    const int tr = sr + forward.d_row[k], tc = sc + forward.d_col[k];
    if (o.forward_backward_check) {
      const int bi =
          std::clamp(static_cast<int>(std::lround(double(tr - backward.row0) / o.stride)), 0, backward.rows - 1);
      const int bj =
          std::clamp(static_cast<int>(std::lround(double(tc - backward.col0) / o.stride)), 0, backward.cols - 1);
      const int n = backward.index(bi, bj);
      if (!backward.active[n] || backward.score[n] <= kNoScore) return false;
      const float er = static_cast<float>(forward.d_row[k] + backward.d_row[n]);
      const float ec = static_cast<float>(forward.d_col[k] + backward.d_col[n]);
      if (er * er + ec * ec > max_fb_sq) return false;
    }
    // Local coherence: the DR error between two lines is a near-rigid shift, so a correct
    // offset has neighbours with the same offset; a chance correlation on a wrong pair or a
    // texture-poor patch does not.
    if (o.min_coherent_neighbours > 0) {
      int coherent = 0;
      for (int ni = std::max(0, i - 1); ni <= std::min(forward.rows - 1, i + 1); ++ni) {
        for (int nj = std::max(0, j - 1); nj <= std::min(forward.cols - 1, j + 1); ++nj) {
          const int n = forward.index(ni, nj);
          if (n == k || !forward.active[n] || forward.score[n] < o.min_zncc) continue;
          if (std::abs(forward.d_row[n] - forward.d_row[k]) <= 1 && std::abs(forward.d_col[n] - forward.d_col[k]) <= 1)
            ++coherent;
        }
      }
      if (coherent < o.min_coherent_neighbours) return false;
    }
    return true;
  };
  // Each node's verdict from the fields, in parallel; with min_peak_margin, the matches that pass
  // are also scored over the whole window (periodic seabed: the costly check).
  enum NodeVerdict : std::uint8_t { kFails = 0, kPasses = 1, kAmbiguous = 2 };
  std::vector<std::uint8_t> verdict(forward_nodes, kFails);
  parallelFor((forward.rows + kBandRows - 1) / kBandRows, o.threads, [&](int band) {
    for (int i = band * kBandRows; i < std::min(forward.rows, (band + 1) * kBandRows); ++i) {
      for (int j = 0; j < forward.cols; ++j) {
        if (!passesFieldChecks(i, j)) continue;
        const int k = forward.index(i, j);
        verdict[k] = kPasses;
        if (o.min_peak_margin > 0.0 &&
            peakMargin(score_ab, forward.gridRow(i), forward.gridCol(j), forward.d_row[k], forward.d_col[k], window,
                       grid_rows, grid_cols, half) < o.min_peak_margin)
          verdict[k] = kAmbiguous;
      }
    }
  });

  std::vector<Correspondence> matches;
  matches.reserve(static_cast<std::size_t>(t.overlapping_pixels));
  std::vector<std::pair<int, int>> mirrored_nodes;  // forward lattice (i, j) of the mirror test's rejects
  for (int i = 0; i < forward.rows; ++i) {
    for (int j = 0; j < forward.cols; ++j) {
      const int k = forward.index(i, j);
      if (verdict[k] == kFails) continue;
      if (verdict[k] == kAmbiguous) {
        ++t.ambiguous_rejected;
        continue;
      }
      const int sr = forward.gridRow(i), sc = forward.gridCol(j);
      const int tr = sr + forward.d_row[k], tc = sc + forward.d_col[k];
      float fr = 0.0f, fc = 0.0f, curvature_col = 0.0f;
      if (o.subpixel && tr > half && tc > half && tr + 1 < grid_rows - half && tc + 1 < grid_cols - half) {
        fr = parabolaPeak(score_ab(sr, sc, tr - 1, tc), forward.score[k], score_ab(sr, sc, tr + 1, tc));
        const float left = score_ab(sr, sc, tr, tc - 1), right = score_ab(sr, sc, tr, tc + 1);
        fc = parabolaPeak(left, forward.score[k], right);
        if (left > kNoScore && right > kNoScore) curvature_col = std::max(1e-6f, 2.0f * forward.score[k] - left - right);
      }
      // Grid position -> B pixel through the resampling map (bilinear; the map is smooth).
      const float gr = tr + fr, gc = tc + fc;
      const int r0 = static_cast<int>(std::floor(gr)), c0 = static_cast<int>(std::floor(gc));
      if (!has_map(r0, c0) || !has_map(r0 + 1, c0) || !has_map(r0, c0 + 1) || !has_map(r0 + 1, c0 + 1)) continue;
      const float wr = gr - r0, wc = gc - c0;
      const cv::Vec2f m = (1 - wr) * ((1 - wc) * map_to_b(r0, c0) + wc * map_to_b(r0, c0 + 1)) +
                          wr * ((1 - wc) * map_to_b(r0 + 1, c0) + wc * map_to_b(r0 + 1, c0 + 1));
      const int nearest_r = static_cast<int>(std::lround(m[0])), nearest_c = static_cast<int>(std::lround(m[1]));
      if (nearest_r < 0 || nearest_c < 0 || nearest_r >= b.valid.rows || nearest_c >= b.valid.cols ||
          !b.valid(nearest_r, nearest_c))
        continue;
      // Contrast-inverted relief (checked on the nodes whose DR-predicted B pixel looks opposed).
      if (o.reject_inverted_relief && inverted.active[k] && inverted.score[k] >= o.min_zncc) {
        ++t.inverted_relief_rejected;
        continue;
      }
      const bool opposed = (o.reject_mirrored_relief || test_relief) &&
                           opposedLooks(a, sr - pad_r, sc - pad_c, b, nearest_r, nearest_c);
      if (opposed && o.reject_mirrored_relief &&
          bestMirroredScore(score_mirrored, sr, sc, tr, tc, half, grid_cols) > forward.score[k]) {
        mirrored_nodes.push_back({i, j});
        continue;
      }
      // A feature's face or shadow in either patch: its contrast outweighs the seabed's and moves
      // the peak towards the side it is seen from.
      const bool on_relief = opposed && test_relief &&
                             (patchHasRelief(relief_a, sr, sc, half) || patchHasRelief(relief_b, tr, tc, half));
      if (on_relief && o.reject_shadowed_relief) {
        ++t.shadowed_relief_rejected;
        continue;
      }
      if (on_relief) ++t.shadowed_relief_marked;
      Correspondence match;
      match.row_a = static_cast<float>(sr - pad_r);
      match.col_a = static_cast<float>(sc - pad_c);
      match.row_b = m[0];
      match.col_b = m[1];
      match.zncc = forward.score[k];
      match.peak_curvature_col = curvature_col;
      match.opposed_relief = on_relief;
      matches.push_back(match);
    }
  }
  if (!mirrored_nodes.empty()) {
    // A raised feature biases every patch it dominates, not only the one centred where the mirror
    // test caught it: matches whose patch overlaps a mirrored one's centre go too.
    const int reach = half / o.stride;
    cv::Mat1b near_mirrored = cv::Mat1b::zeros(forward.rows, forward.cols);
    for (const auto& [i, j] : mirrored_nodes) {
      const cv::Rect box(j - reach, i - reach, 2 * reach + 1, 2 * reach + 1);
      near_mirrored(box & cv::Rect(0, 0, forward.cols, forward.rows)).setTo(1);
    }
    // A match's A pixel is its lattice node times the stride (the lattice starts at A's origin).
    const std::size_t before = matches.size();
    matches.erase(std::remove_if(matches.begin(), matches.end(),
                                 [&](const Correspondence& m) {
                                   return near_mirrored(static_cast<int>(m.row_a) / o.stride,
                                                        static_cast<int>(m.col_a) / o.stride) != 0;
                                 }),
                  matches.end());
    t.mirrored_relief_rejected = static_cast<long>(mirrored_nodes.size() + before - matches.size());
  }
  t.consistency_s = secondsSince(stage);
  t.matches = static_cast<long>(matches.size());
  t.total_s = secondsSince(start);
  return matches;
}

}  // namespace sss::matcher
