// The evaluation figures (sss-report, sss-eval --plot) drawn by tools/eval/report_figures.py with
// matplotlib: the C++ side describes each figure in DATA_DIR/figures.json, rasters as .npy beside it;
// and sss-report's HTML page, written by tools/eval/report_page.py from DATA_DIR/page.json.
#pragma once

#include "tools/eval/heightmap_metrics.hpp"
#include "tools/eval/json_values.hpp"
#include "tools/eval/grey_mosaic.hpp"
#include "tools/eval/trajectory_metrics.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace sss::eval {

// The script next to this file in the source tree when it is there (a build tree), else the
// installed copy (CMake bakes both paths in).
std::string defaultFigureScript();
std::string defaultPageScript();  // the same for report_page.py

struct FigureScriptOptions {
  std::string python = "/usr/bin/python3";  // Debian's: the one that sees python3-matplotlib
  std::string script = defaultFigureScript();
  std::string page_script = defaultPageScript();
};

// Empty when options.python can be run; else one line: what is missing and how to install it.
std::string pythonProblem(const FigureScriptOptions& options);

// Figures to draw, described one by one, then drawn all at once by drawFigures(). Rasters are
// written into data_dir as they are added (so the report need not keep them).
struct FigureBatch {
  std::string data_dir;
  Json figures = Json::array();
  std::string error;  // the first raster that could not be written: the batch is then not drawn
};

// A figure of kind "map", "curves", "mosaics", "depth" or "error_map" (report_figures.py says
// what each reads) that writes `file` into the output folder; returns its entry to fill in (valid
// until the next addFigure on the batch).
Json& addFigure(FigureBatch& batch, const std::string& kind, const std::string& file, const std::string& title);

// Writes the raster as data_dir/NAME.npy and returns its entry: {"npy", "resolution_m", and
// "north_max_m", "east_min_m" for a mosaic (row 0 north) or "north_min_m", "east_min_m" for a
// heightmap (row 0 south)}. On failure batch.error is set.
Json mosaicRaster(FigureBatch& batch, const GreyMosaic& mosaic, const std::string& name);
Json heightmapRaster(FigureBatch& batch, const HeightmapRaster& raster, const std::string& name);

// A line of the "map" figure: points as [north_m, east_m]; colour a matplotlib name ("C1": tab10
// orange, the shared palette); truth is drawn black (white with a black outline over a mosaic).
Json mapLine(const std::string& label, const std::vector<Eigen::Vector2d>& north_east_m, const std::string& colour,
             double width_pt = 1.5, bool mark_start = false, bool truth = false);
// The colour of palette index i: "C<i>" (tab10; 1 orange = DR, 9 cyan = SLAM).
std::string paletteColour(int index);

// An estimate's horizontal error over time, minutes since t0_us: the raw curve and the dashed
// SE(3)-aligned one (entries of a "curves" figure's "curves").
std::vector<Json> horizontalErrorCurves(const std::string& label, const std::vector<ErrorSample>& series,
                                        const std::string& colour, int64_t t0_us);
// The survey lines as labelled bands, minutes since t0_us (a "curves" figure's "bands").
Json surveyLineBands(const std::vector<SurveyLine>& lines, int64_t t0_us);

struct FigureRun {
  std::vector<std::string> written;  // paths of the PNGs drawn, in the batch's order
  std::vector<std::string> missing;  // file names of the figures not drawn
  // Empty when every figure was drawn; else one line: what went wrong and what to do.
  std::string problem;
};

// Writes data_dir/figures.json and runs `python script data_dir out_dir` (its output in
// data_dir/report_figures.log). A missing interpreter, script or matplotlib, or a failing script
// is reported in FigureRun::problem, never thrown: the report goes on without those figures.
FigureRun drawFigures(const FigureBatch& batch, const std::string& out_dir, const FigureScriptOptions& options = {});

// Writes data_dir/page.json and runs `python page_script data_dir out_dir`, which writes
// out_dir/index.html from it (an old index.html is removed first). On failure one line: what went
// wrong and what to do.
sss::core::Status drawPage(const Json& page, const std::string& data_dir, const std::string& out_dir,
                           const FigureScriptOptions& options = {});

}  // namespace sss::eval
