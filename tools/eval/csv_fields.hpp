// The small text parsing the evaluation tools share for the CSV files the chain writes
// (loop_closures.csv): fields split on commas and trimmed, numbers read strictly.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace sss::eval {

// Without leading and trailing spaces, tabs and CRs.
std::string trimField(const std::string& text);
// Comma-separated fields, each trimmed; a trailing comma gives a last empty field.
std::vector<std::string> splitCsvLine(const std::string& line);
// The whole text is one finite number / one integer in range; false otherwise.
bool parseFiniteDouble(const std::string& text, double& value);
bool parseInteger64(const std::string& text, int64_t& value);

}  // namespace sss::eval
