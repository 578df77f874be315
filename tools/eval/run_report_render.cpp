// The per-run report as index.html and report.md. See run_report.hpp.
#include "tools/eval/run_report_internal.hpp"

namespace sss::eval::report_internal {

// ---- HTML and Markdown ---------------------------------------------------------------------

std::string htmlTable(const Table& table) {
  std::ostringstream out;
  out << "<table>\n";
  if (!table.caption.empty()) out << "<caption>" << htmlEscape(table.caption) << "</caption>\n";
  out << "<tr>";
  for (const std::string& h : table.header) out << "<th>" << htmlEscape(h) << "</th>";
  out << "</tr>\n";
  for (const auto& row : table.rows) {
    out << "<tr>";
    for (size_t c = 0; c < row.size(); ++c) {
      const char* tone = row[c].tone > 0 ? " class=\"good\"" : row[c].tone < 0 ? " class=\"bad\"" : "";
      const std::string span =
          row[c].span > 1 ? " colspan=\"" + std::to_string(row[c].span) + "\" style=\"text-align:left\"" : "";
      out << (c == 0 ? "<th scope=\"row\"" : "<td") << tone << span << ">" << htmlEscape(row[c].text)
          << (c == 0 ? "</th>" : "</td>");
    }
    out << "</tr>\n";
  }
  out << "</table>\n";
  return out.str();
}

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

const char* kCss =
    "body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,sans-serif;max-width:1240px;margin:1.5em auto;"
    "padding:0 1em;color:#222;line-height:1.4}\n"
    "h1{font-size:1.5em;margin-bottom:.3em}h2{font-size:1.2em;margin-top:1.8em;border-bottom:1px solid #ddd}\n"
    ".verdict{font-size:1.15em;padding:.7em 1em;border-left:6px solid #888;background:#f4f4f4}\n"
    ".verdict.better{border-color:#2a9d2a;background:#eaf6ea}.verdict.worse{border-color:#c62828;background:#fbeaea}\n"
    "table{border-collapse:collapse;margin:.6em 0 1.2em}caption{text-align:left;font-weight:600;padding:.3em 0}\n"
    "th,td{border:1px solid #ccc;padding:.25em .6em;text-align:right}th[scope=row]{text-align:left;font-weight:normal}\n"
    "tr:first-child th{background:#f0f0f0}td.good{background:#dff2df}td.bad{background:#f8dcdc}\n"
    "figure{margin:.5em 0 1.2em}figure img{max-width:100%;border:1px solid #ccc}figcaption{color:#555;font-size:.92em}\n"
    ".row{display:flex;gap:1em;flex-wrap:wrap}.row figure{flex:1 1 45%}\n"
    ".notes{background:#fff8e1;border:1px solid #f0d890;padding:.5em 1em}.small{color:#666;font-size:.9em}\n";

std::string renderHtml(const RunReport& report, const RunReportRequest& request, const Table& key,
                       const std::vector<Section>& sections, const std::vector<Table>& tables,
                       const std::vector<std::string>& inputs) {
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" << htmlEscape(report.title)
      << "</title>\n<style>\n" << kCss << "</style>\n</head>\n<body>\n";
  out << "<h1>" << htmlEscape(report.title) << "</h1>\n";
  out << "<p class=\"small\">mission " << htmlEscape(request.mission_dir) << " &middot; run " << htmlEscape(request.run_dir)
      << "</p>\n";
  out << "<p class=\"verdict " << report.outcome << "\">" << htmlEscape(report.verdict) << "</p>\n";
  out << htmlTable(key);
  if (!report.notes.empty()) {
    out << "<div class=\"notes\"><strong>Notes</strong> (missing or unusable inputs; their sections are left out)\n<ul>\n";
    for (const std::string& note : report.notes) out << "<li>" << htmlEscape(note) << "</li>\n";
    out << "</ul></div>\n";
  }
  for (const Section& section : sections) {
    out << "<h2>" << htmlEscape(section.heading) << "</h2>\n";
    if (!section.text.empty()) out << "<p>" << htmlEscape(section.text) << "</p>\n";
    std::string open_row;
    for (size_t i = 0; i < section.figures.size(); ++i) {
      const Figure& f = section.figures[i];
      const bool grouped = !f.section.empty();
      const bool starts = grouped && (i == 0 || section.figures[i - 1].section != f.section);
      const bool ends = grouped && (i + 1 == section.figures.size() || section.figures[i + 1].section != f.section);
      if (starts) out << "<div class=\"row\">\n";
      out << "<figure><img src=\"" << htmlEscape(f.file) << "\" alt=\"" << htmlEscape(f.alt) << "\"><figcaption>"
          << htmlEscape(f.caption) << "</figcaption></figure>\n";
      if (ends) out << "</div>\n";
    }
    for (const Table& table : section.tables) out << htmlTable(table);
  }
  out << "<h2>7. Metrics</h2>\n";
  out << "<p class=\"small\">improvement = (DR - SLAM) / DR; green: SLAM better, red: SLAM worse. ATE: absolute "
         "trajectory error against the truth at the same time stamps; SE(3)-aligned: after the best rigid alignment "
         "of the whole trajectory; gauge-free: after the best horizontal rotation and scale about the estimate's first "
         "position, without a shift (what a constant heading bias and a DVL scale factor do, which no loop closure "
         "sees). RPE: relative pose error over the given path length.</p>\n";
  for (const Table& table : tables) out << htmlTable(table);
  out << "<h2>Inputs</h2>\n<ul class=\"small\">\n";
  for (const std::string& input : inputs) out << "<li>" << htmlEscape(input) << "</li>\n";
  out << "</ul>\n<p class=\"small\">Written by sss-report (machine-readable: <a href=\"metrics.json\">metrics.json</a>).</p>\n";
  out << "</body>\n</html>\n";
  return out.str();
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
