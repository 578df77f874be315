// TUM trajectory files ("sec.usec x y z qx qy qz qw" per line, local NED metres, T_world_body):
// a strict reader that names file:line for every problem, and the matching writer.
#pragma once

#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/core/status.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace sss::eval {

struct StampedPose {
  int64_t utime_us = 0;
  sss::core::Pose T_world_body;
};

// Poses in strictly increasing time order.
using Trajectory = std::vector<StampedPose>;

struct TumReadOptions {
  // A quaternion whose norm is further than this from 1 is a malformed line (a unit quaternion
  // written with 9 decimals is within 1e-8). The others are normalised.
  double max_quaternion_norm_error = 0.01;
  // Set: poses of a file whose header names another origin are re-expressed in this origin's
  // frame (see frame_alignment.hpp), so that a run processed with its own origin (the first fix)
  // compares with a truth in the simulator's frame.
  std::optional<sss::core::MissionOrigin> target_origin;
};

struct TumReadResult {
  bool ok = false;
  Trajectory poses;
  std::string error;  // "FILE:LINE: what is wrong; what to do" when !ok
  size_t comment_lines = 0;
  size_t blank_lines = 0;
  // The origin a '# origin_latitude_deg .. origin_longitude_deg ..' header line names (the frame
  // the file was written in), before any re-expression; nullopt when the file names none.
  std::optional<sss::core::MissionOrigin> origin;
  bool reexpressed = false;  // the poses were moved into options.target_origin's frame
};

// Reads a TUM file. Lines starting with '#' (one may name the origin) and blank lines are skipped; fields are separated by
// spaces, tabs or commas. Any other line must hold 8 finite numbers. Timestamps must increase
// strictly. The first problem ends the read with ok = false and a message naming file and line.
TumReadResult readTum(const std::string& path, const TumReadOptions& options = {});
// The same on text already in memory; `name` stands for the file in messages.
TumReadResult parseTum(const std::string& text, const std::string& name, const TumReadOptions& options = {});

// Parses a TUM timestamp ("1780300800.250000", "-3.5", "1.2e3") into microseconds. Decimal text
// is converted exactly (no double rounding); false when the text is not a finite number or out
// of the int64 microsecond range.
bool parseTumTimestamp(const std::string& text, int64_t& utime_us);

// One TUM line (with '\n') as the simulator writes it: microsecond timestamp, 6 decimals for
// metres, 9 for the quaternion.
std::string tumLine(const StampedPose& pose);
// Writes the poses (with an optional '#' comment first). Fails with a message when the file cannot
// be written.
sss::core::Status writeTum(const std::string& path, const Trajectory& poses, const std::string& comment = "",
                           const std::optional<sss::core::MissionOrigin>& origin = std::nullopt);

}  // namespace sss::eval
