// Figure data for report_figures.py and the run of the script. See figure_script.hpp.
#include "tools/eval/figure_script.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

extern char** environ;

namespace sss::eval {
namespace {

namespace fs = std::filesystem;

// NumPy's .npy format 1.0 (what np.load reads without extra packages): magic, header length,
// a Python dict literal padded to a multiple of 64 bytes, then the little-endian data (x86/ARM).
sss::core::Status writeNpy(const std::string& path, const char* descr, const void* data, size_t bytes, int rows,
                           int cols) {
  std::string header = "{'descr': '" + std::string(descr) + "', 'fortran_order': False, 'shape': (" +
                       std::to_string(rows) + ", " + std::to_string(cols) + "), }";
  const size_t preamble = 10;  // magic (6) + version (2) + header length (2)
  header.append(63 - (preamble + header.size()) % 64, ' ');
  header += '\n';
  std::ofstream out(path, std::ios::binary);
  const char magic[8] = {'\x93', 'N', 'U', 'M', 'P', 'Y', 1, 0};
  const uint16_t length = static_cast<uint16_t>(header.size());
  const char length_le[2] = {static_cast<char>(length & 0xff), static_cast<char>(length >> 8)};
  out.write(magic, sizeof magic);
  out.write(length_le, sizeof length_le);
  out << header;
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
  out.close();
  if (!out) {
    return sss::core::Status::error("cannot write " + path + "; check the folder is writable and the disk not full");
  }
  return sss::core::Status::success();
}

std::string lastLine(const std::string& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  return last;
}

// Runs `python script data_dir out_dir` with stdout and stderr into log_path; its exit status, or a
// failure when it could not be started or did not exit normally.
sss::core::Result<int> runScript(const std::string& python, const std::string& script, const std::string& data_dir,
                                 const std::string& out_dir, const std::string& log_path) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::vector<std::string> args = {python, script, data_dir, out_dir};
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, python.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) {
    return sss::core::Status::error("cannot start " + python + ": " + std::strerror(spawned));
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      return sss::core::Status::error("waiting for " + script + ": " + std::strerror(errno));
    }
  }
  if (!WIFEXITED(status)) {
    return sss::core::Status::error(script + " was killed by signal " +
                                    std::to_string(WTERMSIG(status)));
  }
  return WEXITSTATUS(status);
}

// Writes data_dir/NAME.npy (batch.error keeps the first failure) and returns the raster's entry
// with its file and resolution; the caller adds where its corner lies.
Json writeRaster(FigureBatch& batch, const std::string& name, const char* dtype, const void* data, size_t bytes,
                 int rows, int cols, double resolution_m) {
  std::error_code ec;
  fs::create_directories(batch.data_dir, ec);
  const std::string file = name + ".npy";
  const sss::core::Status written =
      writeNpy((fs::path(batch.data_dir) / file).string(), dtype, data, bytes, rows, cols);
  if (!written && batch.error.empty()) batch.error = written.message;
  Json raster = Json::object();
  raster["npy"] = file;
  raster["resolution_m"] = resolution_m;
  return raster;
}

}  // namespace

std::string defaultFigureScript() {
  std::error_code ec;
  if (fs::is_regular_file(SSS_FIGURE_SCRIPT_SOURCE, ec)) return SSS_FIGURE_SCRIPT_SOURCE;
  return SSS_FIGURE_SCRIPT_INSTALLED;
}

std::string defaultPageScript() {
  std::error_code ec;
  if (fs::is_regular_file(SSS_PAGE_SCRIPT_SOURCE, ec)) return SSS_PAGE_SCRIPT_SOURCE;
  return SSS_PAGE_SCRIPT_INSTALLED;
}

std::string pythonProblem(const FigureScriptOptions& options) {
  if (access(options.python.c_str(), X_OK) == 0) return {};
  return options.python + " not found; install python3 and python3-matplotlib with tools/setup-deps.sh";
}

std::string paletteColour(int index) { return "C" + std::to_string(((index % 10) + 10) % 10); }

Json& addFigure(FigureBatch& batch, const std::string& kind, const std::string& file, const std::string& title) {
  Json figure = Json::object();
  figure["kind"] = kind;
  figure["file"] = file;
  figure["title"] = title;
  batch.figures.push_back(std::move(figure));
  return batch.figures.back();
}

Json mosaicRaster(FigureBatch& batch, const GreyMosaic& mosaic, const std::string& name) {
  Json raster = writeRaster(batch, name, "|u1", mosaic.pixels.data(), mosaic.pixels.size(), mosaic.rows, mosaic.cols,
                            mosaic.resolution_m);
  raster["north_max_m"] = mosaic.north_max_m;
  raster["east_min_m"] = mosaic.east_min_m;
  return raster;
}

Json heightmapRaster(FigureBatch& batch, const HeightmapRaster& map, const std::string& name) {
  Json raster = writeRaster(batch, name, "<f4", map.depth_m.data(), map.depth_m.size() * sizeof(float), map.rows,
                            map.cols, map.resolution_m);
  raster["north_min_m"] = map.north_min_m;
  raster["east_min_m"] = map.east_min_m;
  return raster;
}

Json mapLine(const std::string& label, const std::vector<Eigen::Vector2d>& north_east_m, const std::string& colour,
             double width_pt, bool mark_start, bool truth) {
  Json points = Json::array();
  for (const Eigen::Vector2d& p : north_east_m) {
    if (p.allFinite()) points.push_back({p.x(), p.y()});
  }
  Json line = Json::object();
  line["label"] = label;
  line["north_east_m"] = std::move(points);
  line["colour"] = colour;
  line["width"] = width_pt;
  line["mark_start"] = mark_start;
  line["truth"] = truth;
  return line;
}

