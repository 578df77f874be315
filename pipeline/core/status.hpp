// The one error style of the library code: a call that can fail returns a Status (ok, or a message
// that names the cause and, where there is one, the fix), or a Result<T> (a value, or that
// message) for anything bad input can cause. Exceptions only for programming errors (options a
// constructor gets without validating them first); no `bool` + `std::string& error` pairs.
// Both are [[nodiscard]]: an ignored failure is a compile warning.
#pragma once

#include <optional>
#include <string>
#include <utility>

namespace sss::core {

struct [[nodiscard]] Status {
  bool ok = true;
  std::string message;  // empty when ok

  static Status success() { return {}; }
  static Status error(std::string text) { return {false, std::move(text)}; }
  explicit operator bool() const { return ok; }
};

template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}  // NOLINT: implicit, so that `return value;` reads plainly
  Result(Status failure) : message_(std::move(failure.message)) {}  // NOLINT: `return Status::error(...)`

  bool ok() const { return value_.has_value(); }
  explicit operator bool() const { return ok(); }
  // Precondition: ok().
  const T& value() const& { return *value_; }
  T& value() & { return *value_; }
  T&& value() && { return std::move(*value_); }
  const T& operator*() const& { return *value_; }
  T& operator*() & { return *value_; }
  const T* operator->() const { return &*value_; }
  T* operator->() { return &*value_; }
  const std::string& message() const { return message_; }  // empty when ok()
  Status status() const { return ok() ? Status::success() : Status::error(message_); }

 private:
  std::optional<T> value_;
  std::string message_;
};

}  // namespace sss::core
