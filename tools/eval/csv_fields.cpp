// CSV field helpers; see csv_fields.hpp.
#include "tools/eval/csv_fields.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace sss::eval {

using sss::core::Status;

std::string trimField(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  const size_t last = text.find_last_not_of(" \t\r");
  return text.substr(first, last - first + 1);
}

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) fields.push_back(trimField(field));
  if (!line.empty() && line.back() == ',') fields.push_back("");
  return fields;
}

bool parseFiniteDouble(const std::string& text, double& value) {
  char* end = nullptr;
  errno = 0;
  value = std::strtod(text.c_str(), &end);
  return !text.empty() && end == text.c_str() + text.size() && errno != ERANGE && std::isfinite(value);
}

bool parseInteger64(const std::string& text, int64_t& value) {
  char* end = nullptr;
  errno = 0;
  value = std::strtoll(text.c_str(), &end, 10);
  return !text.empty() && end == text.c_str() + text.size() && errno != ERANGE;
}

Status forEachCsvRow(const std::string& path, const std::vector<std::string>& required, const std::string& expected,
                     CsvTable& table, const CsvRowHandler& on_row) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return Status::error(path + ": cannot open; check the path");
  }
  table = CsvTable{};
  table.path = path;
  std::string text;
  int line_number = 0;
  bool have_header = false;
  while (std::getline(in, text)) {
    ++line_number;
    const std::string line = trimField(text);
    if (line.empty() || line[0] == '#') continue;
    CsvRow row{line_number, splitCsvLine(line)};
    if (!have_header) {
      for (size_t k = 0; k < row.fields.size(); ++k) table.column[row.fields[k]] = k;
      for (const std::string& name : required) {
        if (!table.has(name)) {
          return Status::error(table.where(row) + "the header has no column '" + name + "' (expected " + expected +
                               ")");
        }
      }
      have_header = true;
      continue;
    }
    if (row.fields.size() != table.column.size()) {
      return Status::error(table.where(row) + std::to_string(row.fields.size()) + " fields, the header has " +
                           std::to_string(table.column.size()));
    }
    if (const Status taken = on_row(table, row); !taken) return taken;
  }
  if (!have_header) {
    return Status::error(path + ": no header line (expected " + expected + ")");
  }
  return Status::success();
}

Status parseNumberColumns(const CsvTable& table, const CsvRow& row, const std::vector<const char*>& names,
                          double* values) {
  for (size_t k = 0; k < names.size(); ++k) {
    const std::string& field = table.field(row, names[k]);
    if (!parseFiniteDouble(field, values[k])) {
      return Status::error(table.where(row) + names[k] + " '" + field + "' is not a finite number");
    }
  }
  return Status::success();
}

Status parseIntegerColumns(const CsvTable& table, const CsvRow& row, const std::vector<const char*>& names,
                           int64_t* values) {
  for (size_t k = 0; k < names.size(); ++k) {
    const std::string& field = table.field(row, names[k]);
    if (!parseInteger64(field, values[k])) {
      return Status::error(table.where(row) + names[k] + " '" + field + "' is not an integer");
    }
  }
  return Status::success();
}

Status readCsvTable(const std::string& path, const std::vector<std::string>& required, const std::string& expected,
                    CsvTable& table) {
  std::vector<CsvRow> rows;
  const Status read = forEachCsvRow(path, required, expected, table, [&](const CsvTable&, CsvRow& row) {
    rows.push_back(std::move(row));
    return Status::success();
  });
  table.rows = std::move(rows);
  return read;
}

}  // namespace sss::eval