std::vector<Json> horizontalErrorCurves(const std::string& label, const std::vector<ErrorSample>& series,
                                        const std::string& colour, int64_t t0_us) {
  Json raw = {{"label", label + " horizontal"}, {"colour", colour}, {"dashed", false}};
  Json aligned = {{"label", label + " horizontal, SE(3)-aligned"}, {"colour", colour}, {"dashed", true}};
  Json minutes = Json::array(), raw_m = Json::array(), aligned_m = Json::array();
  for (const ErrorSample& s : series) {
    minutes.push_back(static_cast<double>(s.utime_us - t0_us) / 60e6);
    raw_m.push_back(jsonValue(s.horizontal_m));  // NaN as null: a gap in the curve
    aligned_m.push_back(jsonValue(s.aligned_horizontal_m));
  }
  raw["x"] = minutes;
  raw["y"] = std::move(raw_m);
  aligned["x"] = std::move(minutes);
  aligned["y"] = std::move(aligned_m);
  return {std::move(raw), std::move(aligned)};
}

Json surveyLineBands(const std::vector<SurveyLine>& lines, int64_t t0_us) {
  Json bands = Json::array();
  for (const SurveyLine& line : lines) {
    bands.push_back({{"x_min", static_cast<double>(line.start_utime_us - t0_us) / 60e6},
                     {"x_max", static_cast<double>(line.end_utime_us - t0_us) / 60e6},
                     {"label", "line " + std::to_string(line.index)}});
  }
  return bands;
}

FigureRun drawFigures(const FigureBatch& batch, const std::string& out_dir, const FigureScriptOptions& options) {
  FigureRun run;
  if (batch.figures.empty()) return run;
  std::vector<std::string> files;
  for (const Json& figure : batch.figures) files.push_back(figure["file"].get<std::string>());
  // Old PNGs of the same names go first, so that what exists afterwards is what this run drew.
  std::error_code ec;
  for (const std::string& file : files) fs::remove(fs::path(out_dir) / file, ec);
  const std::string spec_path = (fs::path(batch.data_dir) / "figures.json").string();
  const std::string log_path = (fs::path(batch.data_dir) / "report_figures.log").string();

  std::string problem = batch.error;
  if (problem.empty()) {
    fs::create_directories(batch.data_dir, ec);
    std::ofstream out(spec_path, std::ios::binary);
    out << Json{{"schema", "sss-figures/1"}, {"figures", batch.figures}}.dump(1) << "\n";
    out.close();
    if (!out) problem = "cannot write " + spec_path + "; check the folder is writable";
  }
  if (problem.empty()) problem = pythonProblem(options);
  if (problem.empty() && !fs::is_regular_file(options.script, ec)) {
    problem = "the figure script " + options.script + " is missing; run from the build tree or reinstall (cmake --install)";
  } else if (problem.empty()) {
    const sss::core::Result<int> code = runScript(options.python, options.script, batch.data_dir, out_dir, log_path);
    if (!code) {
      problem = code.message();
    } else if (*code == 3) {
      problem = "matplotlib is not installed for " + options.python + "; run tools/setup-deps.sh (python3-matplotlib)";
    } else if (*code != 0) {
      problem = options.script + " failed (exit " + std::to_string(*code) + "): " + lastLine(log_path) +
                "; whole log in " + log_path;
    }
  }
  for (const std::string& file : files) {
    const fs::path path = fs::path(out_dir) / file;
    if (fs::is_regular_file(path, ec)) {
      run.written.push_back(path.string());
    } else {
      run.missing.push_back(file);
    }
  }
  if (problem.empty() && !run.missing.empty()) problem = options.script + " exited 0 without writing them; see " + log_path;
  if (!problem.empty()) {
    std::string names;
    for (const std::string& file : run.missing) names += (names.empty() ? "" : ", ") + file;
    run.problem = "figures not drawn (" + names + "): " + problem;
  }
  return run;
}

sss::core::Status drawPage(const Json& page, const std::string& data_dir, const std::string& out_dir,
                           const FigureScriptOptions& options) {
  std::error_code ec;
  const fs::path html_path = fs::path(out_dir) / "index.html";
  fs::remove(html_path, ec);  // what exists afterwards is what this run wrote
  if (const std::string problem = pythonProblem(options); !problem.empty()) return sss::core::Status::error(problem);
  if (!fs::is_regular_file(options.page_script, ec)) {
    return sss::core::Status::error("the page script " + options.page_script +
                                    " is missing; run from the build tree or reinstall (cmake --install)");
  }
  fs::create_directories(data_dir, ec);
  const std::string page_path = (fs::path(data_dir) / "page.json").string();
  const std::string log_path = (fs::path(data_dir) / "report_page.log").string();
  std::ofstream out(page_path, std::ios::binary);
  out << page.dump(1) << "\n";
  out.close();
  if (!out) return sss::core::Status::error("cannot write " + page_path + "; check the folder is writable");
  const sss::core::Result<int> code = runScript(options.python, options.page_script, data_dir, out_dir, log_path);
  if (!code) return code.status();
  if (*code != 0) {
    return sss::core::Status::error(options.page_script + " failed (exit " + std::to_string(*code) +
                                    "): " + lastLine(log_path) + "; whole log in " + log_path);
  }
  if (!fs::is_regular_file(html_path, ec)) {
    return sss::core::Status::error(options.page_script + " exited 0 without writing " + html_path.string() +
                                    "; see " + log_path);
  }
  return sss::core::Status::success();
}

}  // namespace sss::eval
