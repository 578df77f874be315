// The per-run report's figures and metric tables. See run_report.hpp.
#include "tools/eval/run_report_internal.hpp"

namespace sss::eval::report_internal {


void trajectoryFigures(FigureContext& context, const Trajectory& truth, const Json& background) {
  RunReport& report = context.report;
  Section section{"1. Trajectories over the mosaic", "", {}, {}};
  Json& map = addFigure(context.figures, "map", "trajectories.png",
                        background.is_null()
                            ? "Trajectories: truth, dead reckoning (DR), SLAM (no mosaic in the mission folder)"
                            : "Trajectories over the true-pose mosaic: truth, dead reckoning (DR), SLAM");
  map["background"] = background;
  map["lines"] = {mapLine("truth", northEast(truth), "black", 3.0, true, true),
                  mapLine("dead reckoning (DR)", estimateNorthEast(report.dr), paletteColour(kDrColour), 2.0),
                  mapLine("SLAM", estimateNorthEast(report.slam), paletteColour(kSlamColour), 2.0)};
  map["note"] = "horizontal error RMSE: DR " + metres(report.dr.ate.horizontal_m.rmse) + " (max " +
                metres(report.dr.ate.horizontal_m.max) + "), SLAM " + metres(report.slam.ate.horizontal_m.rmse) +
                " (max " + metres(report.slam.ate.horizontal_m.max) + "); lines closer than a pixel overlap";
  section.figures.push_back({"", "trajectories.png", "trajectories over the mosaic",
                             "Truth (white, black outline), DR (orange) and SLAM (cyan) over the mosaic rendered from "
                             "the true poses. The error over time below resolves what is finer than a pixel here."});
  context.sections.push_back(section);

  Section errors{"2. Horizontal error over time", "", {}, {}};
  const int64_t t0 = truth.front().utime_us;
  Json& plot = addFigure(context.figures, "curves", "error_over_time.png",
                         "Horizontal position error against the truth: DR vs SLAM");
  plot["x_label"] = "time since start (min)";
  plot["y_label"] = "horizontal error (m)";
  plot["curves"] = Json::array();
  for (const auto& [label, evaluation, colour] :
       {std::tuple{std::string("DR"), &report.dr, kDrColour}, std::tuple{std::string("SLAM"), &report.slam, kSlamColour}}) {
    for (Json& curve : horizontalErrorCurves(label, evaluation->series, paletteColour(colour), t0)) {
      plot["curves"].push_back(std::move(curve));
    }
  }
  plot["bands"] = surveyLineBands(report.lines, t0);
  errors.figures.push_back({"", "error_over_time.png", "horizontal error over time",
                            "Solid: raw error; dashed: after the best rigid (SE(3)) alignment of the whole trajectory, "
                            "i.e. the shape error without the global offset. Shaded: survey lines."});
  context.sections.push_back(errors);
}

// The tie report as mbnavadjust users read it: each closure's offset from DR's relative pose
// (before the solve) and from the final estimate's (after), and the decision. The largest
// offsets before the solve first; at most kMaxTieRows rows (loop_closures.csv has them all).
constexpr size_t kMaxTieRows = 60;
Table tieTable(const std::vector<LoopClosureRecord>& closures) {
  Table table;
  std::vector<const LoopClosureRecord*> ties;
  for (const LoopClosureRecord& r : closures) {
    if (r.before && r.after) ties.push_back(&r);
  }
  if (ties.empty()) return table;
  std::stable_sort(ties.begin(), ties.end(), [](const LoopClosureRecord* a, const LoopClosureRecord* b) {
    return a->before->head<2>().norm() > b->before->head<2>().norm();
  });
  table.caption = "Tie report: offset of each closure from DR (before) and from the solution (after), along / across "
                  "/ depth in m and heading in deg, in A's body frame" +
                  (ties.size() > kMaxTieRows ? " (the " + std::to_string(kMaxTieRows) + " largest of " +
                                                   std::to_string(ties.size()) + "; all in loop_closures.csv)"
                                             : std::string());
  table.header = {"subframes", "decision", "before along", "across", "depth", "heading", "after along", "across",
                  "depth", "heading"};
  for (size_t i = 0; i < ties.size() && i < kMaxTieRows; ++i) {
    const LoopClosureRecord& r = *ties[i];
    std::vector<Cell> row = {{r.subframes.empty() ? "line " + std::to_string(r.line) : r.subframes},
                             {r.status + (r.status == "rejected" && !r.rejection.empty() ? " (" + r.rejection + ")" : "")}};
    for (const Eigen::Vector4d* offset : {&*r.before, &*r.after}) {
      for (int k = 0; k < 3; ++k) row.push_back({fixed((*offset)(k), 2)});
      row.push_back({fixed((*offset)(3) * 180.0 / M_PI, 2)});
    }
    // Accepted closures the solution does not explain within a metre stand out.
    if (r.status == "accepted" && r.after->head<2>().norm() > 1.0) {
      for (size_t c = 6; c < 8; ++c) row[c].tone = -1;
    }
    table.rows.push_back(std::move(row));
  }
  return table;
}

void closureFigure(FigureContext& context, const Json& background) {
  RunReport& report = context.report;
  Section section{"3. Loop closures", "", {}, {}};
  if (!report.has_closures) {
    section.text = "No loop-closure file: this section is empty (see the notes).";
    context.sections.push_back(section);
    return;
  }
  const LoopClosureCounts& c = report.closure_counts;
  Json& map = addFigure(context.figures, "map", "loop_closures.png", "Loop closures between subframes over the SLAM trajectory");
  map["background"] = background;
  if (!background.is_null()) map["background"]["alpha"] = 0.45;  // faded, so the graph reads first
  map["lines"] = {mapLine("SLAM trajectory", estimateNorthEast(report.slam), "#464646", 1.0, true)};
  const auto segments = [&](const std::string& status, const std::string& label, const std::string& colour) {
    Json pairs = Json::array();
    for (const LoopClosureRecord& r : report.closures) {
      const bool other = r.status != "accepted" && r.status != "rejected";
      if (r.status != status && !(status == "other" && other)) continue;
      pairs.push_back({{r.centre_a_north_east_m.x(), r.centre_a_north_east_m.y()},
                       {r.centre_b_north_east_m.x(), r.centre_b_north_east_m.y()}});
    }
    return Json{{"label", label}, {"colour", colour}, {"north_east_m", std::move(pairs)}};
  };
  map["segments"] = Json::array();  // drawn in order: accepted last, on top
  if (c.superseded + c.pending > 0) {
    map["segments"].push_back(
        segments("other", "superseded / pending (" + std::to_string(c.superseded + c.pending) + ")", paletteColour(7)));
  }
  map["segments"].push_back(segments("rejected", "rejected (" + std::to_string(c.rejected) + ")", paletteColour(3)));
  map["segments"].push_back(segments("accepted", "accepted (" + std::to_string(c.accepted) + ")", paletteColour(2)));
  map["note"] = "each segment joins the centres of the two subframes of a closure (final SLAM estimate)";
  std::string caption = "Green: accepted closures; red: rejected";
  if (!c.rejection_reasons.empty()) {
    caption += " (";
    bool first = true;
    for (const auto& [reason, n] : c.rejection_reasons) {
      caption += (first ? "" : ", ") + reason + " " + std::to_string(n);
      first = false;
    }
    caption += ")";
  }
  caption += "; grey: superseded or still pending.";
  section.figures.push_back({"", "loop_closures.png", "loop-closure graph", caption});
  section.tables.push_back(tieTable(report.closures));
  if (section.tables.back().rows.empty()) section.tables.pop_back();
  context.sections.push_back(section);
}

// What the run leaves for the survey: coverage, the fixes and calibration, the GeoTIFFs.
void productsSection(FigureContext& context) {
  const RunReport& report = context.report;
  if (!report.has_summary) return;
  const RunSummary& s = report.summary;
  Section section{"6. Survey products", "", {}, {}};
  std::string text;
  if (std::isfinite(s.covered_m2)) {
    text += "Coverage under the SLAM poses: " + fixed(s.covered_m2 / 10000.0, 2) + " ha, " +
            fixed(100.0 * s.fraction_seen_twice, 1) + " % of it seen from two lines or more (what side-scan " +
            "SLAM can use). ";
  }
  if (!s.geotiffs.empty()) {
    text += "GeoTIFFs (" + (s.geotiff_crs.empty() ? std::string("no CRS: set products.projected_crs") : s.geotiff_crs) +
            "): ";
    for (size_t i = 0; i < s.geotiffs.size(); ++i) text += (i ? ", " : "") + s.geotiffs[i];
    text += ".";
  }
  section.text = text;
  const std::string coverage_png = joinPath(context.request.run_dir, "coverage.png");
  if (fileExists(coverage_png)) {
    std::error_code ec;
    fs::copy_file(coverage_png, joinPath(context.request.out_dir, "coverage.png"),
                  fs::copy_options::overwrite_existing, ec);
    if (!ec) {
      section.figures.push_back({"", "coverage.png", "coverage",
                                 "Survey lines that saw each 5 m cell: grey one, green two, blue three or more."});
    }
  }
  Table fixes;
  fixes.caption = "Absolute fixes and DR calibration (final smoothing)";
  fixes.header = {"quantity", "value", "sigma"};
  if (std::isfinite(s.fixes_fed) && s.fixes_fed > 0) {
    fixes.rows.push_back({{"fixes accepted / given"},
                          {fixed(s.fixes_accepted, 0) + " / " + fixed(s.fixes_fed, 0)},
                          {""}});
    fixes.rows.push_back({{"fix residual RMS (m)"}, {fixed(s.fixes_rms_residual_m, 2)}, {""}});
  }
  if (s.calibration_estimated && std::isfinite(s.dvl_scale_sigma)) {
    fixes.rows.push_back({{"DVL scale error (%)"},
                          {fixed(100.0 * s.dvl_scale, 3)},
                          {fixed(100.0 * s.dvl_scale_sigma, 3)}});
  }
  if (s.calibration_estimated) {
    fixes.rows.push_back({{"heading bias (deg)"},
                          {fixed(s.heading_bias_rad * 180.0 / M_PI, 3)},
                          {fixed(s.heading_bias_sigma_rad * 180.0 / M_PI, 3)}});
  }
  if (!fixes.rows.empty()) section.tables.push_back(fixes);
  if (section.text.empty() && section.figures.empty() && section.tables.empty()) return;
  context.sections.push_back(section);
}

void mosaicFigure(FigureContext& context) {
  Section section{"4. Mosaics: DR vs SLAM", "", {}, {}};
  Json panels = Json::array();
  for (auto [name, label] : {std::pair{"mosaic_dr", "dead reckoning (DR)"}, std::pair{"mosaic_slam", "SLAM"}}) {
    const std::string path = joinPath(context.request.run_dir, std::string(name) + ".yaml");
    GreyMosaic mosaic;
    if (!fileExists(path)) {
      context.report.notes.push_back("no " + std::string(name) + ".yaml in the run folder (" + path +
                                     "): no mosaic comparison");
    } else if (const sss::core::Status read = readMosaic(path, mosaic); !read) {
      context.report.notes.push_back("mosaic unusable, no mosaic comparison: " + read.message);
    } else {
      Json panel = mosaicRaster(context.figures, mosaic, name);
      panel["label"] = label;
      panels.push_back(std::move(panel));
    }
  }
  if (panels.size() == 2) {
    addFigure(context.figures, "mosaics", "mosaics_dr_slam.png", "Mosaics rendered with the DR and the SLAM navigation")
        ["panels"] = std::move(panels);
    section.figures.push_back({"", "mosaics_dr_slam.png", "DR vs SLAM mosaics",
                               "Where lines overlap, features should be single and sharp; doubled or smeared features "
                               "show navigation error."});
  } else {
    section.text = "Not available (see the notes).";
  }
  context.sections.push_back(section);
}

void heightmapFigures(FigureContext& context) {
  RunReport& report = context.report;
  Section section{"5. Heightmaps", "", {}, {}};
  const std::string slam_path = joinPath(context.request.run_dir, "heightmap.yaml");
  HeightmapRaster slam;
  if (fileExists(slam_path) && readHeightmap(slam_path, slam).ok) {
    char title[256];
    std::snprintf(title, sizeof title, "SLAM heightmap: %.2g m cells, grid %zu x %zu", slam.resolution_m,
                  static_cast<size_t>(slam.cols), static_cast<size_t>(slam.rows));
    addFigure(context.figures, "depth", "heightmap_slam.png", title)["raster"] =
        heightmapRaster(context.figures, cropToData(slam), "heightmap_slam");
    section.figures.push_back({"depth", "heightmap_slam.png", "SLAM heightmap", "Gridded bathymetry from the SLAM poses."});
  }
  std::vector<const HeightmapRaster*> maps;
  for (const RunHeightmap* h : {&report.heightmap_dr, &report.heightmap_slam}) {
    if (h->present) maps.push_back(&h->error.error_map);
  }
  const double limit_m = maps.empty() ? 0.0 : sharedErrorLimit(maps);
  for (const auto& [label, name, entry] :
       {std::tuple{std::string("DR"), std::string("heightmap_error_dr"), &report.heightmap_dr},
        std::tuple{std::string("SLAM"), std::string("heightmap_error_slam"), &report.heightmap_slam}}) {
    if (!entry->present) continue;
    char title[256];
    std::snprintf(title, sizeof title, "Heightmap error, %s: MAE %.3f m, bias %+.3f m", label.c_str(),
                  entry->error.abs_error_m.mean, entry->error.mean_signed_error_m);
    Json& figure = addFigure(context.figures, "error_map", name + ".png", title);
    figure["raster"] = heightmapRaster(context.figures, cropToData(entry->error.error_map), name);
    figure["limit_m"] = limit_m;
    section.figures.push_back({"errors", name + ".png", label + " heightmap error",
                               label + " heightmap minus the true seabed (same colour scale for DR and SLAM)."});
  }
  if (section.figures.empty()) section.text = "Not available (see the notes).";
  context.sections.push_back(section);
}

void dropUndrawnFigures(FigureContext& context, const FigureRun& run) {
  for (const std::string& path : run.written) context.report.files.push_back(path);
  if (!run.problem.empty()) context.report.notes.push_back(run.problem);
  for (Section& section : context.sections) {
    const size_t before = section.figures.size();
    const auto undrawn = [&](const Figure& figure) {
      return std::find(run.missing.begin(), run.missing.end(), figure.file) != run.missing.end();
    };
    section.figures.erase(std::remove_if(section.figures.begin(), section.figures.end(), undrawn),
                          section.figures.end());
    if (section.figures.size() < before && section.figures.empty() && section.text.empty()) {
      section.text = "Figures not drawn (see the notes).";
    }
  }
}

// ---- tables --------------------------------------------------------------------------------

std::vector<Table> metricTables(const RunReport& report, const RunReportOptions& options) {
  const double same = options.same_change_percent;
  std::vector<Table> tables;
  Table trajectory{"Trajectory against the truth (" + std::to_string(report.truth_poses) + " poses, " +
                       fixed(report.duration_s / 60.0, 1) + " min, " + fixed(report.distance_m, 0) + " m)",
                   {"metric", "DR", "SLAM", "improvement"},
                   {}};
  const auto row = [&](const std::string& name, double dr, double slam, const std::string& unit, int decimals) {
    trajectory.rows.push_back({{name}, {fixed(dr, decimals) + unit}, {fixed(slam, decimals) + unit},
                               improvementCell(improvementPercent(dr, slam), same)});
  };
  const AteResult& d = report.dr.ate;
  const AteResult& s = report.slam.ate;
  row("ATE horizontal RMSE", d.horizontal_m.rmse, s.horizontal_m.rmse, " m", 3);
  row("ATE horizontal max", d.horizontal_m.max, s.horizontal_m.max, " m", 3);
  row("ATE horizontal RMSE, SE(3)-aligned", d.aligned_horizontal_m.rmse, s.aligned_horizontal_m.rmse, " m", 3);
  row("ATE horizontal max, SE(3)-aligned", d.aligned_horizontal_m.max, s.aligned_horizontal_m.max, " m", 3);
  row("ATE horizontal RMSE, gauge-free", d.gauge_free_horizontal_m.rmse, s.gauge_free_horizontal_m.rmse, " m", 3);
  row("ATE horizontal max, gauge-free", d.gauge_free_horizontal_m.max, s.gauge_free_horizontal_m.max, " m", 3);
  // The fitted gauge itself: no better or worse, so no improvement cell.
  trajectory.rows.push_back({{"gauge fit: rotation about the start (clockwise +)"},
                             {fixed(d.gauge_free_rotation_deg, 4) + " deg"},
                             {fixed(s.gauge_free_rotation_deg, 4) + " deg"},
                             {""}});
  trajectory.rows.push_back(
      {{"gauge fit: scale about the start"}, {fixed(d.gauge_free_scale, 5)}, {fixed(s.gauge_free_scale, 5)}, {""}});
  row("ATE 3D RMSE", d.position_m.rmse, s.position_m.rmse, " m", 3);
  if (!report.dr.rpe.empty() && !report.slam.rpe.empty()) {
    const std::string window = fixed(report.rpe_window_m, 0) + " m";
    row("RPE per " + window + ", translation (mean)", report.dr.rpe[report.rpe_index].translation_percent.mean,
        report.slam.rpe[report.rpe_index].translation_percent.mean, " %", 3);
    row("RPE per " + window + ", rotation (mean)", report.dr.rpe[report.rpe_index].rotation_deg.mean,
        report.slam.rpe[report.rpe_index].rotation_deg.mean, " deg", 3);
  }
  const auto matched = [](const TrajectoryEvaluation& e) {
    return std::to_string(e.association.pairs.size()) + "/" + std::to_string(e.estimate_poses);
  };
  if (report.has_lce) {
    row("landmark consistency error (LCE) mean", report.lce_dr.mean, report.lce_slam.mean, " m", 3);
    row("landmark consistency error (LCE) RMSE", report.lce_dr.rmse, report.lce_slam.rmse, " m", 3);
  }
  if (report.has_closure_errors) {
    // DR column: DR's relative pose between the two subframe centres; SLAM column: the closure's.
    const std::string accepted = " (" + std::to_string(report.closure_errors_accepted) + " accepted)";
    row("closure relative pose error RMS, horizontal" + accepted, report.closure_errors_dr.horizontal_m.rmse,
        report.closure_errors.horizontal_m.rmse, " m", 3);
    row("closure relative pose error RMS, lateral" + accepted, report.closure_errors_dr.lateral_m.abs.rmse,
        report.closure_errors.lateral_m.abs.rmse, " m", 3);
    row("closure relative pose error RMS, heading" + accepted, report.closure_errors_dr.heading_deg.abs.rmse,
        report.closure_errors.heading_deg.abs.rmse, " deg", 3);
  }
  trajectory.rows.push_back({{"poses matched to the truth"}, {matched(report.dr)}, {matched(report.slam)}, {""}});
  tables.push_back(trajectory);

  if (!report.lines.empty()) {
    Table lines{"Horizontal ATE RMSE per survey line (raw)", {"line", "heading", "length", "DR", "SLAM", "improvement"}, {}};
    for (const SurveyLine& line : report.lines) {
      const double dr = lineRmse(report.dr, line.index), slam = lineRmse(report.slam, line.index);
      lines.rows.push_back({{"line " + std::to_string(line.index)}, {fixed(line.heading_deg, 0) + " deg"},
                            {fixed(line.length_m, 0) + " m"}, {fixed(dr, 3) + " m"}, {fixed(slam, 3) + " m"},
                            improvementCell(improvementPercent(dr, slam), same)});
    }
    tables.push_back(lines);
  }

  if (report.heightmap_dr.present || report.heightmap_slam.present) {
    Table heightmap{"Heightmap against the true seabed", {"metric", "DR", "SLAM", "improvement"}, {}};
    const HeightmapErrorResult& a = report.heightmap_dr.error;
    const HeightmapErrorResult& b = report.heightmap_slam.error;
    const bool has_a = report.heightmap_dr.present, has_b = report.heightmap_slam.present;
    const auto value = [](bool has, double v, const std::string& unit, int decimals) {
      return has ? fixed(v, decimals) + unit : std::string("-");
    };
    const auto hm_row = [&](const std::string& name, double va, double vb, const std::string& unit, int decimals,
                            bool improvement) {
      heightmap.rows.push_back({{name}, {value(has_a, va, unit, decimals)}, {value(has_b, vb, unit, decimals)},
                                improvement && has_a && has_b ? improvementCell(improvementPercent(va, vb), same) : Cell{""}});
    };
    hm_row("MAE", a.abs_error_m.mean, b.abs_error_m.mean, " m", 3, true);
    hm_row("RMSE", a.abs_error_m.rmse, b.abs_error_m.rmse, " m", 3, true);
    hm_row("max |error|", a.abs_error_m.max, b.abs_error_m.max, " m", 3, false);
    hm_row("bias (estimate - truth)", a.mean_signed_error_m, b.mean_signed_error_m, " m", 3, false);
    hm_row("coverage of the grid", 100.0 * a.coverage_fraction, 100.0 * b.coverage_fraction, " %", 1, false);
    tables.push_back(heightmap);
  }

  Table run{"The run", {"figure", "value"}, {}};
  const LoopClosureCounts& c = report.closure_counts;
  if (report.has_closures) {
    run.rows.push_back({{"closures accepted"}, {std::to_string(c.accepted)}});
    std::string rejected = std::to_string(c.rejected);
    if (!c.rejection_reasons.empty()) {
      rejected += " (";
      bool first = true;
      for (const auto& [reason, n] : c.rejection_reasons) {
        rejected += (first ? "" : ", ") + reason + " " + std::to_string(n);
        first = false;
      }
      rejected += ")";
    }
    run.rows.push_back({{"closures rejected"}, {rejected}});
    run.rows.push_back({{"closures superseded / pending"}, {std::to_string(c.superseded) + " / " + std::to_string(c.pending)}});
  }
  if (report.has_summary) {
    const RunSummary& m = report.summary;
    if (!report.has_closures) {
      run.rows.push_back({{"closures accepted"}, {count(m.closures_accepted)}});
      run.rows.push_back({{"closures rejected"}, {count(m.closures_rejected)}});
    }
    run.rows.push_back({{"subframe pairs attempted"}, {count(m.pairs_attempted)}});
    run.rows.push_back({{"pings"}, {count(m.pings)}});
    run.rows.push_back({{"subframes"}, {count(m.subframes)}});
    run.rows.push_back({{"mission duration"}, {fixed(m.mission_s, 0) + " s"}});
    run.rows.push_back({{"wall time"}, {fixed(m.wall_s, 1) + " s"}});
    run.rows.push_back({{"real-time factor"}, {realTimeText(m)}});
    run.rows.push_back({{"peak memory (RSS)"}, {fixed(m.peak_rss_mib, 0) + " MiB"}});
  }
  if (!run.rows.empty()) tables.push_back(run);
  return tables;
}

// The few numbers an engineer reads first.
Table keyTable(const RunReport& report, const RunReportOptions& options) {
  const double same = options.same_change_percent;
  Table table{"", {"", "DR", "SLAM", "improvement"}, {}};
  table.rows.push_back({{"horizontal position error RMSE"}, {metres(report.dr.ate.horizontal_m.rmse)},
                        {metres(report.slam.ate.horizontal_m.rmse)}, improvementCell(report.ate_improvement_percent, same)});
  table.rows.push_back({{"after SE(3) alignment (shape)"}, {metres(report.dr.ate.aligned_horizontal_m.rmse)},
                        {metres(report.slam.ate.aligned_horizontal_m.rmse)},
                        improvementCell(report.aligned_ate_improvement_percent, same)});
  table.rows.push_back({{"gauge-free (what side-scan can see)"}, {metres(report.dr.ate.gauge_free_horizontal_m.rmse)},
                        {metres(report.slam.ate.gauge_free_horizontal_m.rmse)},
                        improvementCell(report.gauge_free_ate_improvement_percent, same)});
  if (report.heightmap_dr.present || report.heightmap_slam.present) {
    table.rows.push_back({{"heightmap MAE"},
                          {report.heightmap_dr.present ? metres(report.heightmap_dr.error.abs_error_m.mean) : "-"},
                          {report.heightmap_slam.present ? metres(report.heightmap_slam.error.abs_error_m.mean) : "-"},
                          improvementCell(report.heightmap_improvement_percent, same)});
  }
  table.rows.push_back({{"closures"}, {closureSummaryText(report), 0, 3}});
  if (report.has_summary) table.rows.push_back({{"real-time factor"}, {realTimeText(report.summary), 0, 3}});
  return table;
}

}  // namespace sss::eval::report_internal
