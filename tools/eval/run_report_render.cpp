// The per-run report as report.md, and the model of index.html that report_page.py renders. See
// run_report.hpp.
#include "tools/eval/run_report_internal.hpp"

namespace sss::eval::report_internal {

// ---- Markdown and the page model --------------------------------------------------------------

std::string markdownTable(const Table& table) {
  std::ostringstream out;
  if (!table.caption.empty()) out << "**" << markdownEscape(table.caption) << "**\n\n";
  out << "|";
  for (const std::string& h : table.header) out << " " << markdownEscape(h) << " |";
  out << "\n|";
  for (size_t c = 0; c < table.header.size(); ++c) out << (c == 0 ? " --- |" : " ---: |");
  out << "\n";
  for (const auto& row : table.rows) {
    out << "|";
    for (const Cell& cell : row) {
      out << " " << markdownEscape(cell.text) << " |";
      for (int k = 1; k < cell.span; ++k) out << " |";
    }
    out << "\n";
  }
  return out.str() + "\n";
}

namespace {

Json tableJson(const Table& table) {
  Json rows = Json::array();
  for (const auto& row : table.rows) {
    Json cells = Json::array();
    for (const Cell& cell : row) cells.push_back({{"text", cell.text}, {"tone", cell.tone}, {"span", cell.span}});
    rows.push_back(std::move(cells));
  }
  return {{"caption", table.caption}, {"header", table.header}, {"rows", std::move(rows)}};
}

}  // namespace

Json pageJson(const RunReport& report, const RunReportRequest& request, const Table& key,
              const std::vector<Section>& sections, const std::vector<Table>& tables,
              const std::vector<std::string>& inputs) {
  Json page = Json::object();
  page["schema"] = "sss-report-page/1";
  page["title"] = report.title;
  page["mission_dir"] = request.mission_dir;
  page["run_dir"] = request.run_dir;
  page["outcome"] = report.outcome;
  page["verdict"] = report.verdict;
  page["key"] = tableJson(key);
  page["notes"] = report.notes;
  Json section_list = Json::array();
  for (const Section& section : sections) {
    Json figures = Json::array(), section_tables = Json::array();
    for (const Figure& f : section.figures) {
      figures.push_back({{"group", f.section}, {"file", f.file}, {"alt", f.alt}, {"caption", f.caption}});
    }
    for (const Table& table : section.tables) section_tables.push_back(tableJson(table));
    section_list.push_back({{"heading", section.heading},
                            {"text", section.text},
                            {"figures", std::move(figures)},
                            {"tables", std::move(section_tables)}});
  }
  page["sections"] = std::move(section_list);
  Json metric_tables = Json::array();
  for (const Table& table : tables) metric_tables.push_back(tableJson(table));
  page["metric_tables"] = std::move(metric_tables);
  page["inputs"] = inputs;
  return page;
}

std::string renderMarkdown(const RunReport& report, const RunReportRequest& request, const Table& key,
                           const std::vector<Section>& sections, const std::vector<Table>& tables,
                           const std::vector<std::string>& inputs) {
  std::ostringstream out;
  out << "# " << markdownEscape(report.title) << "\n\n";
  out << "mission `" << request.mission_dir << "`, run `" << request.run_dir << "`\n\n";
  out << "> **" << (report.outcome == "better" ? "Better" : report.outcome == "worse" ? "Worse" : "About the same")
      << ":** " << markdownEscape(report.verdict) << "\n\n";
  out << markdownTable(key);
  if (!report.notes.empty()) {
    out << "**Notes** (missing or unusable inputs; their sections are left out)\n\n";
    for (const std::string& note : report.notes) out << "- " << markdownEscape(note) << "\n";
    out << "\n";
  }
  for (const Section& section : sections) {
    out << "## " << markdownEscape(section.heading) << "\n\n";
    if (!section.text.empty()) out << markdownEscape(section.text) << "\n\n";
    for (const Figure& f : section.figures) {
      out << "![" << markdownEscape(f.alt) << "](" << f.file << ")\n\n" << "*" << markdownEscape(f.caption) << "*\n\n";
    }
    for (const Table& table : section.tables) out << markdownTable(table);
  }
  out << "## 7. Metrics\n\nimprovement = (DR - SLAM) / DR, positive: SLAM better.\n\n";
  for (const Table& table : tables) out << markdownTable(table);
  out << "## Inputs\n\n";
  for (const std::string& input : inputs) out << "- `" << input << "`\n";
  out << "\nMachine-readable: [metrics.json](metrics.json).\n";
  return out.str();
}

sss::core::Status writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) {
    return sss::core::Status::error("cannot write " + path + "; check the directory exists, is writable and has space");
  }
  return sss::core::Status::success();
}

}  // namespace sss::eval::report_internal
