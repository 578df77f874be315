// gtest assertions for sss::core::Status and Result<T> (pipeline/core/status.hpp): on failure they
// print the call's message, e.g. ASSERT_OK(store.open()) << "while restoring".
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "pipeline/core/status.hpp"

namespace sss::testing {

inline ::testing::AssertionResult isOk(const sss::core::Status& status) {
  if (status.ok) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "error: " << status.message;
}

template <typename T>
::testing::AssertionResult isOk(const sss::core::Result<T>& result) {
  if (result.ok()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "error: " << result.message();
}

// The message of a call that must fail (a test failure when it succeeds), for the checks on it.
inline std::string failureMessage(const sss::core::Status& status) {
  EXPECT_FALSE(status.ok) << "expected a failure";
  return status.message;
}

}  // namespace sss::testing

#define ASSERT_OK(expression) ASSERT_TRUE(::sss::testing::isOk(expression))
#define EXPECT_OK(expression) EXPECT_TRUE(::sss::testing::isOk(expression))
