// PNG figures for the evaluation, drawn with OpenCV: trajectories in the north/east plane (equal
// axes), error curves over time, and heightmap error maps with a diverging colour scale.
#pragma once

#include "tools/eval/heightmap_metrics.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace sss::eval {

struct PlotTrajectory {
  std::string label;
  std::vector<Eigen::Vector2d> north_east_m;
};

// Truth in black, estimates in distinct colours, east to the right and north up at one scale,
// legend in the emptiest corner, start marked. False with a message on failure.
bool writeTrajectoryPlot(const std::string& path, const PlotTrajectory& truth, const std::vector<PlotTrajectory>& estimates,
                         const std::string& title, std::string& error);

struct PlotCurve {
  std::string label;
  std::vector<double> x;
  std::vector<double> y;
  int colour_index = 0;  // into the shared palette; estimates keep their colour across figures
  bool dashed = false;
};

// Shaded background interval (e.g. a survey line), labelled at the top.
struct PlotBand {
  double x_min = 0.0;
  double x_max = 0.0;
  std::string label;
};

bool writeCurvePlot(const std::string& path, const std::vector<PlotCurve>& curves, const std::vector<PlotBand>& bands,
                    const std::string& title, const std::string& x_label, const std::string& y_label,
                    std::string& error);

struct ErrorMapPngOptions {
  // Colour scale +-limit_m; <= 0 picks the 99th percentile of |error| rounded up to 1, 2 or 5 x 10^k.
  double limit_m = 0.0;
  int max_size_px = 1400;  // larger rasters are block-averaged down to this
};

// North up; blue = estimate shallower, white = 0, red = estimate deeper, grey = no data; a colour
// bar with its scale in metres below. used_limit_m (optional) receives the scale used.
bool writeErrorMapPng(const std::string& path, const HeightmapRaster& error_map, const std::string& title,
                      std::string& error, const ErrorMapPngOptions& options = {}, double* used_limit_m = nullptr);

// Round up to 1, 2 or 5 x 10^k.
double niceCeil(double value);

}  // namespace sss::eval
