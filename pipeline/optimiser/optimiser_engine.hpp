// The optimiser stage without middleware (stage 5 of the chain, README: Architecture): subframes become pose-graph nodes
// (centre DR pose, distance travelled), matcher loop closures become graph edges, each update
// yields the optimised centre poses (SSS_TRAJECTORY for the matcher) and the correction of any DR
// pose (SSS_POSE, DDS); at the end, full smoothing, the per-ping trajectory and the bathymetry.
// Used by the sss-optimiser process and by the offline runner, so both share every line of maths.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <set>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/core/config.hpp"
#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/core/closure_types.hpp"
#include "pipeline/optimiser/bathymetry.hpp"
#include "pipeline/optimiser/pose_graph.hpp"
#include "pipeline/core/subframe_types.hpp"

namespace sss::optimiser {

struct OptimiserEngineOptions {
  PoseGraphOptions graph;
  BathymetryOptions bathymetry;
  // Newest nodes sent to the matcher after an update (it keeps at most 240 subframes).
  int max_trajectory_nodes = 600;
  // Closures naming a subframe not seen yet (SSS_LOOP overtook SSS_SUBFRAME) wait for it.
  int max_pending_closures = 64;
  // Ping poses kept per subframe for the per-ping trajectory and the bathymetry: 200 pings of a
  // subframe take ~20 kB, 5000 subframes (~70 h of survey) ~100 MB. Oldest dropped first.
  int max_stored_subframes = 5000;
  // The INS odometer (distance_travelled_m) restarts at 0 when its bridge restarts: a centre whose
  // distance is lower than the previous one's by more than this is an odometer reset (see
  // addSubframe); a smaller decrease is jitter and counts as no distance.
  double odometer_reset_tolerance_m = 1.0;
};

void readOptimiserEngineOptions(sss::core::ConfigSection& section, OptimiserEngineOptions& options);
std::vector<std::string> validateOptimiserEngineOptions(const OptimiserEngineOptions& options);

struct OptimiserEngineCounters {
  uint64_t subframes_in = 0;
  uint64_t subframes_refused = 0;      // malformed, duplicate or out of order
  uint64_t closures_in = 0;
  uint64_t closures_refused = 0;       // refused by the graph (see its counters) or never resolved
  uint64_t closures_waiting = 0;       // now waiting for their subframe (filled by counters())
  uint64_t subframes_forgotten = 0;    // ping poses dropped beyond max_stored_subframes
  uint64_t odometer_resets = 0;        // INS odometer went backwards (see addSubframe)
  uint64_t odometry_drift_updates = 0; // the odometry's drift fraction taken from the INS (addNavAccuracy)
  double odometry_drift_fraction = 0.0; // the one in use (filled by counters())
};

// A stamped pose (per-ping trajectories).
struct StampedPose {
  int64_t utime_us = 0;
  sss::core::Pose T_world_body;
};

// Writes poses as TUM (timestamp_s north east down qx qy qz qw, local NED) with a comment line
// and, when known, the line naming the frame's origin (pipeline/core/mission_origin.hpp).
Status writeTum(const std::string& path, const std::vector<StampedPose>& poses, const std::string& comment,
                const std::optional<sss::core::MissionOrigin>& origin = std::nullopt);

// One closure for the loop_closures.csv table: the graph's record and the two centres under the
// current estimate.
struct ClosureSummary {
  ClosureRecord record;
  Eigen::Vector3d centre_a_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d centre_b_ned_m = Eigen::Vector3d::Zero();
  // B's centre in A's body frame as DR has it (before the solve) and as the current estimate has it
  // (after): the closure's offset from each is what a tie report lists.
  sss::core::Pose T_a_b_dr;
  sss::core::Pose T_a_b_estimate;
  float mean_zncc = 0.0f;
};

// Not thread-safe: one owner calls it. Deterministic for the same input order.
class OptimiserEngine {
 public:
  explicit OptimiserEngine(const OptimiserEngineOptions& options);

  // A new subframe (its image is not kept): a node at its centre ping. Subframes must come in
  // time order; a refused one leaves the engine unchanged. The graph's distance travelled is the
  // centre's plus an offset that keeps it monotonic: when the INS odometer goes back (its bridge
  // restarted), the distance from the previous node is the horizontal straight line between their
  // DR positions, and the offset carries on from there. Such a subframe is accepted with a notice
  // in the Status message (for the log) and counted in odometer_resets.
  Status addSubframe(const sss::core::Subframe& subframe);
  // A closure from the matcher. One naming a subframe not seen yet waits (bounded) for it.
  Status addLoopClosure(const sss::core::LoopClosure& closure);

  // An absolute position fix (GNSS, USBL) with the DR position and distance at its time, in the
  // navigation's own distance (the odometer offset is added here, as for subframes).
  Status addFix(AbsoluteFix fix);
  // The INS's reported position accuracy (every nav sample may carry one). The report nearest the
  // first node's time (within kAnchorAccuracyMaxGapS) widens that node's anchor to it
  // (SlidingWindowPoseGraph::setFirstNodeHorizontalSigma): how well the INS knew where the survey
  // started. Reports without a value are ignored; before the first node one per second is kept.
  void addNavAccuracy(const NavAccuracy& accuracy);
  // Every report also feeds the INS's drift rate (InsDriftEstimator): with
  // odometry_drift_from_ins, the graph's odometry takes it once it qualifies and whenever it
  // moves by more than kDriftUpdateRatio (OptimiserEngineCounters::odometry_drift_updates).
  static constexpr double kAnchorAccuracyMaxGapS = 30.0;
  static constexpr double kDriftUpdateRatio = 0.1;
  // True once the first node's anchor is decided (further reports only feed the drift rate).
  bool anchorDecided() const { return anchor_decided_; }
  // The odometry's drift fraction as the graph holds it, and whether it came from the INS.
  double odometryDriftFraction() const { return graph_.odometryDriftFraction(); }
  bool odometryDriftFromIns() const { return counters_.odometry_drift_updates > 0; }

