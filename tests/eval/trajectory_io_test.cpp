// TUM reading: comments and blank lines, exact timestamps, malformed lines and out-of-order
// timestamps rejected with file:line, and a lossless write/read round trip.
#include "tools/eval/trajectory_io.hpp"

#include "tests/eval/eval_test_paths.hpp"
#include "tests/support/status_assertions.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

namespace sss::eval {
namespace {

const char* kGood =
    "# ground truth\n"
    "\n"
    "1780300800.000000 0.0000 0.0000 49.8079 -0.002473135 0.020780543 0.002044419 0.999778912\n"
    "   # indented comment\n"
    "1780300800.250000,0.5,0.0,49.7866,0,0,0,1\n"
    "1780300800.5\t1.0\t0.0\t49.7664\t0\t0\t0.7071067811865476\t0.7071067811865476\r\n";

TEST(TumReader, SkipsCommentsAndBlankLinesAndAcceptsSpacesTabsCommas) {
  const TumReadResult result = parseTum(kGood, "good.tum");
  ASSERT_TRUE(result.ok) << result.error;
  ASSERT_EQ(result.poses.size(), 3u);
  EXPECT_EQ(result.comment_lines, 2u);
  EXPECT_EQ(result.blank_lines, 1u);
  EXPECT_EQ(result.poses[0].utime_us, 1780300800000000);
  EXPECT_EQ(result.poses[1].utime_us, 1780300800250000);
  EXPECT_EQ(result.poses[2].utime_us, 1780300800500000);
  EXPECT_DOUBLE_EQ(result.poses[0].T_world_body.translation.z(), 49.8079);
  // qx qy qz qw order: the third pose is a 90 deg turn about down (heading east).
  EXPECT_NEAR(sss::core::eulerFromQuaternion(result.poses[2].T_world_body.rotation).heading_rad, M_PI / 2, 1e-12);
}

TEST(TumReader, ParsesTimestampsExactly) {
  int64_t utime = 0;
  ASSERT_TRUE(parseTumTimestamp("1780300800.123456", utime));
  EXPECT_EQ(utime, 1780300800123456);  // a double would round this
  ASSERT_TRUE(parseTumTimestamp("12.5", utime));
  EXPECT_EQ(utime, 12500000);
  ASSERT_TRUE(parseTumTimestamp("-0.5", utime));
  EXPECT_EQ(utime, -500000);
  ASSERT_TRUE(parseTumTimestamp("1.0000005", utime));
  EXPECT_EQ(utime, 1000001);  // rounded to the microsecond
  ASSERT_TRUE(parseTumTimestamp("1.5e3", utime));
  EXPECT_EQ(utime, 1500000000);
  EXPECT_FALSE(parseTumTimestamp("abc", utime));
  EXPECT_FALSE(parseTumTimestamp("nan", utime));
  EXPECT_FALSE(parseTumTimestamp("inf", utime));
  EXPECT_FALSE(parseTumTimestamp("1e300", utime));
  EXPECT_FALSE(parseTumTimestamp(".", utime));
}

TEST(TumReader, RejectsLineWithWrongFieldCountNamingFileAndLine) {
  const std::string text = "# header\n1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 1\n";
  const TumReadResult result = parseTum(text, "est.tum");
  EXPECT_FALSE(result.ok);
  EXPECT_TRUE(result.poses.empty());
  EXPECT_NE(result.error.find("est.tum:3:"), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("found 7"), std::string::npos) << result.error;
}

TEST(TumReader, RejectsNonNumericField) {
  const TumReadResult result = parseTum("1.0 0 0 0 0 0 0 1\n2.0 0 0 0 abc 0 0 1\n", "est.tum");
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.error.find("est.tum:2: field qx 'abc'"), std::string::npos) << result.error;
  EXPECT_FALSE(parseTum("x1.0 0 0 0 0 0 0 1\n", "a.tum").ok);
  EXPECT_FALSE(parseTum("1.0 nan 0 0 0 0 0 1\n", "a.tum").ok);
}

TEST(TumReader, RejectsNonUnitQuaternion) {
  const TumReadResult result = parseTum("1.0 0 0 0 0 0 0 0\n", "est.tum");
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.error.find("est.tum:1:"), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("norm"), std::string::npos) << result.error;
}

TEST(TumReader, RejectsTimestampsOutOfOrderNamingBothLines) {
  const std::string text = "1.0 0 0 0 0 0 0 1\n# c\n2.0 0 0 0 0 0 0 1\n1.5 0 0 0 0 0 0 1\n";
  const TumReadResult result = parseTum(text, "est.tum");
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.error.find("est.tum:4:"), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("line 3"), std::string::npos) << result.error;
  // Repeated timestamps are out of order too.
  EXPECT_FALSE(parseTum("1.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n", "dup.tum").ok);
}

TEST(TumReader, RejectsEmptyAndMissingFiles) {
  const TumReadResult empty = parseTum("# only a comment\n\n", "empty.tum");
  EXPECT_FALSE(empty.ok);
  EXPECT_NE(empty.error.find("empty.tum"), std::string::npos);
  const TumReadResult missing = readTum("/nonexistent/dir/est.tum");
  EXPECT_FALSE(missing.ok);
  EXPECT_NE(missing.error.find("/nonexistent/dir/est.tum: cannot open"), std::string::npos) << missing.error;
}

TEST(TumReader, SurvivesRandomBytes) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> byte(0, 255), length(0, 400);
  const std::string alphabet = "0123456789.-+eE #,\t\nnaif";
  std::uniform_int_distribution<size_t> pick(0, alphabet.size() - 1);
  for (int trial = 0; trial < 2000; ++trial) {
    std::string text;
    const int n = length(rng);
    for (int i = 0; i < n; ++i) text += trial % 2 ? static_cast<char>(byte(rng)) : alphabet[pick(rng)];
    const TumReadResult result = parseTum(text, "fuzz.tum");
    if (!result.ok) {
      EXPECT_EQ(result.error.rfind("fuzz.tum:", 0), 0u) << result.error;
    }
  }
}

TEST(TumWriter, RoundTripsThroughAFile) {
  const Trajectory poses = test::lawnmower(2, 50.0, 30.0);
  const std::string path = (std::filesystem::temp_directory_path() / "sss_eval_roundtrip.tum").string();
  std::string error;
  ASSERT_OK(writeTum(path, poses, "written by the test\nsecond line"));
  const TumReadResult result = readTum(path);
  ASSERT_TRUE(result.ok) << result.error;
  ASSERT_EQ(result.poses.size(), poses.size());
  EXPECT_EQ(result.comment_lines, 2u);
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(result.poses[i].utime_us, poses[i].utime_us);
    // 6 decimals for metres, 9 for the quaternion.
    EXPECT_LT((result.poses[i].T_world_body.translation - poses[i].T_world_body.translation).norm(), 1e-6);
    EXPECT_LT(result.poses[i].T_world_body.rotation.angularDistance(poses[i].T_world_body.rotation), 1e-8);
  }
  std::filesystem::remove(path);
  error = sss::testing::failureMessage(writeTum("/nonexistent/dir/out.tum", poses));
  EXPECT_NE(error.find("/nonexistent/dir/out.tum"), std::string::npos);
}

TEST(TumWriter, WritesNegativeAndSubSecondTimestamps) {
  StampedPose pose;
  pose.utime_us = -500000;
  EXPECT_EQ(tumLine(pose).substr(0, 10), "-0.500000 ");
  pose.utime_us = -1500001;
  EXPECT_EQ(tumLine(pose).substr(0, 10), "-1.500001 ");
}

}  // namespace
}  // namespace sss::eval
