// Config loading: every documented error names the key, the bad value and what is allowed.
#include "pipeline/core/config.hpp"

#include <gtest/gtest.h>

namespace sss::core {
namespace {

struct ExampleOptions {
  int patch_size = 13;
  double max_offset_px = 5.0;
  std::string mode = "dense";
  bool enabled = true;
  std::vector<double> lever_arm_m = {0.0, 0.0, 0.0};
};

void readExample(ConfigSection section, ExampleOptions& options) {
  section.required("patch_size", options.patch_size,
                   {inRange(3, 31), satisfies<int>([](int v) { return v % 2 == 1; }, "an odd number")});
  section.optional("max_offset_px", options.max_offset_px, {greaterThan(0.0)});
  section.optional("mode", options.mode, {oneOf({"dense", "sparse"})});
  section.optional("enabled", options.enabled);
  section.optional("lever_arm_m", options.lever_arm_m,
                   {satisfies<std::vector<double>>([](const auto& v) { return v.size() == 3; }, "3 numbers [x, y, z]")});
  section.rejectUnknownKeys();
}

TEST(Config, ValidSectionFillsOptions) {
  Config config = Config::fromString("matcher:\n  patch_size: 15\n  mode: sparse\n  lever_arm_m: [0.1, 0.2, -0.3]\n");
  ExampleOptions options;
  readExample(config.section("matcher"), options);
  ASSERT_TRUE(config.ok()) << config.problemReport();
  EXPECT_EQ(options.patch_size, 15);
  EXPECT_EQ(options.mode, "sparse");
  EXPECT_DOUBLE_EQ(options.max_offset_px, 5.0);  // default kept
  EXPECT_DOUBLE_EQ(options.lever_arm_m[2], -0.3);
}

TEST(Config, MissingRequiredKeyNamesKeyAndExpectedType) {
  Config config = Config::fromString("matcher:\n  mode: dense\n");
  ExampleOptions options;
  readExample(config.section("matcher"), options);
  ASSERT_EQ(config.problems().size(), 1u);
  EXPECT_EQ(config.problems()[0].message(), "config key 'matcher.patch_size': missing; required: an integer");
  EXPECT_EQ(options.patch_size, 13);
}

TEST(Config, WrongTypeNamesValueAndExpectedType) {
  Config config = Config::fromString("matcher:\n  patch_size: 12.5\n  max_offset_px: five\n");
  ExampleOptions options;
  readExample(config.section("matcher"), options);
  ASSERT_EQ(config.problems().size(), 2u);
  EXPECT_EQ(config.problems()[0].message(), "config key 'matcher.patch_size' = 12.5: wrong type; expected an integer");
  EXPECT_EQ(config.problems()[1].message(), "config key 'matcher.max_offset_px' = five: wrong type; expected a number");
}

TEST(Config, OutOfRangeValueNamesTheAllowedRange) {
  Config config = Config::fromString("matcher:\n  patch_size: 41\n  mode: fast\n");
  ExampleOptions options;
  readExample(config.section("matcher"), options);
  ASSERT_EQ(config.problems().size(), 2u);
  EXPECT_EQ(config.problems()[0].message(), "config key 'matcher.patch_size' = 41: not allowed; expected a value in [3, 31]");
  EXPECT_EQ(config.problems()[1].message(),
            "config key 'matcher.mode' = fast: not allowed; expected one of {dense, sparse}");
  EXPECT_EQ(options.patch_size, 13);
}

TEST(Config, SecondRuleReportedWhenFirstPasses) {
  Config config = Config::fromString("matcher:\n  patch_size: 12\n");
  ExampleOptions options;
  readExample(config.section("matcher"), options);
  ASSERT_EQ(config.problems().size(), 1u);
  EXPECT_EQ(config.problems()[0].message(), "config key 'matcher.patch_size' = 12: not allowed; expected an odd number");
}

TEST(Config, UnknownKeyIsReportedWithTheKnownOnes) {
  Config config = Config::fromString("matcher:\n  patch_size: 13\n  pach_size: 15\n");
  ExampleOptions options;
  readExample(config.section("matcher"), options);
  ASSERT_EQ(config.problems().size(), 1u);
  EXPECT_EQ(config.problems()[0].key, "matcher.pach_size");
  EXPECT_NE(config.problems()[0].reason.find("unknown key"), std::string::npos);
  EXPECT_NE(config.problems()[0].reason.find("patch_size"), std::string::npos);
}

TEST(Config, QuotedNumberIsAStringAndShownQuoted) {
  Config config = Config::fromString("matcher:\n  patch_size: 13\n  lever_arm_m: \"0 0 0\"\n");
  ExampleOptions options;
  readExample(config.section("matcher"), options);
  ASSERT_EQ(config.problems().size(), 1u);
  EXPECT_EQ(config.problems()[0].message(),
            "config key 'matcher.lever_arm_m' = \"0 0 0\": wrong type; expected a list of numbers");
}

TEST(Config, SyntaxErrorAndMissingFileAreProblemsNotExceptions) {
  Config bad = Config::fromString("matcher: [unclosed\n", "deploy.yaml");
  ASSERT_EQ(bad.problems().size(), 1u);
  EXPECT_NE(bad.problems()[0].reason.find("deploy.yaml: YAML syntax error at line"), std::string::npos);
  Config missing = Config::fromFile("/nonexistent/sss.yaml");
  ASSERT_EQ(missing.problems().size(), 1u);
  EXPECT_NE(missing.problems()[0].reason.find("cannot open config file '/nonexistent/sss.yaml'"), std::string::npos);
}

TEST(Config, MissingSectionKeepsEveryDefault) {
  Config config = Config::fromString("other:\n  x: 1\n");
  ExampleOptions options;
  ConfigSection section = config.section("matcher");
  section.optional("max_offset_px", options.max_offset_px, {greaterThan(0.0)});
  ConfigSection nested = section.section("deeper");
  nested.optional("mode", options.mode);
  nested.rejectUnknownKeys();
  EXPECT_TRUE(config.ok()) << config.problemReport();
  EXPECT_DOUBLE_EQ(options.max_offset_px, 5.0);
  EXPECT_EQ(options.mode, "dense");
}

TEST(Config, SectionThatIsNotAMapIsReported) {
  Config config = Config::fromString("matcher: 3\n");
  ExampleOptions options;
  readExample(config.section("matcher"), options);
  ASSERT_GE(config.problems().size(), 1u);
  EXPECT_EQ(config.problems()[0].message(), "config key 'matcher' = 3: wrong type; expected a section (a map of keys)");
}

TEST(Config, SequenceOfSectionsIsReadItemByItemWithIndexedKeys) {
  Config config = Config::fromString("targets:\n  - {north_m: 1.5, east_m: 2}\n  - {north_m: -3, easting: 4}\n  - 7\n");
  ConfigSection root = config.root();
  std::vector<ConfigSection> items = root.sequence("targets");
  ASSERT_EQ(items.size(), 2u) << "the scalar item is a problem, not a section";
  std::vector<double> north(2, 0.0), east(2, 0.0);
  for (size_t i = 0; i < items.size(); ++i) {
    items[i].required("north_m", north[i]);
    items[i].optional("east_m", east[i]);
    items[i].rejectUnknownKeys();
  }
  root.rejectUnknownKeys();
  EXPECT_DOUBLE_EQ(north[0], 1.5);
  EXPECT_DOUBLE_EQ(east[0], 2.0);
  EXPECT_DOUBLE_EQ(north[1], -3.0);
  ASSERT_EQ(config.problems().size(), 2u) << config.problemReport();
  EXPECT_EQ(config.problems()[0].key, "targets[2]");
  EXPECT_EQ(config.problems()[1].key, "targets[1].easting");

  Config none = Config::fromString("other: 1\n");
  EXPECT_TRUE(none.root().sequence("targets").empty());
  Config not_a_list = Config::fromString("targets: {north_m: 1}\n");
  EXPECT_TRUE(not_a_list.root().sequence("targets").empty());
  ASSERT_EQ(not_a_list.problems().size(), 1u);
  EXPECT_NE(not_a_list.problems()[0].reason.find("expected a list of sections"), std::string::npos);
}

}  // namespace
}  // namespace sss::core
