// JSON of the reports (summary.json, eval.json, metrics.json) through nlohmann-json, with one
// convention for numbers: rounded to a stated number of significant digits, so the files read as
// measurements and not as 17-digit doubles, and non-finite numbers written as null (JSON has no
// NaN). Keys stay in the order written (ordered_json).
#pragma once

#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

namespace sss::eval {

using Json = nlohmann::ordered_json;

// A number rounded to significant_digits; null when not finite.
Json jsonNumber(double value, int significant_digits = 10);
// Any value: numbers as jsonNumber (10 digits), the rest as nlohmann writes them.
template <typename T>
Json jsonValue(const T& value) {
  if constexpr (std::is_floating_point_v<T>) {
    return jsonNumber(static_cast<double>(value));
  } else {
    return Json(value);
  }
}
inline Json jsonValue(double value, int significant_digits) { return jsonNumber(value, significant_digits); }
// An array of numbers, each as jsonNumber.
Json jsonNumbers(const std::vector<double>& values, int significant_digits = 6);

}  // namespace sss::eval