  // Decides pending closures and solves the window (see SlidingWindowPoseGraph::optimize).
  UpdateReport update();
  // End of mission: full smoothing over all nodes.
  UpdateReport finish();
  // True when input arrived since the last update.
  bool hasNewInput() const { return new_input_; }

  // Optimised centre poses of the newest max_trajectory_nodes nodes (for the matcher).
  std::vector<sss::core::TrajectoryNode> trajectory() const;
  // Correction of a DR pose at utime_us: corrected = T_corrected_dr * DR.
  Correction correctionAt(int64_t utime_us) const { return graph_.correctionAt(utime_us); }

  // Every stored ping in time order, DR or corrected (the graph's correction interpolated at the
  // ping time).
  std::vector<StampedPose> pingTrajectory(bool corrected) const;
  // Seabed points of the accepted closures (latest association round of each pair), triangulated
  // with the corrected (use_dr = false) or the DR ping poses.
  std::vector<SeabedPoint> seabedPoints(bool use_dr) const;
  std::vector<ClosureSummary> closureSummaries() const;

  const SlidingWindowPoseGraph& graph() const { return graph_; }

  // Everything needed to carry on as if nothing happened: the graph (nodes, closures, decisions,
  // prior), the ping times and DR poses of the stored subframes, the closures' correspondences, the
  // closures waiting for their subframe, the odometer offset and the counters. Two files (see
  // optimiser_checkpoint.cpp): `path`, text rewritten atomically on each save (engine state and
  // graph: small, bounded by the graph), and `path`.journal, binary and append-only (each subframe's
  // ping poses and each closure's correspondences written once), so a save costs what arrived since
  // the previous one, however long the mission. `path` names the journal bytes that belong to it:
  // a crash between the two writes leaves a consistent pair.
  Status saveCheckpoint(const std::string& path);
  // Replaces the engine's state. A missing, old-version (1: the graph alone), truncated or corrupt
  // checkpoint or journal is refused with the reason and leaves the engine unchanged.
  Status loadCheckpoint(const std::string& path);
  OptimiserEngineCounters counters() const {
    OptimiserEngineCounters counters = counters_;
    counters.closures_waiting = waiting_.size();
    counters.odometry_drift_fraction = graph_.odometryDriftFraction();
    return counters;
  }
  const OptimiserEngineOptions& options() const { return options_; }
  size_t storedSubframes() const { return stored_.size(); }
  size_t memoryBytes() const;

 private:
  struct StoredSubframe {
    sss::core::Pose T_body_sonar;
    int centre_index = 0;
    std::vector<int64_t> utime_us;
    std::vector<sss::core::Pose> dr;  // T_world_body per ping
  };
  struct StoredCorrespondences {
    int association_round = 0;
    float mean_zncc = 0.0f;
    std::vector<sss::core::ClosureCorrespondence> correspondences;
  };

  // The journal that the checkpoint at `path` uses, and the records not appended to it yet.
  struct Journal {
    std::string path;  // empty: none yet (the next save writes a new one with everything)
    uint64_t id = 0;   // random, in both files: a journal of another checkpoint is refused
    uint64_t bytes = 0;
    uint64_t subframe_records = 0;
    uint64_t correspondence_records = 0;
  };

  Status addToGraph(const sss::core::LoopClosure& closure);
  // Gives the graph the INS accuracy nearest its first node's time, once one is on both sides of it
  // or the nearest is within kAnchorAccuracyMaxGapS and no nearer one can come.
  void decideAnchor();
  // World-frame correction of a stored subframe's pings (rigid, as the matcher applies it).
  sss::core::Pose subframeCorrection(int64_t id, const StoredSubframe& stored, bool use_dr) const;

  OptimiserEngineOptions options_;
  SlidingWindowPoseGraph graph_;
  std::map<int64_t, StoredSubframe> stored_;
  std::map<std::pair<int64_t, int64_t>, StoredCorrespondences> correspondences_;
  std::deque<sss::core::LoopClosure> waiting_;
  std::deque<NavAccuracy> start_accuracy_;  // INS accuracy reports until the anchor is decided
  InsDriftEstimator ins_drift_;             // the INS's drift rate from every report (odometry_drift_from_ins)
  bool anchor_decided_ = false;
  int64_t newest_subframe_id_ = -1;
  bool new_input_ = false;
  OptimiserEngineCounters counters_;
  // Graph distance travelled = subframe centre's distance_travelled_m + odometer_offset_m_.
  double odometer_offset_m_ = 0.0;
  double last_input_distance_m_ = 0.0;  // the centre's distance_travelled_m of the newest node
  Journal journal_;
  std::vector<int64_t> unjournaled_subframes_;
  std::set<std::pair<int64_t, int64_t>> unjournaled_pairs_;
};

}  // namespace sss::optimiser
