// Waterfall and mosaic PNGs of canonical subframes. See pictures.hpp.
#include "pipeline/subframe/pictures.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "pipeline/core/georeference.hpp"

namespace sss::subframe {

using sss::core::Result;
using sss::core::Status;

Result<std::vector<std::string>> writeWaterfalls(const std::vector<Subframe>& subframes, const std::string& dir,
                                                 const PictureOptions& options) {
  std::map<int, std::vector<const Subframe*>> lines;
  for (const Subframe& s : subframes) lines[s.line_id].push_back(&s);
  std::vector<std::string> files;
  for (const auto& [line_id, list] : lines) {
    int rows = 0;
    for (const Subframe* s : list) rows += s->rows();
    const int cols = list.front()->cols();
    const int factor = std::max(1, (cols + options.waterfall_max_width_px - 1) / options.waterfall_max_width_px);
    const int width = cols / factor;
    cv::Mat image(rows, width, CV_8UC3, cv::Scalar(0, 0, 0));
    int row0 = 0;
    for (const Subframe* s : list) {
      for (int r = 0; r < s->rows(); ++r) {
        for (int x = 0; x < width; ++x) {
          double sum = 0.0;
          int valid = 0;
          for (int k = 0; k < factor; ++k) {
            const size_t i = static_cast<size_t>(r) * cols + x * factor + k;
            if (s->mask[i] == kMaskValid) {
              sum += s->image[i];
              ++valid;
            }
          }
          cv::Vec3b& pixel = image.at<cv::Vec3b>(row0 + r, x);
          if (valid == 0) {
            pixel = cv::Vec3b(60, 0, 0);  // BGR: dark blue for masked
          } else {
            const double v = std::clamp(sum / valid / options.display_max_intensity, 0.0, 1.0) * 255.0;
            pixel = cv::Vec3b(static_cast<uint8_t>(v), static_cast<uint8_t>(v), static_cast<uint8_t>(v));
          }
        }
      }
      for (int x = 0; x < std::min(8, width); ++x) image.at<cv::Vec3b>(row0, x) = cv::Vec3b(0, 0, 255);
      row0 += s->rows();
    }
    const std::string path = dir + "/waterfall_line_" + std::to_string(line_id) + ".png";
    if (!cv::imwrite(path, image)) {
      return Status::error("cannot write " + path);
    }
    files.push_back(path);
  }
  return files;
}

Result<MosaicRaster> renderMosaic(const std::vector<Subframe>& subframes,
                                  const std::map<int64_t, std::vector<sss::core::Pose>>& poses_by_subframe,
                                  const PictureOptions& options) {
  if (subframes.empty()) {
    return Status::error("no subframes for the mosaic");
  }
  struct Point {
    double north, east;
    float value;
  };
  std::vector<Point> points;
  double n_min = std::numeric_limits<double>::max(), n_max = -n_min, e_min = n_min, e_max = -n_min;
  for (const Subframe& s : subframes) {
    auto found = poses_by_subframe.find(s.id);
    const std::vector<sss::core::Pose> poses = found != poses_by_subframe.end() ? found->second : drPoses(s);
    // Every other column: the mosaic cell (0.5 m) is far coarser than a bin.
    // Half-row steps (interpolated poses) so 0.5 m pings leave no empty cells between rows.
    for (int half = 0; half < 2 * s.rows() - 1; ++half) {
      const int r = half / 2;
      const sss::core::Pose pose =
          half % 2 == 0 ? poses[r] : sss::core::interpolate(poses[r], poses[r + 1], 0.5);
      const double altitude_m = half % 2 == 0 ? s.pings[r].altitude_m
                                              : 0.5 * (s.pings[r].altitude_m + s.pings[r + 1].altitude_m);
      for (int c = 0; c < s.cols(); c += 2) {
        const size_t i = static_cast<size_t>(r) * s.cols() + c;
        if (s.mask[i] != kMaskValid) continue;
        const auto p = sss::core::georeferencePixel(s.geometry, pose, altitude_m, c);
        if (!p) continue;
        points.push_back({p->x(), p->y(), s.image[i]});
        n_min = std::min(n_min, p->x());
        n_max = std::max(n_max, p->x());
        e_min = std::min(e_min, p->y());
        e_max = std::max(e_max, p->y());
      }
    }
  }
  if (points.empty()) {
    return Status::error("no valid pixels for the mosaic");
  }
  MosaicRaster mosaic;
  const double res = options.mosaic_resolution_m;
  mosaic.resolution_m = res;
  mosaic.rows = static_cast<int>(std::ceil((n_max - n_min) / res)) + 1;
  mosaic.cols = static_cast<int>(std::ceil((e_max - e_min) / res)) + 1;
  mosaic.north_max_m = n_min + mosaic.rows * res;
  mosaic.east_min_m = e_min;
  const int rows = mosaic.rows, cols = mosaic.cols;
  cv::Mat sum(rows, cols, CV_64F, cv::Scalar(0.0));
  cv::Mat count(rows, cols, CV_32S, cv::Scalar(0));
  for (const Point& p : points) {
    // North up: image row 0 is the northernmost cell.
    const int row = rows - 1 - static_cast<int>((p.north - n_min) / res);
    const int col = static_cast<int>((p.east - e_min) / res);
    sum.at<double>(row, col) += p.value;
    count.at<int>(row, col) += 1;
  }
  mosaic.gray.assign(static_cast<size_t>(rows) * cols, 0);  // 0 = no data (data is 1..255)
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const int n = count.at<int>(r, c);
      if (n == 0) continue;
      const double v = 1.0 + std::clamp(sum.at<double>(r, c) / n / options.display_max_intensity, 0.0, 1.0) * 254.0;
      mosaic.gray[static_cast<size_t>(r) * cols + c] = static_cast<uint8_t>(v);
    }
  }
  return mosaic;
}

