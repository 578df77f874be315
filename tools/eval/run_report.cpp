// The per-run report: inputs -> metrics -> verdict, figures, index.html, report.md, metrics.json.
// See run_report.hpp.
#include "tools/eval/run_report.hpp"
#include "tools/eval/frame_alignment.hpp"
#include "tools/eval/run_report_internal.hpp"
#include "tools/eval/yaml_file.hpp"

namespace sss::eval {

using sss::core::Status;

using namespace report_internal;

namespace {

// ---- inputs --------------------------------------------------------------------------------

// A file whose header names another origin than target_origin is re-expressed in its frame; the
// file's own origin goes to *origin when given.
Status readTrajectoryInput(const std::string& path, const std::string& what, Trajectory& poses,
                           const std::optional<sss::core::MissionOrigin>& target_origin = std::nullopt,
                           std::optional<sss::core::MissionOrigin>* origin = nullptr) {
  if (!fileExists(path)) return Status::error(path + ": missing (" + what + ")");
  TumReadOptions options;
  options.target_origin = target_origin;
  TumReadResult result = readTum(path, options);
  if (!result.ok) return Status::error(result.error);
  poses = std::move(result.poses);
  if (origin) *origin = result.origin;
  return Status::success();
}

// Heightmaps are compared in the truth's frame (a run with its own origin is re-expressed).
HeightmapReadOptions truthFrame(const RunReport& report) {
  HeightmapReadOptions options;
  options.target_origin = report.truth_origin;
  return options;
}

void readHeightmaps(RunReport& report, const RunReportRequest& request) {
  const std::string seabed_path = joinPath(request.mission_dir, "seabed.yaml");
  const std::string slam_path = joinPath(request.run_dir, "heightmap.yaml");
  const std::string dr_path = joinPath(request.run_dir, "heightmap_dr.yaml");
  const bool have_slam = fileExists(slam_path), have_dr = fileExists(dr_path);
  if (!have_slam) report.notes.push_back("no SLAM heightmap (" + slam_path + "): heightmap section without it");
  if (!have_dr) report.notes.push_back("no DR heightmap (" + dr_path + "): heightmap section without it");
  if (!have_slam && !have_dr) return;
  HeightmapRaster seabed;
  if (!fileExists(seabed_path)) {
    report.notes.push_back("no true seabed (" + seabed_path + "): heightmap errors not computed");
  } else if (const Status read = readHeightmap(seabed_path, seabed, truthFrame(report)); !read) {
    report.notes.push_back("true seabed unusable, heightmap errors not computed: " + read.message);
    seabed = HeightmapRaster();
  } else {
    report.seabed_path = seabed_path;
  }
  for (auto [path, entry, present] : {std::tuple{slam_path, &report.heightmap_slam, have_slam},
                                      std::tuple{dr_path, &report.heightmap_dr, have_dr}}) {
    if (!present || report.seabed_path.empty()) continue;
    HeightmapRaster estimate;
    if (const Status read = readHeightmap(path, estimate, truthFrame(report)); !read) {
      report.notes.push_back("heightmap unusable: " + read.message);
      continue;
    }
    entry->path = path;
    entry->error = compareHeightmaps(seabed, estimate);
    if (!entry->error.ok) {
      report.notes.push_back(path + ": not compared with the seabed: " + entry->error.error);
      continue;
    }
    entry->present = true;
  }
  if (report.heightmap_dr.present && report.heightmap_slam.present) {
    report.heightmap_improvement_percent =
        improvementPercent(report.heightmap_dr.error.abs_error_m.mean, report.heightmap_slam.error.abs_error_m.mean);
  }
}

}  // namespace

// ---- loop closures and summary -----------------------------------------------------------

sss::core::Status readLoopClosures(const std::string& path, std::vector<LoopClosureRecord>& closures) {
  const std::vector<const char*> kCentres = {"north_a_m", "east_a_m", "north_b_m", "east_b_m"};
  CsvTable table;
  if (const Status read =
          readCsvTable(path, {"status", kCentres[0], kCentres[1], kCentres[2], kCentres[3]},
                       "subframe_id_a,subframe_id_b,...,status,...,north_a_m,east_a_m,north_b_m,east_b_m", table);
      !read) {
    return read;
  }
  closures.clear();
  for (const CsvRow& row : table.rows) {
    LoopClosureRecord record;
    record.line = row.line;
    record.status = table.field(row, "status");
    if (record.status != "accepted" && record.status != "rejected" && record.status != "pending" &&
        record.status != "superseded") {
      return Status::error(table.where(row) + "status '" + record.status +
                           "' is not accepted, rejected, pending or superseded");
    }
    if (table.has("rejection")) record.rejection = table.field(row, "rejection");
    double values[4];
    if (const Status parsed = parseNumberColumns(table, row, kCentres, values); !parsed) return parsed;
    record.centre_a_north_east_m = Eigen::Vector2d(values[0], values[1]);
    record.centre_b_north_east_m = Eigen::Vector2d(values[2], values[3]);
    if (table.has("subframe_id_a") && table.has("subframe_id_b")) {
      record.subframes = table.field(row, "subframe_id_a") + "-" + table.field(row, "subframe_id_b");
    }
    for (auto [prefix, target] : {std::pair{"before_", &record.before}, std::pair{"after_", &record.after}}) {
      const std::string p = prefix;
      const std::vector<std::string> names = {p + "along_m", p + "across_m", p + "depth_m", p + "heading_rad"};
      if (!table.has(names[0])) continue;
      const std::vector<const char*> columns = {names[0].c_str(), names[1].c_str(), names[2].c_str(), names[3].c_str()};
      double offset[4];
      if (const Status parsed = parseNumberColumns(table, row, columns, offset); !parsed) return parsed;
      *target = Eigen::Vector4d(offset[0], offset[1], offset[2], offset[3]);
    }
    closures.push_back(std::move(record));
  }
  return Status::success();
}

LoopClosureCounts countClosures(const std::vector<LoopClosureRecord>& closures) {
  LoopClosureCounts counts;
  for (const LoopClosureRecord& r : closures) {
    if (r.status == "accepted") ++counts.accepted;
    else if (r.status == "rejected") {
      ++counts.rejected;
      ++counts.rejection_reasons[r.rejection.empty() ? "unknown" : r.rejection];
    } else if (r.status == "pending") ++counts.pending;
    else ++counts.superseded;
  }
  return counts;
}

Status readRunSummary(const std::string& path, RunSummary& summary) {
  const sss::core::Result<YAML::Node> loaded = loadYamlFile(path, "JSON");
  if (!loaded) return loaded.status();
  const YAML::Node& root = *loaded;
  if (!root.IsMap()) {
    return Status::error(path + ": expected a JSON object with pings, subframes, closures_accepted, wall_s, ...");
  }
  RunSummary result;
  const std::pair<const char*, double*> keys[] = {
      {"pings", &result.pings},
      {"subframes", &result.subframes},
      {"pairs_attempted", &result.pairs_attempted},
      {"closures_accepted", &result.closures_accepted},
      {"closures_rejected", &result.closures_rejected},
      {"wall_s", &result.wall_s},
      {"mission_s", &result.mission_s},
      {"real_time_factor", &result.real_time_factor},
      {"peak_rss_mib", &result.peak_rss_mib}};
  for (const auto& [key, value] : keys) {
    const YAML::Node node = root[key];
    double number = kNaN;
    if (node && node.IsScalar() && parseFiniteDouble(node.Scalar(), number)) {
      *value = number;
    } else {
      result.missing_keys.push_back(key);
    }
  }
  // Optional blocks (older runs lack them): read what is there, quietly.
  const auto optional = [&](const char* block, const char* key, double& value) {
    const YAML::Node node = root[block] ? root[block][key] : YAML::Node();
    double number = kNaN;
    if (node && node.IsScalar() && parseFiniteDouble(node.Scalar(), number)) value = number;
  };
  optional("coverage", "covered_m2", result.covered_m2);
  optional("coverage", "fraction_seen_twice", result.fraction_seen_twice);
  optional("fixes", "fed", result.fixes_fed);
  optional("fixes", "accepted", result.fixes_accepted);
  optional("fixes", "rejected_gate", result.fixes_rejected);
  optional("fixes", "rms_residual_m", result.fixes_rms_residual_m);
  optional("calibration", "dvl_scale", result.dvl_scale);
  optional("calibration", "dvl_scale_sigma", result.dvl_scale_sigma);
  optional("calibration", "heading_bias_rad", result.heading_bias_rad);
  optional("calibration", "heading_bias_sigma_rad", result.heading_bias_sigma_rad);
  if (root["calibration"] && root["calibration"]["estimated"] && root["calibration"]["estimated"].IsScalar()) {
    result.calibration_estimated = root["calibration"]["estimated"].Scalar() == "true";
  }
  if (root["geotiff"] && root["geotiff"].IsMap()) {
    if (root["geotiff"]["crs"] && root["geotiff"]["crs"].IsScalar()) result.geotiff_crs = root["geotiff"]["crs"].Scalar();
    if (root["geotiff"]["files"] && root["geotiff"]["files"].IsSequence()) {
      for (const auto& file : root["geotiff"]["files"]) {
        if (file.IsScalar()) result.geotiffs.push_back(file.Scalar());
      }
    }
  }
  summary = std::move(result);
  return Status::success();
}

// ---- the report ----------------------------------------------------------------------------

RunReport writeRunReport(const RunReportRequest& request, const RunReportOptions& options) {
  RunReport report;
  report.title = request.title;
  if (report.title.empty()) {
    fs::path run = fs::path(request.run_dir).lexically_normal();
    if (run.filename().empty()) run = run.parent_path();  // "dir/"
    report.title = "sss-slam run " + (run.filename().empty() ? request.run_dir : run.filename().string());
  }
  const auto fail = [&](RunReportStatus status, const std::string& error) {
    report.status = status;
    report.error = error;
    return report;
  };
  try {
    // Required: the truth, the SLAM estimate, some DR.
    if (!fs::is_directory(request.mission_dir)) {
      return fail(RunReportStatus::bad_input, request.mission_dir + ": not a folder (--mission: the sss-sim --out folder)");
    }
    if (!fs::is_directory(request.run_dir)) {
      return fail(RunReportStatus::bad_input, request.run_dir + ": not a folder (--run: the sss-process output folder)");
    }
    report.truth_path = joinPath(request.mission_dir, "ground_truth.tum");
    report.slam_path = joinPath(request.run_dir, "slam.tum");
    report.dr_path = joinPath(request.run_dir, "dead_reckoning.tum");
    Trajectory truth, dr, slam;
    std::optional<sss::core::MissionOrigin> run_origin;  // the frame the run's files were written in
    Status read = readTrajectoryInput(report.truth_path,
                                      "the simulator's ground truth; is --mission the sss-sim --out folder?", truth,
                                      std::nullopt, &report.truth_origin);
    if (read) {
      read = readTrajectoryInput(report.slam_path, "the SLAM trajectory; is --run the sss-process output folder?", slam,
                                 report.truth_origin, &run_origin);
    }
    if (!read) return fail(RunReportStatus::bad_input, read.message);
    if (!fileExists(report.dr_path)) {
      const std::string fallback = joinPath(request.mission_dir, "dead_reckoning.tum");
      if (!fileExists(fallback)) {
        return fail(RunReportStatus::bad_input, report.dr_path + ": missing, and so is " + fallback +
                                                    " (the dead reckoning SLAM is compared with)");
      }
      report.notes.push_back("no dead_reckoning.tum in the run folder; the mission's " + fallback + " stands in for DR");
      report.dr_path = fallback;
    }
    if (const Status read_dr = readTrajectoryInput(report.dr_path, "dead reckoning", dr, report.truth_origin);
        !read_dr) {
      return fail(RunReportStatus::bad_input, read_dr.message);
    }

    report.truth_poses = truth.size();
    report.duration_s = static_cast<double>(truth.back().utime_us - truth.front().utime_us) * 1e-6;
    report.distance_m = cumulativeDistanceM(truth).back();
    report.lines = segmentSurveyLines(truth, options.trajectory.lines);
    report.dr = evaluateTrajectory(truth, dr, report.lines, options.trajectory);
    if (!report.dr.ok) return fail(RunReportStatus::bad_input, report.dr_path + ": " + report.dr.error);
    report.slam = evaluateTrajectory(truth, slam, report.lines, options.trajectory);
    if (!report.slam.ok) return fail(RunReportStatus::bad_input, report.slam_path + ": " + report.slam.error);
    if (!options.trajectory.rpe.windows_m.empty()) {
      report.rpe_index = closestWindow(options.trajectory.rpe.windows_m, options.rpe_window_m);
      report.rpe_window_m = options.trajectory.rpe.windows_m[report.rpe_index];
    }
    report.ate_improvement_percent = improvementPercent(report.dr.ate.horizontal_m.rmse, report.slam.ate.horizontal_m.rmse);
    report.aligned_ate_improvement_percent =
        improvementPercent(report.dr.ate.aligned_horizontal_m.rmse, report.slam.ate.aligned_horizontal_m.rmse);
    report.gauge_free_ate_improvement_percent =
        improvementPercent(report.dr.ate.gauge_free_horizontal_m.rmse, report.slam.ate.gauge_free_horizontal_m.rmse);

    // Optional inputs: each missing or unusable one becomes a note.
    readHeightmaps(report, request);
    report.closures_path = joinPath(request.run_dir, "loop_closures.csv");
    if (!fileExists(report.closures_path)) {
      report.notes.push_back("no loop_closures.csv in the run folder (" + report.closures_path + "): no closure graph");
    } else if (const Status read = readLoopClosures(report.closures_path, report.closures); !read) {
      report.notes.push_back("loop closures unusable, no closure graph: " + read.message);
    } else {
      report.has_closures = true;
      report.closure_counts = countClosures(report.closures);
      // The centres are in the run's frame (its own origin, e.g. its first fix); the figures draw
      // in the truth's, as the trajectories and heightmaps are.
      if (run_origin && report.truth_origin && !sameOrigin(*run_origin, *report.truth_origin)) {
        for (LoopClosureRecord& closure : report.closures) {
          for (Eigen::Vector2d* centre : {&closure.centre_a_north_east_m, &closure.centre_b_north_east_m}) {
            *centre = reexpressPosition({centre->x(), centre->y(), 0.0}, *run_origin, *report.truth_origin).head<2>();
          }
        }
      }
      // The same file as sss-eval --closures reads: relative pose errors of the accepted closures.
      std::vector<ClosureRecord> records;
      if (const Status read = readClosureCsv(report.closures_path, records); !read) {
        report.notes.push_back("loop closures without relative poses, no closure errors: " + read.message);
      } else {
        const ClosureEvaluation closures =
            evaluateClosures(records, truth, &dr, options.trajectory.association.max_interpolation_gap_s);
        for (const ClosureGroup& group : closures.groups) {
          if (group.status != "accepted") continue;
          report.has_closure_errors = true;
          report.closure_errors_accepted = group.count;
          report.closure_errors = group.closure;
          report.closure_errors_dr = group.dr;
        }
      }
    }
    if (!report.lines.empty()) {
      // Landmark consistency on correspondences made from the truth (sss-eval --lce).
      HeightmapRaster seabed;
      const std::string seabed_path = joinPath(request.mission_dir, "seabed.yaml");
      const bool have_seabed = fileExists(seabed_path) && readHeightmap(seabed_path, seabed, truthFrame(report)).ok;
      LandmarkConsistencyOptions model;
      model.seabed_depth_m = flatSeabedDepthM(truth, have_seabed ? &seabed : nullptr, options.lce_altitude_m,
                                              report.lce_seabed_depth_source);
      model.max_interpolation_gap_s = options.trajectory.association.max_interpolation_gap_s;
      const TrueCorrespondences pairs = generateTrueCorrespondences(truth, report.lines, options.lce, model);
      if (!pairs.pairs.empty()) {
        report.has_lce = true;
        report.lce_seabed_depth_m = model.seabed_depth_m;
        report.lce_correspondences = pairs.pairs.size();
        report.lce_truth_max_m = landmarkConsistency(truth, pairs.pairs, model).horizontal_m.max;
        report.lce_dr = landmarkConsistency(dr, pairs.pairs, model).horizontal_m;
        report.lce_slam = landmarkConsistency(slam, pairs.pairs, model).horizontal_m;
      }
    }
    const std::string summary_path = joinPath(request.run_dir, "summary.json");
    if (!fileExists(summary_path)) {
      report.notes.push_back("no summary.json in the run folder (" + summary_path + "): no run figures (time, memory)");
    } else if (const Status read_summary = readRunSummary(summary_path, report.summary); !read_summary) {
      report.notes.push_back("run summary unusable: " + read_summary.message);
    } else {
      report.has_summary = true;
      if (!report.summary.missing_keys.empty()) {
        std::string keys;
        for (const std::string& key : report.summary.missing_keys) keys += (keys.empty() ? "" : ", ") + key;
        report.notes.push_back(summary_path + " lacks numbers for: " + keys);
      }
    }
    GreyMosaic truth_mosaic;
    const GreyMosaic* background = nullptr;
    const std::string mosaic_path = joinPath(request.mission_dir, "mosaic.yaml");
    if (!fileExists(mosaic_path)) {
      report.notes.push_back("no true-pose mosaic (" + mosaic_path + "): trajectories drawn on a blank background");
    } else if (const Status read = readMosaic(mosaic_path, truth_mosaic); !read) {
      report.notes.push_back("true-pose mosaic unusable, trajectories drawn on a blank background: " + read.message);
    } else {
      background = &truth_mosaic;
    }
    makeVerdict(report, options);

    // Outputs.
    std::error_code ec;
    fs::create_directories(request.out_dir, ec);
    if (ec || !fs::is_directory(request.out_dir)) {
      return fail(RunReportStatus::write_failed,
                  "cannot create " + request.out_dir + (ec ? ": " + ec.message() : std::string()));
    }
    std::vector<Section> sections;
    FigureBatch figures{joinPath(request.out_dir, "figure_data"), Json::array(), ""};
    FigureContext context{request, report, sections, figures};
    const Json background_raster = background ? mosaicRaster(figures, *background, "mosaic_truth") : Json();
    trajectoryFigures(context, truth, background_raster);
    closureFigure(context, background_raster);
    mosaicFigure(context);
    heightmapFigures(context);
    productsSection(context);
    // Every figure in one run of the script (one interpreter start-up), then the pages.
    FigureRun drawn = drawFigures(figures, request.out_dir, request.figures);
    const std::string python_problem = pythonProblem(request.figures);
    if (!python_problem.empty()) {  // one note for the figures and the page
      drawn.problem = "figures and index.html not drawn: " + python_problem + "; report.md and metrics.json have every table";
    }
    dropUndrawnFigures(context, drawn);

    const Table key = keyTable(report, options);
    const std::vector<Table> tables = metricTables(report, options);
    std::vector<std::string> inputs = {report.truth_path, report.dr_path, report.slam_path};
    if (report.has_closures) inputs.push_back(report.closures_path);
    if (!report.seabed_path.empty()) inputs.push_back(report.seabed_path);
    for (const RunHeightmap* h : {&report.heightmap_dr, &report.heightmap_slam}) {
      if (h->present) inputs.push_back(h->path);
    }
    if (background) inputs.push_back(mosaic_path);
    if (report.has_summary) inputs.push_back(summary_path);

    const std::string html_path = joinPath(request.out_dir, "index.html");
    const std::string md_path = joinPath(request.out_dir, "report.md");
    const std::string json_path = joinPath(request.out_dir, "metrics.json");
    // The HTML page by report_page.py; without it report.md is the report.
    const Status page = drawPage(pageJson(report, request, key, sections, tables, inputs), figures.data_dir,
                                 request.out_dir, request.figures);
    if (page) {
      report.files.push_back(html_path);
    } else if (python_problem.empty()) {
      report.notes.push_back("index.html not written: " + page.message + "; report.md has the same content");
    }
    report.index_html = page ? html_path : md_path;
    // Files listed before they are written, so metrics.json lists itself and report.md.
    for (const std::string& path : {md_path, json_path}) report.files.push_back(path);
    Status written = writeText(md_path, renderMarkdown(report, request, key, sections, tables, inputs));
    if (written) written = writeText(json_path, runReportJson(report, request));
    if (!written) return fail(RunReportStatus::write_failed, written.message);
  } catch (const std::bad_alloc&) {
    return fail(RunReportStatus::bad_input, "out of memory; are the inputs the right files?");
  } catch (const std::exception& e) {
    return fail(RunReportStatus::bad_input, e.what());
  }
  return report;
}

std::string formatRunTable(const RunReport& report) {
  std::vector<std::vector<std::string>> rows = {{"", "DR", "SLAM", "improvement"}};
  rows.push_back({"horizontal ATE RMSE", metres(report.dr.ate.horizontal_m.rmse), metres(report.slam.ate.horizontal_m.rmse),
                  percent(report.ate_improvement_percent, true)});
  rows.push_back({"  SE(3)-aligned", metres(report.dr.ate.aligned_horizontal_m.rmse),
                  metres(report.slam.ate.aligned_horizontal_m.rmse), percent(report.aligned_ate_improvement_percent, true)});
  rows.push_back({"  gauge-free", metres(report.dr.ate.gauge_free_horizontal_m.rmse),
                  metres(report.slam.ate.gauge_free_horizontal_m.rmse),
                  percent(report.gauge_free_ate_improvement_percent, true)});
  if (report.has_lce) {
    rows.push_back({"LCE mean", metres(report.lce_dr.mean), metres(report.lce_slam.mean),
                    percent(improvementPercent(report.lce_dr.mean, report.lce_slam.mean), true)});
  }
  rows.push_back({"heightmap MAE", report.heightmap_dr.present ? metres(report.heightmap_dr.error.abs_error_m.mean) : "-",
                  report.heightmap_slam.present ? metres(report.heightmap_slam.error.abs_error_m.mean) : "-",
                  percent(report.heightmap_improvement_percent, true)});
  std::string out = report.title + "\n" + report.verdict + "\n\n" + formatColumns(rows);
  // Free-text rows under the table, their values starting at its second column.
  const size_t indent = std::string("horizontal ATE RMSE").size() + 2;
  const auto line = [&](const std::string& label, const std::string& value) {
    out += label + std::string(indent > label.size() ? indent - label.size() : 1, ' ') + value + "\n";
  };
  line("closures", closureSummaryText(report));
  if (report.has_summary) line("real-time factor", realTimeText(report.summary));
  line("report", report.index_html);
  return out;
}

std::string runReportJson(const RunReport& report, const RunReportRequest& request) {
  Json json = Json::object();
  json["schema"] = jsonValue("sss-report/1");
  json["title"] = jsonValue(report.title);
  json["mission_dir"] = jsonValue(request.mission_dir);
  json["run_dir"] = jsonValue(request.run_dir);
  json["out_dir"] = jsonValue(request.out_dir);
  json["verdict"] = jsonValue(report.verdict);
  json["outcome"] = jsonValue(report.outcome);

  Json& trajectory_json = (json["trajectory"] = Json::object());
  trajectory_json["truth_path"] = jsonValue(report.truth_path);
  trajectory_json["truth_poses"] = jsonValue(static_cast<uint64_t>(report.truth_poses));
  trajectory_json["duration_s"] = jsonValue(report.duration_s);
  trajectory_json["distance_m"] = jsonValue(report.distance_m);
  Json& lines_json = (trajectory_json["lines"] = Json::array());
  for (const SurveyLine& line : report.lines) {
    Json& line_json = lines_json.emplace_back(Json::object());
    line_json["index"] = jsonValue(line.index);
    line_json["length_m"] = jsonValue(line.length_m);
    line_json["heading_deg"] = jsonValue(line.heading_deg);
  }
  trajectory_json["rpe_window_m"] = jsonValue(report.rpe_window_m);
  for (const auto& [key, path, evaluation] :
       {std::tuple{"dr", report.dr_path, &report.dr}, std::tuple{"slam", report.slam_path, &report.slam}}) {
    Json& estimate_json = (trajectory_json[key] = Json::object());
    estimate_json["path"] = jsonValue(path);
    estimate_json["poses"] = jsonValue(static_cast<uint64_t>(evaluation->estimate_poses));
    estimate_json["matched"] = jsonValue(static_cast<uint64_t>(evaluation->association.pairs.size()));
    writeErrorStatistics(estimate_json, "ate_horizontal_m", evaluation->ate.horizontal_m);
    writeErrorStatistics(estimate_json, "ate_aligned_horizontal_m", evaluation->ate.aligned_horizontal_m);
    writeErrorStatistics(estimate_json, "ate_gauge_free_horizontal_m", evaluation->ate.gauge_free_horizontal_m);
    estimate_json["gauge_free_scale"] = jsonValue(evaluation->ate.gauge_free_scale);
    estimate_json["gauge_free_rotation_deg"] = jsonValue(evaluation->ate.gauge_free_rotation_deg);
    writeErrorStatistics(estimate_json, "ate_position_m", evaluation->ate.position_m);
    const bool has_rpe = report.rpe_index < evaluation->rpe.size();
    estimate_json["rpe_translation_percent"] = jsonValue(has_rpe ? evaluation->rpe[report.rpe_index].translation_percent.mean : kNaN);
    estimate_json["rpe_rotation_deg"] = jsonValue(has_rpe ? evaluation->rpe[report.rpe_index].rotation_deg.mean : kNaN);
    Json& estimate_lines_json = (estimate_json["lines"] = Json::array());
    for (const LineError& line : evaluation->lines) {
      Json& line_json = estimate_lines_json.emplace_back(Json::object());
      line_json["index"] = jsonValue(line.line);
      line_json["horizontal_rmse_m"] = jsonValue(line.horizontal_m.rmse);
    }
  }
  trajectory_json["ate_horizontal_rmse_improvement_percent"] = jsonValue(report.ate_improvement_percent);
  trajectory_json["ate_aligned_horizontal_rmse_improvement_percent"] = jsonValue(report.aligned_ate_improvement_percent);
  trajectory_json["ate_gauge_free_horizontal_rmse_improvement_percent"] = jsonValue(report.gauge_free_ate_improvement_percent);

  if (report.heightmap_dr.present || report.heightmap_slam.present) {
    Json& heightmap_json = (json["heightmap"] = Json::object());
    heightmap_json["seabed_path"] = jsonValue(report.seabed_path);
    for (const auto& [key, entry] : {std::pair{"dr", &report.heightmap_dr}, std::pair{"slam", &report.heightmap_slam}}) {
      if (!entry->present) {
        heightmap_json[key] = nullptr;
        continue;
      }
      const HeightmapErrorResult& r = entry->error;
      Json& heightmap_entry_json = (heightmap_json[key] = Json::object());
      heightmap_entry_json["path"] = jsonValue(entry->path);
      heightmap_entry_json["mae_m"] = jsonValue(r.abs_error_m.mean);
      heightmap_entry_json["rmse_m"] = jsonValue(r.abs_error_m.rmse);
      heightmap_entry_json["median_m"] = jsonValue(r.abs_error_m.median);
      heightmap_entry_json["max_m"] = jsonValue(r.abs_error_m.max);
      heightmap_entry_json["bias_m"] = jsonValue(r.mean_signed_error_m);
      heightmap_entry_json["coverage_fraction"] = jsonValue(r.coverage_fraction);
      heightmap_entry_json["compared_cells"] = jsonValue(static_cast<uint64_t>(r.compared_cells));
    }
    heightmap_json["mae_improvement_percent"] = jsonValue(report.heightmap_improvement_percent);
  } else {
    json["heightmap"] = nullptr;
  }

  if (report.has_closures) {
    const LoopClosureCounts& c = report.closure_counts;
    Json& closures_json = (json["closures"] = Json::object());
    closures_json["path"] = jsonValue(report.closures_path);
    closures_json["accepted"] = jsonValue(static_cast<uint64_t>(c.accepted));
    closures_json["rejected"] = jsonValue(static_cast<uint64_t>(c.rejected));
    closures_json["pending"] = jsonValue(static_cast<uint64_t>(c.pending));
    closures_json["superseded"] = jsonValue(static_cast<uint64_t>(c.superseded));
    closures_json["total"] = jsonValue(static_cast<uint64_t>(c.total()));
    Json& rejection_reasons_json = (closures_json["rejection_reasons"] = Json::object());
    for (const auto& [reason, n] : c.rejection_reasons) rejection_reasons_json[reason] = jsonValue(static_cast<uint64_t>(n));
  } else {
    json["closures"] = nullptr;
  }

  if (report.has_closure_errors) {
    Json& closure_errors_json = (json["closure_errors"] = Json::object());
    closure_errors_json["accepted"] = jsonValue(static_cast<uint64_t>(report.closure_errors_accepted));
    writeRelativePoseErrorStatistics(closure_errors_json, "closure", report.closure_errors);
    writeRelativePoseErrorStatistics(closure_errors_json, "dr", report.closure_errors_dr);
  } else {
    json["closure_errors"] = nullptr;
  }
  if (report.has_lce) {
    Json& lce_json = (json["lce"] = Json::object());
    lce_json["seabed_depth_m"] = jsonValue(report.lce_seabed_depth_m);
    lce_json["seabed_depth_source"] = jsonValue(report.lce_seabed_depth_source);
    lce_json["correspondences"] = jsonValue(static_cast<uint64_t>(report.lce_correspondences));
    lce_json["truth_max_m"] = jsonValue(report.lce_truth_max_m);
    writeErrorStatistics(lce_json, "dr", report.lce_dr);
    writeErrorStatistics(lce_json, "slam", report.lce_slam);
    lce_json["mean_improvement_percent"] = jsonValue(improvementPercent(report.lce_dr.mean, report.lce_slam.mean));
  } else {
    json["lce"] = nullptr;
  }

  if (report.has_summary) {
    const RunSummary& s = report.summary;
    Json& run_json = (json["run"] = Json::object());
    run_json["pings"] = jsonValue(s.pings);
    run_json["subframes"] = jsonValue(s.subframes);
    run_json["pairs_attempted"] = jsonValue(s.pairs_attempted);
    run_json["closures_accepted"] = jsonValue(s.closures_accepted);
    run_json["closures_rejected"] = jsonValue(s.closures_rejected);
    run_json["wall_s"] = jsonValue(s.wall_s);
    run_json["mission_s"] = jsonValue(s.mission_s);
    run_json["real_time_factor"] = jsonValue(s.real_time_factor);
    run_json["peak_rss_mib"] = jsonValue(s.peak_rss_mib);
  } else {
    json["run"] = nullptr;
  }

  Json& notes_json = (json["notes"] = Json::array());
  for (const std::string& note : report.notes) notes_json.push_back(jsonValue(note));
  Json& files_json = (json["files"] = Json::array());
  for (const std::string& file : report.files) files_json.push_back(jsonValue(file));
  return json.dump(2) + "\n";
}

}  // namespace sss::eval
