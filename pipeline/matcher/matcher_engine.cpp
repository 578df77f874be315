// The matcher stage without middleware: stored subframes, overlap search, pair matching and the
// iterative re-association with optimised poses; its state kept in a MatcherStateStore.
#include "pipeline/matcher/matcher_engine.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace sss::matcher {
namespace {

using sss::core::Pose;

bool wellFormed(const sss::core::Subframe& s) {
  const size_t pixels = static_cast<size_t>(s.rows()) * static_cast<size_t>(s.cols());
  return s.rows() > 1 && s.cols() > 0 && s.image.size() == pixels && s.mask.size() == pixels &&
         s.centre_ping_index >= 0 && s.centre_ping_index < s.rows();
}

}  // namespace

void readMatcherEngineOptions(sss::core::ConfigSection& section, MatcherEngineOptions& options) {
  using sss::core::inRange;
  using sss::core::greaterThan;
  sss::core::ConfigSection overlap = section.section("overlap");
  readOverlapOptions(overlap, options.overlap);
  overlap.rejectUnknownKeys();
  readPairMatcherOptions(section, options.pair);
  section.optional("max_stored_subframes", options.max_stored_subframes, {inRange(2, 100000)});
  section.optional("max_stored_mib", options.max_stored_mib, {greaterThan(0.0)});
  section.optional("max_association_rounds", options.max_association_rounds, {inRange(0, 10)});
  section.optional("reassociation_translation_m", options.reassociation_translation_m, {inRange(0.0, 1000.0)});
  section.optional("reassociation_rotation_rad", options.reassociation_rotation_rad, {inRange(0.0, 3.2)});
  section.optional("max_closure_correspondences", options.max_closure_correspondences, {inRange(0, 100000)});
}

std::vector<std::string> validateMatcherEngineOptions(const MatcherEngineOptions& o) {
  std::vector<std::string> problems = validateOverlapOptions(o.overlap);
  for (const std::string& p : validatePairMatcherOptions(o.pair)) problems.push_back(p);
  if (o.max_stored_subframes < 2) problems.push_back("max_stored_subframes must be >= 2");
  if (!(o.max_stored_mib > 0.0)) problems.push_back("max_stored_mib must be > 0");
  if (o.max_association_rounds < 0) problems.push_back("max_association_rounds must be >= 0");
  if (!(o.reassociation_translation_m >= 0.0)) problems.push_back("reassociation_translation_m must be >= 0");
  if (!(o.reassociation_rotation_rad >= 0.0)) problems.push_back("reassociation_rotation_rad must be >= 0");
  if (o.max_closure_correspondences < 0) problems.push_back("max_closure_correspondences must be >= 0");
  return problems;
}

MatcherEngine::MatcherEngine(const MatcherEngineOptions& options) : options_(options), dense_(options.pair.dense) {
  const std::vector<std::string> problems = validateMatcherEngineOptions(options_);
  if (!problems.empty()) throw std::invalid_argument("MatcherEngineOptions: " + problems.front());
}

void MatcherEngine::setCorrection(Stored& stored, const Pose& correction) {
  stored.correction = correction;
  stored.poses.clear();
  stored.poses.reserve(stored.subframe.pings.size());
  for (const auto& ping : stored.subframe.pings) stored.poses.push_back(correction * ping.T_world_body);
  stored.footprint = computeFootprint(stored.subframe, stored.poses, options_.overlap);
}

std::vector<Footprint> MatcherEngine::allFootprints() const {
  std::vector<Footprint> footprints;
  footprints.reserve(stored_.size());
  for (const auto& [id, stored] : stored_) footprints.push_back(stored.footprint);
  return footprints;
}