Status writeMosaic(const MosaicRaster& mosaic, const std::string& path,
                   const std::optional<sss::core::MissionOrigin>& origin) {
  cv::Mat image(mosaic.rows, mosaic.cols, CV_8UC1, const_cast<uint8_t*>(mosaic.gray.data()));
  if (!cv::imwrite(path, image)) {
    return Status::error("cannot write " + path);
  }
  // Its geo-reference, in the simulator's mosaic.yaml format.
  const std::string yaml_path = std::filesystem::path(path).replace_extension(".yaml").string();
  std::ofstream yaml(yaml_path);
  yaml.precision(12);
  yaml << "# " << std::filesystem::path(path).filename().string()
       << ": mean normalised intensity per cell, geo-referenced with the poses given.\n"
       << "# Pixel (row, col): north = north_max_m - (row + 0.5) * resolution_m, east = east_min_m + (col + 0.5) * "
          "resolution_m.\n"
       << "resolution_m: " << mosaic.resolution_m << "\nnorth_max_m: " << mosaic.north_max_m
       << "\neast_min_m: " << mosaic.east_min_m << "\nrows: " << mosaic.rows << "\ncols: " << mosaic.cols << "\n";
  if (origin) yaml << sss::core::originYamlKeys(*origin);
  if (!yaml) {
    return Status::error("cannot write " + yaml_path);
  }
  return Status::success();
}

Status writeMosaic(const std::vector<Subframe>& subframes,
                   const std::map<int64_t, std::vector<sss::core::Pose>>& poses_by_subframe, const std::string& path,
                   const PictureOptions& options, const std::optional<sss::core::MissionOrigin>& origin) {
  const Result<MosaicRaster> mosaic = renderMosaic(subframes, poses_by_subframe, options);
  if (!mosaic) return Status::error(mosaic.message() + " " + path);
  return writeMosaic(*mosaic, path, origin);
}

Subframe decimateForMosaic(const Subframe& s, int factor) {
  Subframe out;
  out.id = s.id;
  out.line_id = s.line_id;
  out.centre_ping_index = s.centre_ping_index;
  out.pings = s.pings;
  out.geometry = s.geometry;
  const size_t pixels = static_cast<size_t>(s.rows()) * static_cast<size_t>(std::max(s.cols(), 0));
  if (factor < 1 || s.image.size() != pixels || s.mask.size() != pixels) {
    out.geometry.bins_per_side = 0;  // no image (none sent, or an inconsistent one): nothing to draw
    return out;
  }
  const int bins = s.geometry.bins_per_side / factor;
  out.geometry.bins_per_side = bins;
  out.geometry.bin_size_m = s.geometry.bin_size_m * factor;
  out.geometry.first_bin_range_m = s.geometry.first_bin_range_m + 0.5 * (factor - 1) * s.geometry.bin_size_m;
  const int cols = out.geometry.columns();
  out.image.assign(static_cast<size_t>(s.rows()) * cols, 0.0f);
  out.mask.assign(out.image.size(), kMaskValid);
  const int source_bins = s.geometry.bins_per_side;
  for (int row = 0; row < s.rows(); ++row) {
    for (int bin = 0; bin < bins; ++bin) {
      for (int side = 0; side < 2; ++side) {  // 0 port, 1 starboard
        float sum = 0.0f;
        uint8_t mask = kMaskValid;
        for (int k = 0; k < factor; ++k) {
          const int source_bin = bin * factor + k;
          const int column = side == 0 ? source_bins - 1 - source_bin : source_bins + source_bin;
          const size_t i = static_cast<size_t>(row) * s.cols() + column;
          sum += s.image[i];
          if (s.mask[i] != kMaskValid) mask = s.mask[i];
        }
        const int column = side == 0 ? bins - 1 - bin : bins + bin;
        out.image[static_cast<size_t>(row) * cols + column] = sum / static_cast<float>(factor);
        out.mask[static_cast<size_t>(row) * cols + column] = mask;
      }
    }
  }
  return out;
}

}  // namespace sss::subframe
