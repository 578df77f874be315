// Streaming JSON writer. See json_writer.hpp.
#include "tools/eval/json_writer.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace sss::eval {

std::string JsonWriter::escape(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char code[8];
          std::snprintf(code, sizeof code, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
          out += code;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string JsonWriter::number(double value, int significant_digits) {
  if (!std::isfinite(value)) return "null";
  char text[40];
  std::snprintf(text, sizeof text, "%.*g", significant_digits, value);
  return text;
}

void JsonWriter::newline() {
  text_ += '\n';
  text_.append(2 * stack_.size(), ' ');
}

void JsonWriter::beforeValue() {
  if (stack_.empty()) return;
  Level& level = stack_.back();
  if (level.object) {
    // Programming error: every value in an object needs its key first.
    if (!key_pending_) throw std::logic_error("JsonWriter: value in an object without a key");
    key_pending_ = false;
    return;
  }
  if (level.count++ > 0) text_ += ',';
  newline();
}

JsonWriter& JsonWriter::key(const std::string& name) {
  if (stack_.empty() || !stack_.back().object || key_pending_) throw std::logic_error("JsonWriter: misplaced key " + name);
  if (stack_.back().count++ > 0) text_ += ',';
  newline();
  text_ += escape(name) + ": ";
  key_pending_ = true;
  return *this;
}

JsonWriter& JsonWriter::beginObject() {
  beforeValue();
  text_ += '{';
  stack_.push_back({true, 0});
  return *this;
}

JsonWriter& JsonWriter::endObject() {
  if (stack_.empty() || !stack_.back().object || key_pending_) throw std::logic_error("JsonWriter: unbalanced endObject");
  const bool empty = stack_.back().count == 0;
  stack_.pop_back();
  if (!empty) newline();
  text_ += '}';
  if (stack_.empty()) text_ += '\n';
  return *this;
}

JsonWriter& JsonWriter::beginArray() {
  beforeValue();
  text_ += '[';
  stack_.push_back({false, 0});
  return *this;
}

JsonWriter& JsonWriter::endArray() {
  if (stack_.empty() || stack_.back().object) throw std::logic_error("JsonWriter: unbalanced endArray");
  const bool empty = stack_.back().count == 0;
  stack_.pop_back();
  if (!empty) newline();
  text_ += ']';
  return *this;
}

JsonWriter& JsonWriter::value(double number_value, int significant_digits) {
  beforeValue();
  text_ += number(number_value, significant_digits);
  return *this;
}

JsonWriter& JsonWriter::value(int64_t number_value) {
  beforeValue();
  text_ += std::to_string(number_value);
  return *this;
}

JsonWriter& JsonWriter::value(uint64_t number_value) {
  beforeValue();
  text_ += std::to_string(number_value);
  return *this;
}

JsonWriter& JsonWriter::value(bool flag) {
  beforeValue();
  text_ += flag ? "true" : "false";
  return *this;
}

JsonWriter& JsonWriter::value(const std::string& text) {
  beforeValue();
  text_ += escape(text);
  return *this;
}

JsonWriter& JsonWriter::null() {
  beforeValue();
  text_ += "null";
  return *this;
}

JsonWriter& JsonWriter::numbers(const std::vector<double>& values, int significant_digits) {
  beforeValue();
  text_ += '[';
  for (size_t i = 0; i < values.size(); ++i) {
    if (i > 0) text_ += ", ";
    text_ += number(values[i], significant_digits);
  }
  text_ += ']';
  return *this;
}

}  // namespace sss::eval