PairOutcome MatcherEngine::matchStored(const PairKey& key, int round) {
  const Stored& a = stored_.at(key.first);
  const Stored& b = stored_.at(key.second);
  const PairMatch match = matchPair(a.subframe, a.poses, b.subframe, b.poses, dense_, options_.pair);
  if (pair_observer_) pair_observer_(a.subframe, b.subframe, round, match);
  PairOutcome outcome;
  outcome.subframe_id_a = key.first;
  outcome.subframe_id_b = key.second;
  outcome.association_round = round;
  outcome.accepted = match.accepted;
  outcome.reason = match.reason;
  outcome.seconds = match.seconds;
  outcome.dense_timings = match.dense_timings;
  outcome.pose_seconds = match.pose.seconds;
  PairState& state = pairs_[key];
  state.rounds_done = round + 1;
  state.relative_at_match = a.correction.inverse() * b.correction;
  ++counters_.pairs_attempted;
  if (round > 0) ++counters_.rematches;
  counters_.pair_seconds_total += match.seconds;
  if (!match.accepted) {
    ++counters_.pairs_rejected;
    return outcome;
  }
  ++counters_.closures_accepted;
  if (match.opposed_relief_replaced) ++counters_.closures_without_opposed_relief;
  if (match.pass_disagreement_widened) ++counters_.closures_widened_by_passes;
  LoopClosure& c = outcome.closure;
  c.subframe_id_a = key.first;
  c.subframe_id_b = key.second;
  c.centre_utime_a_us = a.subframe.centre().utime_us;
  c.centre_utime_b_us = b.subframe.centre().utime_us;
  // The estimator works in the corrected frames; the optimiser's closure is between the DR-indexed
  // nodes, and a correction is world-frame, so T_a_b is the same in either (the correction of a
  // subframe moves all its pings rigidly).
  c.T_a_b = match.pose.T_a_b;
  c.covariance = match.pose.covariance;
  c.association_round = round;
  c.num_matches = static_cast<int>(match.matches.size());
  c.num_inliers = match.pose.num_inliers;
  c.range_cost = match.pose.range_cost;
  c.plane_cost = match.pose.plane_cost;
  c.total_cost = match.pose.total_cost;
  c.mean_zncc = static_cast<float>(match.mean_zncc);
  const auto& geometry = a.subframe.geometry;
  const std::vector<int>& inliers = match.pose.all_inlier_indices;
  const size_t published = std::min(inliers.size(), static_cast<size_t>(options_.max_closure_correspondences));
  c.correspondences.reserve(published);
  for (size_t k = 0; k < published; ++k) {
    const size_t i = k * inliers.size() / published;  // evenly thinned
    const Correspondence& m = match.matches[inliers[i]];
    ClosureCorrespondence cc;
    cc.ping_index_a = std::clamp(static_cast<int>(std::lround(m.row_a)), 0, a.subframe.rows() - 1);
    cc.column_a = static_cast<int>(std::lround(m.col_a));
    cc.ping_index_b = std::clamp(static_cast<int>(std::lround(m.row_b)), 0, b.subframe.rows() - 1);
    cc.column_b = static_cast<int>(std::lround(m.col_b));
    cc.slant_range_a_m = static_cast<float>(
        std::hypot(geometry.signedGroundRangeM(m.col_a), a.subframe.pings[cc.ping_index_a].altitude_m));
    cc.slant_range_b_m = static_cast<float>(
        std::hypot(b.subframe.geometry.signedGroundRangeM(m.col_b), b.subframe.pings[cc.ping_index_b].altitude_m));
    cc.landmark_a_m = match.pose.all_inlier_landmarks_a[i].cast<float>();
    c.correspondences.push_back(cc);
  }
  return outcome;
}

std::vector<PairOutcome> MatcherEngine::addSubframe(sss::core::Subframe subframe) {
  ++counters_.subframes_in;
  std::vector<PairOutcome> outcomes;
  if (!wellFormed(subframe) || stored_.count(subframe.id)) {
    ++counters_.subframes_rejected;
    return outcomes;
  }
  const int64_t id = subframe.id;
  Stored& stored = stored_[id];
  stored.subframe = std::move(subframe);
  setCorrection(stored, newSubframeCorrection(id, stored.subframe.line_id));
  // On disk before matching: if the process dies while matching, restore() finds the subframe
  // without a state entry and matches it then.
  if (store_) recordStateError(store_->writeSubframe(stored.subframe));
  outcomes = matchNewSubframe(id, allFootprints());
  evictBeyondLimit();
  saveState();
  return outcomes;
}

