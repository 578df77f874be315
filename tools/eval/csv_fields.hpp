// The small text parsing the evaluation tools share for the CSV files the chain writes
// (loop_closures.csv): fields split on commas and trimmed, numbers read strictly.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "pipeline/core/status.hpp"

namespace sss::eval {

// Without leading and trailing spaces, tabs and CRs.
std::string trimField(const std::string& text);
// Comma-separated fields, each trimmed; a trailing comma gives a last empty field.
std::vector<std::string> splitCsvLine(const std::string& line);
// The whole text is one finite number / one integer in range; false otherwise.
bool parseFiniteDouble(const std::string& text, double& value);
bool parseInteger64(const std::string& text, int64_t& value);

// A CSV file with a header line, columns found by name (any order, extra columns ignored).
struct CsvRow {
  int line = 0;  // in the file, for messages
  std::vector<std::string> fields;
};
struct CsvTable {
  std::string path;
  std::map<std::string, size_t> column;
  std::vector<CsvRow> rows;

  bool has(const std::string& name) const { return column.count(name) != 0; }
  // The named field of a row; the column must exist (required, or checked with has()).
  const std::string& field(const CsvRow& row, const std::string& name) const { return row.fields[column.at(name)]; }
  // "PATH:LINE: " for a message about the row.
  std::string where(const CsvRow& row) const { return path + ":" + std::to_string(row.line) + ": "; }
};

// The named fields of a row as numbers / integers, in the order of `names`; fails with
// "PATH:LINE: NAME 'TEXT' is not a finite number" (or "an integer") for the first that is not.
sss::core::Status parseNumberColumns(const CsvTable& table, const CsvRow& row, const std::vector<const char*>& names,
                                     double* values);
sss::core::Status parseIntegerColumns(const CsvTable& table, const CsvRow& row, const std::vector<const char*>& names,
                                      int64_t* values);

// Reads path: '#' and blank lines skipped, the first other line is the header, every row must have
// as many fields as the header. False with "PATH[:LINE]: ..." on a missing file, a missing
// required column or header, or a row of another length; `expected` (e.g. "a,b,...") is quoted
// in the header messages.
sss::core::Status readCsvTable(const std::string& path, const std::vector<std::string>& required,
                               const std::string& expected, CsvTable& table);

// The same reading, row by row, for files too large to hold as text (matches.csv): `table` has the
// header and no rows; each row goes to on_row (which may move it away), which fails to stop.
using CsvRowHandler = std::function<sss::core::Status(const CsvTable& table, CsvRow& row)>;
sss::core::Status forEachCsvRow(const std::string& path, const std::vector<std::string>& required,
                                const std::string& expected, CsvTable& table, const CsvRowHandler& on_row);

}  // namespace sss::eval
