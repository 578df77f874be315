// The matcher's state on disk, so a restarted sss-matcher continues where it was: one self-checking
// file per stored subframe (written once) and a small state file (corrections, pair bookkeeping).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/pose.hpp"
#include "pipeline/core/status.hpp"
#include "pipeline/core/subframe_types.hpp"

namespace sss::matcher {

// What <dir>/matcher.state holds: each stored subframe's correction, every pair's bookkeeping.
struct SubframeCorrection {
  int64_t subframe_id = 0;
  sss::core::Pose correction;  // world-frame: corrected = correction * DR
};
struct PairRecord {
  int64_t subframe_id_a = 0;  // the older subframe
  int64_t subframe_id_b = 0;
  int rounds_done = 0;
  sss::core::Pose relative_at_match;  // correction_a^-1 * correction_b when last matched
};
struct MatcherState {
  std::vector<SubframeCorrection> corrections;
  std::vector<PairRecord> pairs;
};

// Files in the state directory; each is written to <name>.tmp, fsync'ed and renamed into place, so a
// kill or a power cut leaves the previous file or the new one, never half of one:
//   subframes/<id>.subframe  one stored subframe, exact (float image), binary with an FNV-1a checksum
//   matcher.state            versioned text, one line per subframe and pair, a checksum line
// Readers check everything (magic, version, sizes, checksum, id against the name): a bad file is
// reported with its path and the reason, never trusted, never a crash.
class MatcherStateStore {
 public:
  explicit MatcherStateStore(std::string directory);
  const std::string& directory() const { return directory_; }
  std::string subframePath(int64_t subframe_id) const;
  std::string statePath() const;

  // Creates the directories and removes the temporary files a kill mid-write left behind.
  sss::core::Status open();

  sss::core::Status writeSubframe(const sss::core::Subframe& subframe);
  sss::core::Status removeSubframe(int64_t subframe_id);  // ok when there was no file
  sss::core::Status writeState(const MatcherState& state);

  // Ids of the subframe files, ascending (other names are ignored).
  std::vector<int64_t> subframeIds() const;
  // nullopt when there is no such file; an error when there is one that cannot be trusted.
  sss::core::Result<std::optional<sss::core::Subframe>> readSubframe(int64_t subframe_id) const;
  sss::core::Result<std::optional<MatcherState>> readState() const;

 private:
  std::string directory_;
};

}  // namespace sss::matcher
