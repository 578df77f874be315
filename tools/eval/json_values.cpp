// Numbers for the reports' JSON, see json_values.hpp.
#include "tools/eval/json_values.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace sss::eval {

Json jsonNumber(double value, int significant_digits) {
  if (!std::isfinite(value)) return nullptr;
  // Printed and read back: the nearest double to the rounded decimal, which nlohmann then writes
  // in its shortest form (0.1, not 0.10000000000000001).
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", significant_digits, value);
  return std::strtod(text, nullptr);
}

Json jsonNumbers(const std::vector<double>& values, int significant_digits) {
  Json array = Json::array();
  for (const double value : values) array.push_back(jsonNumber(value, significant_digits));
  return array;
}

}  // namespace sss::eval