Pose MatcherEngine::newSubframeCorrection(int64_t id, int line_id) const {
  // A new subframe inherits the correction of the newest stored one of its line, else of the
  // newest stored subframe: the optimiser has not seen it yet, and DR continues from there.
  Pose correction = Pose::identity();
  for (auto it = stored_.rbegin(); it != stored_.rend(); ++it) {
    if (it->first == id) continue;
    correction = it->second.correction;
    if (it->second.subframe.line_id == line_id) break;
  }
  return correction;
}

std::vector<PairOutcome> MatcherEngine::matchNewSubframe(int64_t id, const std::vector<Footprint>& others) {
  std::vector<PairOutcome> outcomes;
  // findOverlaps skips the subframe's own footprint.
  for (const OverlapCandidate& candidate : findOverlaps(stored_.at(id).footprint, others, options_.overlap)) {
    const PairKey key{std::min(candidate.subframe_id, id), std::max(candidate.subframe_id, id)};
    if (pairs_.count(key)) continue;  // matched before a restart
    outcomes.push_back(matchStored(key, 0));
  }
  return outcomes;
}

void MatcherEngine::evictBeyondLimit() {
  // Bounded memory and disk: drop the oldest subframes, their pairs and their files.
  const double max_bytes = options_.max_stored_mib * 1024.0 * 1024.0;
  while (static_cast<int>(stored_.size()) > options_.max_stored_subframes ||
         (stored_.size() > 2 && static_cast<double>(memoryBytes()) > max_bytes)) {
    const int64_t oldest = stored_.begin()->first;
    stored_.erase(stored_.begin());
    for (auto it = pairs_.begin(); it != pairs_.end();) {
      it = it->first.first == oldest || it->first.second == oldest ? pairs_.erase(it) : std::next(it);
    }
    ++counters_.subframes_evicted;
    if (store_) recordStateError(store_->removeSubframe(oldest));
  }
}

MatcherState MatcherEngine::state() const {
  MatcherState state;
  state.corrections.reserve(stored_.size());
  for (const auto& [id, stored] : stored_) state.corrections.push_back({id, stored.correction});
  state.pairs.reserve(pairs_.size());
  for (const auto& [key, pair] : pairs_) {
    state.pairs.push_back({key.first, key.second, pair.rounds_done, pair.relative_at_match});
  }
  return state;
}

void MatcherEngine::saveState() {
  if (store_) recordStateError(store_->writeState(state()));
}

void MatcherEngine::recordStateError(const sss::core::Status& written) {
  if (written) return;
  ++counters_.state_write_errors;
  state_error_ = written.message;
}

std::string MatcherEngine::takeStateError() {
  std::string error;
  error.swap(state_error_);
  return error;
}

RestoreReport MatcherEngine::restore(MatcherStateStore& store) {
  if (store_ || !stored_.empty()) throw std::logic_error("MatcherEngine::restore: call once, on an empty engine");
  RestoreReport report;
  report.directory = store.directory();
  if (const sss::core::Status opened = store.open(); !opened) {
    ++counters_.state_write_errors;
    report.problems.push_back(opened.message + "; the matcher's state is not kept");
    return report;
  }
  store_ = &store;

  const sss::core::Result<std::optional<MatcherState>> read_state = store.readState();
  report.state_file_found = read_state && read_state->has_value();
  if (!read_state) {
    ++counters_.state_files_corrupt;
    report.problems.push_back(read_state.message() +
                              "; restoring the subframes without it (no corrections, pairs matched again)");
  }
  const MatcherState state = report.state_file_found ? **read_state : MatcherState{};
  std::map<int64_t, Pose> corrections;
  for (const SubframeCorrection& c : state.corrections) corrections[c.subframe_id] = c.correction;

  std::vector<int64_t> without_state;
  for (const int64_t id : store.subframeIds()) {  // ascending: a missing correction is inherited as when it came
    sss::core::Result<std::optional<sss::core::Subframe>> read = store.readSubframe(id);
    if (!read) {
      ++counters_.state_files_corrupt;
      // Never usable; removed so it is not reported at every start. The LCM log keeps the message.
      const sss::core::Status removed = store.removeSubframe(id);
      report.problems.push_back(read.message() + (removed ? "; skipped and removed" : "; skipped; " + removed.message));
      continue;
    }
    if (!read->has_value()) continue;
    Stored& stored = stored_[id];
    stored.subframe = std::move(**read);
    const auto correction = corrections.find(id);
    if (correction == corrections.end()) without_state.push_back(id);
    setCorrection(stored, correction != corrections.end() ? correction->second
                                                          : newSubframeCorrection(id, stored.subframe.line_id));
  }
  for (const PairRecord& p : state.pairs) {
    if (p.subframe_id_a < p.subframe_id_b && stored_.count(p.subframe_id_a) && stored_.count(p.subframe_id_b)) {
      pairs_[{p.subframe_id_a, p.subframe_id_b}] = PairState{p.rounds_done, p.relative_at_match};
    }
  }
  evictBeyondLimit();  // max_stored_subframes may be smaller than before the restart
  counters_.subframes_restored = stored_.size();
  counters_.pairs_restored = pairs_.size();

  // Subframes stored but not (all) matched when the process died: their pairs, as addSubframe
  // would have matched them (against the older subframes), except those already done.
  for (const int64_t id : without_state) {
    if (!stored_.count(id)) continue;  // evicted
    std::vector<Footprint> older;
    for (auto it = stored_.begin(); it != stored_.end() && it->first < id; ++it) older.push_back(it->second.footprint);
    for (PairOutcome& outcome : matchNewSubframe(id, older)) report.outcomes.push_back(std::move(outcome));
  }
  saveState();
  report.subframes = counters_.subframes_restored;
  report.pairs = counters_.pairs_restored;
  report.subframes_without_state = without_state.size();
  return report;
}

