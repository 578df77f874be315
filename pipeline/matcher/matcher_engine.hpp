// The matcher stage without middleware: keeps recent subframes, finds overlapping pairs from their
// footprints under the latest optimised poses, matches them and returns loop closures; re-matches
// pairs the optimiser has moved (the paper's iterative data association, n_iter rounds). With a
// MatcherStateStore it keeps its state on disk and a restarted engine continues from there.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/core/closure_types.hpp"
#include "pipeline/core/config.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/matcher/matcher_state.hpp"
#include "pipeline/matcher/overlap.hpp"
#include "pipeline/matcher/pair_matcher.hpp"
#include "pipeline/core/subframe_types.hpp"

namespace sss::matcher {

struct MatcherEngineOptions {
  OverlapOptions overlap;
  PairMatcherOptions pair;
  // Subframes kept for matching (oldest dropped first). A 200-ping subframe of 2 x 1250 bins holds
  // ~2.5 MB: 240 of them (~3.3 h of survey at 50 s each) take ~600 MB.
  int max_stored_subframes = 240;
  // The same bound in memory, whichever is reached first: a swath that follows the sonar's range
  // (canonical.swath_from_range) makes every subframe larger (150 m a side: ~5 MB), and the
  // vehicle's memory does not grow with it. At least two subframes are always kept.
  double max_stored_mib = 600.0;
  // Paper: 2 rounds of data association with optimised poses after the DR one.
  int max_association_rounds = 2;
  // A pair is re-matched when the optimiser moved its two subframes relative to each other by
  // more than this since they were last matched.
  double reassociation_translation_m = 0.5;
  double reassociation_rotation_rad = 0.005;
  // Inlier correspondences sent with a closure for the optimiser's bathymetric point cloud
  // (evenly thinned beyond this; ~28 bytes each on the wire).
  int max_closure_correspondences = 3000;
};

void readMatcherEngineOptions(sss::core::ConfigSection& section, MatcherEngineOptions& options);
std::vector<std::string> validateMatcherEngineOptions(const MatcherEngineOptions& options);

// The closure and trajectory types are the stages' shared domain types (pipeline/core).
using sss::core::ClosureCorrespondence;
using sss::core::LoopClosure;
using sss::core::TrajectoryNode;

// What happened to one pair: a closure when accepted, the reason when not.
struct PairOutcome {
  int64_t subframe_id_a = 0;
  int64_t subframe_id_b = 0;
  int association_round = 0;
  bool accepted = false;
  std::string reason;
  double seconds = 0.0;
  MatchTimings dense_timings;
  double pose_seconds = 0.0;
  LoopClosure closure;  // valid when accepted
};

struct MatcherEngineCounters {
  uint64_t subframes_in = 0;
  uint64_t subframes_rejected = 0;  // malformed (sizes) or a duplicate id
  uint64_t subframes_evicted = 0;
  uint64_t trajectory_updates = 0;
  uint64_t pairs_attempted = 0;
  uint64_t closures_accepted = 0;
  uint64_t pairs_rejected = 0;
  uint64_t rematches = 0;           // attempts with optimised poses (round >= 1)
  uint64_t closures_without_opposed_relief = 0;  // accepted with the pose test_opposed_relief re-estimated
  uint64_t closures_widened_by_passes = 0;       // accepted with the covariance test_pass_agreement widened
  double pair_seconds_total = 0.0;
  // State directory (restore()).
  uint64_t subframes_restored = 0;
  uint64_t pairs_restored = 0;      // pairs known as matched at restore
  uint64_t state_files_corrupt = 0; // unreadable subframe or state files at restore: skipped
  uint64_t state_write_errors = 0;  // failed writes or removals in the state directory
};

// What restore() found, for the node's log.
struct RestoreReport {
  std::string directory;
  bool state_file_found = false;
  size_t subframes = 0;            // restored
  size_t pairs = 0;                // restored as already matched
  size_t subframes_without_state = 0;  // stored but not (all) matched before the restart
  std::vector<std::string> problems;   // one per skipped file or failed write: path and reason
  std::vector<PairOutcome> outcomes;   // the pairs of those subframes, matched now
};

// Sees every pair the engine matches (the two subframes, the association round, the dense matches
// and their decimation), accepted or not; for evaluation tools (sss-process --write-matches).
using PairMatchObserver = std::function<void(const sss::core::Subframe& a, const sss::core::Subframe& b,
                                             int association_round, const PairMatch& match)>;

class MatcherEngine {
 public:
  explicit MatcherEngine(const MatcherEngineOptions& options);

