// PNG figures for the evaluation, drawn with OpenCV: trajectories in the north/east plane (equal
// axes), error curves over time, and heightmap error maps with a diverging colour scale; for the
// run report also maps over a mosaic, mosaics side by side and depth maps.
#pragma once

#include "tools/eval/heightmap_metrics.hpp"
#include "tools/eval/trajectory_metrics.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <utility>
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

// An estimate's horizontal error over time, minutes since t0_us: the raw curve and the dashed
// SE(3)-aligned one.
std::vector<PlotCurve> horizontalErrorCurves(const std::string& label, const std::vector<ErrorSample>& series,
                                             int colour_index, int64_t t0_us);
// The survey lines as labelled bands, minutes since t0_us.
std::vector<PlotBand> surveyLineBands(const std::vector<SurveyLine>& lines, int64_t t0_us);

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

// ---- maps (sss-report): trajectories and closures over a mosaic, mosaics side by side, depth ----

struct PlotColour {
  uint8_t r = 0, g = 0, b = 0;
};
// The shared palette (Tableau 10): 1 orange, 2 green, 3 red, 7 grey, 9 cyan, ...
PlotColour paletteRgb(int index);

// An 8-bit grey mosaic in the simulator's mosaic.yaml layout: pixel (row, col) lies at north =
// north_max_m - (row + 0.5) * resolution_m, east = east_min_m + (col + 0.5) * resolution_m; 0 = no data.
struct GreyMosaic {
  int rows = 0;
  int cols = 0;
  double resolution_m = 1.0;
  double north_max_m = 0.0;
  double east_min_m = 0.0;
  std::vector<uint8_t> pixels;  // row-major, row 0 northmost
};

// Reads X.yaml (keys resolution_m, north_max_m, east_min_m, rows, cols) and the 8-bit grey X.png
// beside it. False with a message naming the file on any problem (missing key, size mismatch).
bool readMosaic(const std::string& yaml_path, GreyMosaic& mosaic, std::string& error);

// North/east rectangle in local NED metres.
struct MapExtent {
  double north_min_m = 0.0;
  double north_max_m = 0.0;
  double east_min_m = 0.0;
  double east_max_m = 0.0;
  bool valid() const { return north_max_m > north_min_m && east_max_m > east_min_m; }
};
// The extent of the mosaic's pixels with data; invalid when it has none.
MapExtent mosaicDataExtent(const GreyMosaic& mosaic);

struct MapPolyline {
  std::string label;  // legend entry; empty: none
  std::vector<Eigen::Vector2d> north_east_m;
  PlotColour colour;
  int thickness_px = 2;
  int casing_px = 0;        // a border this wide in casing_colour on both sides (0: none)
  PlotColour casing_colour;
  bool mark_start = false;  // a ring and "start" at the first point
};

struct MapSegments {
  std::string label;  // legend entry, e.g. "accepted (42)"
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> north_east_m;
  PlotColour colour;
  int thickness_px = 2;
};

struct MapFigure {
  std::string title;
  std::string note;                        // second line under the title (grey)
  const GreyMosaic* background = nullptr;  // optional, drawn as grey = base + gain * value
  double background_base = 30.0;           // lower the gain to fade the mosaic under busy overlays
  double background_gain = 0.75;
  std::vector<MapPolyline> polylines;  // drawn in order, after the background
  std::vector<MapSegments> segments;   // drawn after the polylines; listed top-most (last) first
  MapExtent extent;                    // invalid: fit the background's data and every point, 4 % margin
  int max_map_width_px = 1100;         // the map area (plus ~200 px of axes and titles)
  int max_map_height_px = 950;
};

// North up, equal scale, metre ticks, a scale bar and the legend. False with a message on failure.
bool writeMapPng(const std::string& path, const MapFigure& figure, std::string& error);

struct MosaicPanel {
  std::string label;
  const GreyMosaic* mosaic = nullptr;
};

// Mosaics side by side at one geographic extent (the union of their data) and one scale, each
// resampled (area-averaged) into it; labelled panels, metre ticks, a scale bar; at most
// max_width_px wide. False with a message on failure.
bool writeMosaicPanelsPng(const std::string& path, const std::vector<MosaicPanel>& panels, const std::string& title,
                          std::string& error, int max_width_px = 1560, int max_panel_height_px = 900);

struct DepthMapPngOptions {
  int max_size_px = 900;      // larger rasters are block-averaged down to this
  bool hillshade = true;      // light from the north-west, so relief and artefacts show
};

// North up; depth in a perceptual colour map (shallow yellow, deep purple) between the 1st and 99th
// percentiles, a colour bar in metres below; grey = no data.
bool writeDepthMapPng(const std::string& path, const HeightmapRaster& map, const std::string& title,
                      std::string& error, const DepthMapPngOptions& options = {});

}  // namespace sss::eval
