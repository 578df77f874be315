// A small streaming JSON writer for the evaluation report: indented objects, one-line number
// arrays, non-finite numbers written as null (JSON has no NaN).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace sss::eval {

class JsonWriter {
 public:
  JsonWriter& beginObject();
  JsonWriter& endObject();
  JsonWriter& beginArray();
  JsonWriter& endArray();
  // The next value belongs to this key (inside an object).
  JsonWriter& key(const std::string& name);
  JsonWriter& value(double number, int significant_digits = 10);
  JsonWriter& value(int64_t number);
  JsonWriter& value(uint64_t number);
  JsonWriter& value(int number) { return value(static_cast<int64_t>(number)); }
  JsonWriter& value(bool flag);
  JsonWriter& value(const std::string& text);
  JsonWriter& value(const char* text) { return value(std::string(text)); }
  JsonWriter& null();
  // A whole array of numbers on one line.
  JsonWriter& numbers(const std::vector<double>& values, int significant_digits = 6);

  // The document so far (complete once every begin has its end).
  const std::string& str() const { return text_; }

  static std::string escape(const std::string& text);
  static std::string number(double value, int significant_digits);

 private:
  void beforeValue();
  void newline();

  struct Level {
    bool object = false;
    size_t count = 0;
  };
  std::string text_;
  std::vector<Level> stack_;
  bool key_pending_ = false;
};

}  // namespace sss::eval