  // Called after each pair is matched; it does not change what the engine does.
  void setPairMatchObserver(PairMatchObserver observer) { pair_observer_ = std::move(observer); }

  // Stores the subframe and matches it against the stored subframes it overlaps under the latest
  // corrections (largest overlap first, at most overlap.max_candidates).
  std::vector<PairOutcome> addSubframe(sss::core::Subframe subframe);

  // Optimised centre poses: each named subframe's correction (optimised * DR^-1 at its centre) is
  // applied to all its pings. Pairs whose relative pose moved beyond the thresholds are re-matched
  // (up to max_association_rounds), pairs that overlap only under the new poses are tried.
  std::vector<PairOutcome> updateTrajectory(const std::vector<TrajectoryNode>& nodes);

  // Restores the subframes and the pair bookkeeping from the store, then keeps the store up to date:
  // each subframe's file is written when it is stored (before its pairs are matched) and removed
  // when it is evicted, the state file is rewritten after each addSubframe and updateTrajectory.
  // Subframes are restored in id order with their saved corrections; pairs saved as matched are not
  // matched again. A subframe file without a state entry was stored but the process died while
  // matching it: it gets the correction a new subframe would get (identity when nothing is known)
  // and its pairs are matched here as addSubframe would have. Bad files are skipped, counted and
  // reported, the rest is restored. Call once, on an empty engine; the store must outlive it.
  RestoreReport restore(MatcherStateStore& store);
  // The newest failed write in the state directory since the last call ("" when none).
  std::string takeStateError();

  // The bookkeeping the state file keeps: stored subframes' corrections and pairs, in id order.
  MatcherState state() const;

  const MatcherEngineCounters& counters() const { return counters_; }
  size_t storedSubframes() const { return stored_.size(); }
  size_t memoryBytes() const;
  const MatcherEngineOptions& options() const { return options_; }

 private:
  struct Stored {
    sss::core::Subframe subframe;
    sss::core::Pose correction;  // world-frame: corrected = correction * DR
    std::vector<sss::core::Pose> poses;
    Footprint footprint;
  };
  struct PairState {
    int rounds_done = 0;              // association rounds run (1 = the DR round)
    sss::core::Pose relative_at_match;  // correction_a^-1 * correction_b when last matched
  };
  using PairKey = std::pair<int64_t, int64_t>;

  void setCorrection(Stored& stored, const sss::core::Pose& correction);
  PairOutcome matchStored(const PairKey& key, int round);
  std::vector<Footprint> allFootprints() const;
  sss::core::Pose newSubframeCorrection(int64_t id, int line_id) const;
  std::vector<PairOutcome> matchNewSubframe(int64_t id, const std::vector<Footprint>& others);
  void evictBeyondLimit();
  void saveState();
  void recordStateError(const sss::core::Status& written);  // counts and keeps a failed write

  MatcherEngineOptions options_;
  DenseMatcher dense_;
  std::map<int64_t, Stored> stored_;
  std::map<PairKey, PairState> pairs_;
  MatcherEngineCounters counters_;
  MatcherStateStore* store_ = nullptr;  // none: nothing persisted
  PairMatchObserver pair_observer_;
  std::string state_error_;
};

}  // namespace sss::matcher