std::vector<PairOutcome> MatcherEngine::updateTrajectory(const std::vector<TrajectoryNode>& nodes) {
  ++counters_.trajectory_updates;
  std::vector<PairOutcome> outcomes;
  bool moved = false;
  for (const TrajectoryNode& node : nodes) {
    auto it = stored_.find(node.subframe_id);
    if (it == stored_.end()) continue;
    const Pose correction = node.T_world_body * it->second.subframe.centre().T_world_body.inverse();
    setCorrection(it->second, correction);
    moved = true;
  }
  if (!moved) return outcomes;
  if (options_.max_association_rounds == 0) {
    saveState();
    return outcomes;
  }

  // Re-association: pairs already matched whose relative pose moved (paper: n_iter rounds).
  std::vector<std::pair<PairKey, int>> jobs;
  for (const auto& [key, state] : pairs_) {
    if (state.rounds_done > options_.max_association_rounds) continue;
    const Stored& a = stored_.at(key.first);
    const Stored& b = stored_.at(key.second);
    const sss::core::Vector6d change = sss::core::boxMinus(a.correction.inverse() * b.correction, state.relative_at_match);
    if (change.head<3>().norm() > options_.reassociation_translation_m ||
        change.tail<3>().norm() > options_.reassociation_rotation_rad) {
      jobs.push_back({key, state.rounds_done});
    }
  }
  // Pairs that overlap only under the optimised poses (DR had them too far apart).
  const std::vector<Footprint> footprints = allFootprints();
  for (const auto& [id, stored] : stored_) {
    for (const OverlapCandidate& candidate : findOverlaps(stored.footprint, footprints, options_.overlap)) {
      if (candidate.subframe_id < id) continue;  // each pair once, from its older subframe
      const PairKey key{id, candidate.subframe_id};
      if (!pairs_.count(key)) jobs.push_back({key, 1});
    }
  }
  std::sort(jobs.begin(), jobs.end());
  jobs.erase(std::unique(jobs.begin(), jobs.end()), jobs.end());
  for (const auto& [key, round] : jobs) outcomes.push_back(matchStored(key, round));
  saveState();
  return outcomes;
}

size_t MatcherEngine::memoryBytes() const {
  size_t bytes = 0;
  for (const auto& [id, stored] : stored_) {
    const auto& s = stored.subframe;
    bytes += s.image.capacity() * sizeof(float) + s.mask.capacity() + s.pings.capacity() * sizeof(s.pings[0]) +
             stored.poses.capacity() * sizeof(Pose) + sizeof(Stored);
  }
  return bytes + pairs_.size() * (sizeof(PairKey) + sizeof(PairState) + 32);
}

}  // namespace sss::matcher
