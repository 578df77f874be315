// Subframes and closures into the pose graph, corrections and bathymetry out. See optimiser_engine.hpp.
#include "pipeline/optimiser/optimiser_engine.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <optional>
#include <set>
#include <string>

namespace sss::optimiser {

using sss::core::Pose;

namespace {
// A subframe pair in either order: (older id, newer id).
std::pair<int64_t, int64_t> pairKey(int64_t a, int64_t b) { return {std::min(a, b), std::max(a, b)}; }

// At most `limit` correspondences, evenly spread (idempotent: a thinned list is kept as it is).
std::vector<sss::core::ClosureCorrespondence> thinned(const std::vector<sss::core::ClosureCorrespondence>& all,
                                                         int limit) {
  const size_t count = all.size();
  const size_t keep = std::min(count, static_cast<size_t>(std::max(limit, 0)));
  std::vector<sss::core::ClosureCorrespondence> out;
  out.reserve(keep);
  for (size_t k = 0; k < keep; ++k) out.push_back(all[k * count / keep]);
  return out;
}
}  // namespace

void readOptimiserEngineOptions(sss::core::ConfigSection& section, OptimiserEngineOptions& options) {
  using sss::core::inRange;
  sss::core::ConfigSection graph = section.section("graph");
  readPoseGraphOptions(graph, options.graph);
  graph.rejectUnknownKeys();
  sss::core::ConfigSection bathymetry = section.section("bathymetry");
  readBathymetryOptions(bathymetry, options.bathymetry);
  bathymetry.rejectUnknownKeys();
  section.optional("max_trajectory_nodes", options.max_trajectory_nodes, {inRange(1, 100000)});
  section.optional("max_pending_closures", options.max_pending_closures, {inRange(0, 100000)});
  section.optional("max_stored_subframes", options.max_stored_subframes, {inRange(1, 1000000)});
  section.optional("odometer_reset_tolerance_m", options.odometer_reset_tolerance_m, {inRange(0.0, 1e6)});
}

std::vector<std::string> validateOptimiserEngineOptions(const OptimiserEngineOptions& options) {
  std::vector<std::string> errors = validatePoseGraphOptions(options.graph);
  for (const std::string& error : validateBathymetryOptions(options.bathymetry)) errors.push_back(error);
  if (options.max_trajectory_nodes < 1) errors.push_back("max_trajectory_nodes must be >= 1");
  if (options.max_pending_closures < 0) errors.push_back("max_pending_closures must be >= 0");
  if (options.max_stored_subframes < 1) errors.push_back("max_stored_subframes must be >= 1");
  if (!(options.odometer_reset_tolerance_m >= 0.0)) errors.push_back("odometer_reset_tolerance_m must be >= 0");
  return errors;
}

Status writeTum(const std::string& path, const std::vector<StampedPose>& poses, const std::string& comment,
                const std::optional<sss::core::MissionOrigin>& origin) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return Status::error("cannot write " + path);
  // Every line of the comment behind a '#'.
  for (size_t start = 0; start <= comment.size();) {
    const size_t end = std::min(comment.find('\n', start), comment.size());
    std::fprintf(f, "# %s\n", comment.substr(start, end - start).c_str());
    start = end + 1;
  }
  std::fprintf(f, "# timestamp_s north_m east_m down_m qx qy qz qw (T_world_body, local NED of the mission origin)\n");
  if (origin) std::fprintf(f, "%s\n", sss::core::originCommentLine(*origin).c_str());
  for (const StampedPose& p : poses) {
    const auto& q = p.T_world_body.rotation;
    const auto& t = p.T_world_body.translation;
    std::fprintf(f, "%lld.%06lld %.4f %.4f %.4f %.9f %.9f %.9f %.9f\n", static_cast<long long>(p.utime_us / 1000000),
                 static_cast<long long>(p.utime_us % 1000000), t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  }
  if (std::fclose(f) != 0) return Status::error("cannot write " + path);
  return Status::success();
}

OptimiserEngine::OptimiserEngine(const OptimiserEngineOptions& options)
    : options_(options),
      graph_(options.graph),
      ins_drift_(options.graph.ins_drift) {}

Status OptimiserEngine::addSubframe(const sss::core::Subframe& subframe) {
  ++counters_.subframes_in;
  if (subframe.pings.empty() || subframe.centre_ping_index < 0 || subframe.centre_ping_index >= subframe.rows()) {
    ++counters_.subframes_refused;
    return Status::error("subframe " + std::to_string(subframe.id) + " has no centre ping");
  }
  const sss::core::SubframePing& centre = subframe.centre();
  const double input_m = centre.distance_travelled_m;
  if (!std::isfinite(input_m)) {
    ++counters_.subframes_refused;
    return Status::error("subframe " + std::to_string(subframe.id) + ": distance travelled is not finite; dropped");
  }
  // The graph needs a monotonic odometer; the INS's restarts at 0 with its bridge.
  double offset_m = odometer_offset_m_;
  double distance_m = input_m + offset_m;
  std::string notice;
  if (const std::optional<NodeState> previous = graph_.newestNode()) {
    if (input_m < last_input_distance_m_ - options_.odometer_reset_tolerance_m) {
      // Odometer reset: the distance since the previous node is lost; the horizontal straight line
      // between the DR positions is the figure left (a lower bound of the path, exact on a line).
      const double straight_m =
          (centre.T_world_body.translation - previous->T_world_body_dr.translation).head<2>().norm();
      distance_m = previous->distance_travelled_m + straight_m;
      offset_m = distance_m - input_m;
      char text[320];
      std::snprintf(text, sizeof(text),
                    "subframe %lld: INS odometer went back from %.3f m to %.3f m (odometer reset); distance from "
                    "the previous node taken as the straight line between their DR positions, %.3f m; graph "
                    "odometer offset now %.3f m",
                    static_cast<long long>(subframe.id), last_input_distance_m_, input_m, straight_m, offset_m);
      notice = text;
    } else {
      distance_m = std::max(distance_m, previous->distance_travelled_m);  // jitter within the tolerance
    }
  }
  const Status added = graph_.addNode(subframe.id, centre.utime_us, centre.T_world_body, distance_m);
  if (!added.ok) {
    ++counters_.subframes_refused;
    return added;
  }
  if (!notice.empty()) ++counters_.odometer_resets;
  if (graph_.numNodes() == 1) decideAnchor();
  odometer_offset_m_ = offset_m;
  last_input_distance_m_ = input_m;
  StoredSubframe& stored = stored_[subframe.id];
  stored.T_body_sonar = subframe.geometry.T_body_sonar;
  stored.centre_index = subframe.centre_ping_index;
  for (const sss::core::SubframePing& ping : subframe.pings) {
    stored.utime_us.push_back(ping.utime_us);
    stored.dr.push_back(ping.T_world_body);
  }
  unjournaled_subframes_.push_back(subframe.id);
  while (static_cast<int>(stored_.size()) > options_.max_stored_subframes) {
    stored_.erase(stored_.begin());
    ++counters_.subframes_forgotten;
  }
  newest_subframe_id_ = std::max(newest_subframe_id_, subframe.id);
  new_input_ = true;

  // Closures that were waiting for this subframe.
  std::deque<sss::core::LoopClosure> still_waiting;
  for (sss::core::LoopClosure& closure : waiting_) {
    const bool known = graph_.estimate(closure.subframe_id_a) && graph_.estimate(closure.subframe_id_b);
    if (known) {
      static_cast<void>(addToGraph(closure));  // a refusal is counted in closures_refused
    } else if (std::max(closure.subframe_id_a, closure.subframe_id_b) > newest_subframe_id_) {
      still_waiting.push_back(std::move(closure));
    } else {
      ++counters_.closures_refused;  // its subframe was missed (e.g. dropped on the bus)
    }
  }
  waiting_ = std::move(still_waiting);
  Status result = Status::success();
  result.message = notice;
  return result;
}

Status OptimiserEngine::addLoopClosure(const sss::core::LoopClosure& closure) {
  ++counters_.closures_in;
  const bool known = graph_.estimate(closure.subframe_id_a) && graph_.estimate(closure.subframe_id_b);
  if (!known && std::max(closure.subframe_id_a, closure.subframe_id_b) > newest_subframe_id_ &&
      options_.max_pending_closures > 0) {
    // Thinned now as addToGraph would: bounds what waits (and the checkpoint) without changing it.
    waiting_.push_back(closure);
    waiting_.back().correspondences = thinned(closure.correspondences, options_.bathymetry.max_points_per_closure);
    if (static_cast<int>(waiting_.size()) > options_.max_pending_closures) {
      waiting_.pop_front();
      ++counters_.closures_refused;
    }
    return Status::success();
  }
  return addToGraph(closure);
}

Status OptimiserEngine::addFix(AbsoluteFix fix) {
  fix.dr_distance_m += odometer_offset_m_;
  const Status added = graph_.addFix(fix);
  if (added.ok) new_input_ = true;
  return added;
}

Status OptimiserEngine::addToGraph(const sss::core::LoopClosure& closure) {
  LoopClosure edge;
  edge.subframe_id_a = closure.subframe_id_a;
  edge.subframe_id_b = closure.subframe_id_b;
  edge.T_a_b = closure.T_a_b;
  edge.covariance = closure.covariance;
  edge.association_round = closure.association_round;
  edge.num_inliers = closure.num_inliers;
  edge.total_cost = closure.total_cost;
  const Status added = graph_.addLoopClosure(edge);
  if (!added.ok) {
    ++counters_.closures_refused;
    return added;
  }
  new_input_ = true;
  // The correspondences of the newest association round of the pair, thinned evenly.
  const auto key = pairKey(closure.subframe_id_a, closure.subframe_id_b);
  auto existing = correspondences_.find(key);
  if (existing != correspondences_.end() && existing->second.association_round > closure.association_round) {
    return added;
  }
  StoredCorrespondences& stored = correspondences_[key];
  stored.association_round = closure.association_round;
  stored.mean_zncc = closure.mean_zncc;
  stored.correspondences = thinned(closure.correspondences, options_.bathymetry.max_points_per_closure);
  unjournaled_pairs_.insert(key);
  // A closure stored as (b, a) has its correspondences the other way round.
  if (closure.subframe_id_a != key.first) {
    for (auto& c : stored.correspondences) {
      std::swap(c.ping_index_a, c.ping_index_b);
      std::swap(c.column_a, c.column_b);
      std::swap(c.slant_range_a_m, c.slant_range_b_m);
      c.landmark_a_m.setConstant(std::nanf(""));  // in B's frame now: not usable as a start
    }
  }
  return added;
}

UpdateReport OptimiserEngine::update() {
  new_input_ = false;
  return graph_.optimize();
}

UpdateReport OptimiserEngine::finish() {
  new_input_ = false;
  // Closures still waiting can no longer be resolved.
  counters_.closures_refused += waiting_.size();
  waiting_.clear();
  graph_.optimize();
  return graph_.fullSmoothing();
}

std::vector<sss::core::TrajectoryNode> OptimiserEngine::trajectory() const {
  const std::vector<NodeState> nodes = graph_.nodes();
  const size_t first = nodes.size() > static_cast<size_t>(options_.max_trajectory_nodes)
                           ? nodes.size() - static_cast<size_t>(options_.max_trajectory_nodes)
                           : 0;
  std::vector<sss::core::TrajectoryNode> out;
  out.reserve(nodes.size() - first);
  for (size_t i = first; i < nodes.size(); ++i) {
    out.push_back({nodes[i].subframe_id, nodes[i].utime_us, nodes[i].T_world_body});
  }
  return out;
}

std::vector<StampedPose> OptimiserEngine::pingTrajectory(bool corrected) const {
  std::vector<StampedPose> out;
  for (const auto& [id, stored] : stored_) {
    for (size_t i = 0; i < stored.dr.size(); ++i) {
      Pose pose = stored.dr[i];
      if (corrected) pose = graph_.correctionAt(stored.utime_us[i]).T_corrected_dr * pose;
      out.push_back({stored.utime_us[i], pose});
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const StampedPose& a, const StampedPose& b) { return a.utime_us < b.utime_us; });
  return out;
}

Pose OptimiserEngine::subframeCorrection(int64_t id, const StoredSubframe& stored, bool use_dr) const {
  if (use_dr) return Pose::identity();
  const auto estimate = graph_.estimate(id);
  if (!estimate) return Pose::identity();
  return *estimate * stored.dr[static_cast<size_t>(stored.centre_index)].inverse();
}

std::vector<SeabedPoint> OptimiserEngine::seabedPoints(bool use_dr) const {
  // Accepted closures only: a rejected one may pair unrelated seabed.
  std::set<std::pair<int64_t, int64_t>> accepted;
  for (const ClosureRecord& record : graph_.closures()) {
    if (record.status != ClosureStatus::kAccepted) continue;
    accepted.insert(pairKey(record.closure.subframe_id_a, record.closure.subframe_id_b));
  }
  std::vector<SeabedPoint> points;
  for (const auto& [key, stored] : correspondences_) {
    if (!accepted.count(key)) continue;
    const auto a = stored_.find(key.first);
    const auto b = stored_.find(key.second);
    if (a == stored_.end() || b == stored_.end()) continue;
    const Pose correction_a = subframeCorrection(key.first, a->second, use_dr);
    const Pose correction_b = subframeCorrection(key.second, b->second, use_dr);
    const Pose centre_a = correction_a * a->second.dr[static_cast<size_t>(a->second.centre_index)];
    for (const sss::core::ClosureCorrespondence& c : stored.correspondences) {
      if (c.ping_index_a < 0 || c.ping_index_b < 0 || c.ping_index_a >= static_cast<int>(a->second.dr.size()) ||
          c.ping_index_b >= static_cast<int>(b->second.dr.size())) {
        continue;
      }
      SonarObservation observation_a{correction_a * a->second.dr[static_cast<size_t>(c.ping_index_a)] * a->second.T_body_sonar,
                                     c.slant_range_a_m};
      SonarObservation observation_b{correction_b * b->second.dr[static_cast<size_t>(c.ping_index_b)] * b->second.T_body_sonar,
                                     c.slant_range_b_m};
      // Start from the matcher's landmark; without it, straight below the midpoint of the sonars.
      Eigen::Vector3d initial = centre_a.rotation * c.landmark_a_m.cast<double>() + centre_a.translation;
      if (!initial.allFinite()) {
        initial = 0.5 * (observation_a.T_world_sonar.translation + observation_b.T_world_sonar.translation);
        initial.z() += 0.5 * (c.slant_range_a_m + c.slant_range_b_m);
      }
      auto point = triangulateSeabedPoint(observation_a, observation_b, initial, options_.bathymetry);
      if (!point) continue;
      point->subframe_id_a = key.first;
      point->subframe_id_b = key.second;
      points.push_back(*point);
    }
  }
  return points;
}

std::vector<ClosureSummary> OptimiserEngine::closureSummaries() const {
  std::vector<ClosureSummary> out;
  std::map<int64_t, NodeState> node_of;
  for (const NodeState& n : graph_.nodes()) node_of[n.subframe_id] = n;
  for (const ClosureRecord& record : graph_.closures()) {
    ClosureSummary summary;
    summary.record = record;
    const auto a = node_of.find(record.closure.subframe_id_a), b = node_of.find(record.closure.subframe_id_b);
    if (a != node_of.end() && b != node_of.end()) {
      summary.centre_a_ned_m = a->second.T_world_body.translation;
      summary.centre_b_ned_m = b->second.T_world_body.translation;
      summary.T_a_b_dr = sss::core::between(a->second.T_world_body_dr, b->second.T_world_body_dr);
      summary.T_a_b_estimate = sss::core::between(a->second.T_world_body, b->second.T_world_body);
    }
    const auto key = pairKey(record.closure.subframe_id_a, record.closure.subframe_id_b);
    if (auto found = correspondences_.find(key); found != correspondences_.end()) summary.mean_zncc = found->second.mean_zncc;
    out.push_back(summary);
  }
  return out;
}

size_t OptimiserEngine::memoryBytes() const {
  size_t bytes = 0;
  for (const auto& [id, stored] : stored_) bytes += stored.dr.size() * (sizeof(Pose) + sizeof(int64_t));
  for (const auto& [key, stored] : correspondences_) {
    bytes += stored.correspondences.size() * sizeof(sss::core::ClosureCorrespondence);
  }
  return bytes + graph_.numNodes() * 1024;  // graph: ~1 kB per node (estimates, covariances, factors)
}

void OptimiserEngine::addNavAccuracy(const NavAccuracy& accuracy) {
  const bool reported = std::isfinite(accuracy.north_std_m) && std::isfinite(accuracy.east_std_m) &&
                        accuracy.north_std_m > 0.0 && accuracy.east_std_m > 0.0;
  if (!reported) return;
  if (options_.graph.odometry_drift_from_ins) {
    ins_drift_.add(accuracy.distance_travelled_m, 0.5 * (accuracy.north_std_m + accuracy.east_std_m));
    const std::optional<double> drift = ins_drift_.driftFraction();
    const double held = graph_.odometryDriftFraction();
    if (drift && (counters_.odometry_drift_updates == 0 || std::abs(*drift - held) > kDriftUpdateRatio * held)) {
      if (graph_.setOdometryDriftFraction(*drift).ok) ++counters_.odometry_drift_updates;
    }
  }
  if (anchor_decided_) return;
  // One per second is plenty (the INS's accuracy changes slowly); 20 min of them at most, oldest
  // dropped: the first subframe's centre is well within that of its last ping.
  constexpr int64_t kSpacingUs = 1'000'000;
  constexpr size_t kMaxKept = 1200;
  if (!start_accuracy_.empty() && accuracy.utime_us < start_accuracy_.back().utime_us + kSpacingUs &&
      accuracy.utime_us >= start_accuracy_.back().utime_us)
    return;
  start_accuracy_.push_back(accuracy);
  if (start_accuracy_.size() > kMaxKept) start_accuracy_.pop_front();
  if (graph_.numNodes() > 0) decideAnchor();
}

void OptimiserEngine::decideAnchor() {
  if (anchor_decided_ || graph_.numNodes() == 0) return;
  const int64_t node_us = *graph_.firstNodeUtime();
  const int64_t max_gap_us = static_cast<int64_t>(kAnchorAccuracyMaxGapS * 1e6);
  const NavAccuracy* nearest = nullptr;
  bool after_node = false;
  for (const NavAccuracy& a : start_accuracy_) {
    if (a.utime_us >= node_us) after_node = true;
    if (!nearest || std::llabs(a.utime_us - node_us) < std::llabs(nearest->utime_us - node_us)) nearest = &a;
  }
  // A report after the node's time: none nearer can come (nav arrives in time order).
  if (!after_node) return;
  if (nearest && std::llabs(nearest->utime_us - node_us) <= max_gap_us) {
    // Refused only when no report came after the first node's time for a whole window (it has
    // been marginalised): then the anchor keeps first_node_sigma_m.
    (void)graph_.setFirstNodeHorizontalSigma(nearest->north_std_m, nearest->east_std_m);
  }
  anchor_decided_ = true;
  start_accuracy_.clear();
  start_accuracy_.shrink_to_fit();
}

}  // namespace sss::optimiser
