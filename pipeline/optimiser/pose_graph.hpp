// Sliding-window pose graph over subframe-centre poses (stage 5 of the chain, README: Architecture; paper Sec. "Pose Graph
// Optimization", eq. (6)): DR odometry chain plus loop closures with robust rejection (Cauchy loss,
// chi-square gate, pairwise consistency), Schur-complement marginalisation, full smoothing,
// corrections for any time and checkpoints. Pure C++ over Ceres: no LCM, DDS or systemd.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "pipeline/core/config.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/core/sensor_types.hpp"
#include "pipeline/core/status.hpp"
#include "pipeline/optimiser/ins_drift_estimator.hpp"

namespace ceres {
class CostFunction;
class LossFunction;
}  // namespace ceres

namespace sss::optimiser {

struct CalibratedOdometryError;  // pose_manifold.hpp

struct PoseGraphOptions {
  // ---- sliding window ----------------------------------------------------------------------------
  // Nodes optimised per update; older ones are marginalised into a prior. Adjacent-line closures
  // stay inside the window when it spans two survey lines (2 x 4 subframes for 400 m lines).
  int window_size = 30;

  // ---- DR odometry between consecutive nodes, d = distance travelled between them (m) -------------
  // Covariance in the [dt, dr] tangent of the relative pose (see odometryCovariance()):
  //   horizontal sigma^2 = (random_walk * sqrt(d))^2 + (drift_fraction * d)^2 + min_sigma^2 (x and y)
  //   vertical sigma     = depth_sigma (depth is measured absolutely: relative error does not grow)
  //   heading sigma^2    = (heading_random_walk * sqrt(d))^2 + min_heading_sigma^2
  //   roll, pitch sigma  = attitude_sigma (the INS measures them absolutely against gravity)
  double odometry_random_walk_m_per_sqrt_m = 0.02;  // DVL velocity noise integrated over distance
  double odometry_drift_fraction = 0.005;           // 0.5 % of distance, 1 sigma (heading/scale bias)
  double odometry_min_sigma_m = 0.05;               // keeps nodes a few metres apart well posed
  double odometry_depth_sigma_m = 0.1;
  double odometry_heading_random_walk_rad_per_sqrt_m = 2e-4;  // 0.002 rad (0.11 deg) per 100 m
  double odometry_min_heading_sigma_rad = 1e-4;
  double odometry_attitude_sigma_rad = 0.002;
  // The drift fraction from the INS's own reported position accuracy: its growth per metre travelled
  // since its last aiding (InsDriftEstimator, fed by OptimiserEngine::addNavAccuracy), once it
  // qualifies (ins_drift); odometry_drift_fraction until then, and for navigation that reports no
  // accuracy (files with the position in the ping headers).
  bool odometry_drift_from_ins = true;
  InsDriftEstimatorOptions ins_drift;

  // ---- absolute INS measurements of every node (0 switches one off) -------------------------------
  // Depth, roll, pitch and heading are measured against absolute references (pressure, gravity,
  // earth rotation): their error stays bounded however far the vehicle goes, unlike position. Without
  // these a long chain of adjacent-line closures lets heading (and so position) wander further than
  // the DR itself. Sigmas are per node and treated as independent between nodes, so they are
  // wider than the INS's specification (which is mostly a slowly varying bias).
  double absolute_depth_sigma_m = 0.2;
  double absolute_roll_pitch_sigma_rad = 0.002;
  double absolute_heading_sigma_rad = 0.005;

  // ---- anchor: the first node's DR pose fixes the gauge --------------------------------------------
  double first_node_sigma_m = 0.1;
  double first_node_sigma_rad = 0.001;
  // Widen the horizontal anchor to the INS's own reported position accuracy at the first node
  // (setFirstNodeHorizontalSigma). Off for an INS whose reported accuracy is not to be trusted:
  // the anchor is then first_node_sigma_m alone.
  bool first_node_sigma_from_ins = true;

  // ---- loop closures ------------------------------------------------------------------------------
  std::string robust_loss = "cauchy";  // "cauchy", "huber" or "none", on the whitened closure residual
  double robust_loss_scale = 4.0;      // whitened residual norm where down-weighting starts
  int min_closure_inliers = 0;         // closures with fewer RANSAC inliers are rejected on arrival
  // Chi-square gate of a new closure against the current estimate (6 dof: 22.46 = 99.9 %), applied
  // once this many closures are accepted (before that the estimate is DR and says little more
  // than the pairwise test).
  double gate_chi2 = 22.46;
  int gate_min_accepted_closures = 5;
  // The same test once more at full smoothing, against the smoothed survey. PCM compares closures
  // two at a time through DR chains whose drift model is wide, so a closure can pass it and still
  // lie many sigmas from the solution everything else agrees on (measured: a far-range pair on a
  // rippled seabed matched 6.9 m off, 9 sigma, as the first closure, when the gate above was not
  // yet active). Each closure's chi-square is its leave-one-out innovation: its residual against
  // the survey the other factors give, under the covariance of both (linearised at the solution; an
  // outlier bends the graph towards itself, so its residual under the solution alone says little).
  // The worst closure beyond this is rejected (kChiSquareGate) and the graph solved again, until
  // none is left. It runs before closure_reweighting, under the closures' stated covariances. 0: off.
  double smoothed_gate_chi2 = 22.46;
  // Pairwise consistency (PCM): cycle closure_i * DR chain * closure_j^-1 * DR chain within this
  // chi-square (6 dof: 16.81 = 99 %); the largest mutually consistent set among the newest
  // pcm_max_closures closures is accepted when it has at least min_consistent_closures members
  // (counted as below).
  double pcm_chi2 = 16.81;
  int pcm_max_closures = 100;
  int min_consistent_closures = 2;
  // Count only closures that share no subframe, both for min_consistent_closures and to choose
  // between consistent sets: closures through one subframe share the errors of its image, so they
  // agree with each other whatever those are (a subframe matched 1.2 m off along track to two
  // neighbouring subframes of another line gives two closures that pass the pairwise test together).
  // false: every closure counts, as PCM assumes independent closures.
  bool pcm_count_independent_subframes = true;

  // ---- solver -------------------------------------------------------------------------------------
  int max_iterations = 10;            // per window update; deterministic bound
  double max_solver_time_s = 0.0;     // > 0 adds a wall-clock bound (then results depend on load)
  int full_smoothing_max_iterations = 100;

  // ---- weights from the residuals (variance components, variance_components.hpp) -----------------
  // At full smoothing, factors on the configured closure and odometry covariances from the
  // solution's own residuals and each group's redundancy, iterated up to
  // variance_component_iterations times:
  //   "none": the configured covariances as they are;
  //   "dr_bound": the odometry model is a specification DR stays within, so closures may not strain
  //     it beyond: when the odometry residuals exceed their model (factor > 1) the closures are
  //     widened by that factor until they fit, else nothing changes. Closures whose errors are
  //     common to a pair (relief at far range) agree with each other and only DR can show them;
  //   "variance_components": both factors estimated (Förstner); measured worse on the randomised
  //     missions: a pair-common closure error is absorbed by stretching DR.
  // Each factor stays within [variance_factor_min, variance_factor_max]. Whatever the mode, full
  // smoothing measures DR's strain (VarianceFactors::odometry_strain).
  std::string closure_reweighting = "none";
  // ---- separation bias of closures between lines that look at their overlap from opposite sides --
  // A raised feature (rock, boulder) shows each line the face turned towards it, and the shadow
  // behind: the dense matches of two lines looking at it from opposite sides pair those two faces, so
  // every such closure places the lines closer together, by about the features' half width (measured
  // on randomised missions: 1.2-1.6 m on rock outcrops and boulders, about 0 on mud and sand). No
  // spread inside a pair shows it and the closures of all pairs agree, so neither the closure
  // covariance nor their consistency can. At full smoothing one bias for the whole survey is
  // estimated against DR with a zero-mean prior of this sigma; closures between parallel or
  // anti-parallel lines (relative heading within 30 deg) more than separation_bias_min_lateral_m
  // apart are corrected by it (window updates use the last estimate) when separation_bias_apply is
  // set; otherwise it is only measured (a diagnostic solve whose estimate is discarded), so a run
  // can say that its closures and DR disagree on the lines' separation. 0: neither.
  // The bias is applied only when the data say it is there: |estimate| at least
  // separation_bias_significance of its own sigma. Estimating it costs lateral accuracy (the
  // survey's width then rests on DR alone): on the synthetic lawnmower with truthful closures a
  // free bias of 0.1-0.4 +- 0.3 m per pair spreads the lines and doubles the ATE.
  // Not applied by default because on a lawnmower it is confounded with DR: a DVL scale factor lengthens
  // every turn between lines alike, which moves DR's line separations by the same amount (0.6 % of
  // a 157 m turn: 0.9 m), and the test then takes DR's error for the closures' (README, measured:
  // high-drift 1.72 -> 3.31 m). Absolute fixes or cross lines would tell the two apart.
  double separation_bias_sigma_m = 2.0;
  bool separation_bias_apply = false;
  // When the bias is significant, not applied and a shortening (what feature faces do), the closures
  // and DR disagree on the lines' separation and nothing tells which is wrong: widen the lateral
  // variance of the opposite-side closures by the disputed amount (estimate^2 + sigma^2), so they
  // keep what they say along track and in heading and stop pulling the lines together.
  bool separation_bias_widen = false;
  // The same widening once absolute fixes were accepted: the DVL scale is then estimated in the
  // solve that measures the bias (calibration auto), so a significant shortening is the closures'
  // and not DR's scale on the turns, the confusion that keeps separation_bias_widen off by default.
  bool separation_bias_widen_with_fixes = true;
  double separation_bias_min_lateral_m = 10.0;
  double separation_bias_significance = 3.0;

  // ---- absolute position fixes (GNSS at the surface, USBL) ------------------------------------------
  // A fix is a horizontal position with its covariance, tied to the node nearest in time through the
  // DR displacement between the node and the fix (whose drift over that distance adds the odometry
  // model's covariance). Like a closure it must pass a chi-square gate of its innovation against the
  // node's current estimate and covariance (2 dof: 13.82 = 99.9 %), so an outlying USBL fix does not
  // pull the survey, and it enters the solve under the closures' robust loss.
  double fix_gate_chi2 = 13.82;
  // A GNSS receiver's error (ionosphere, satellite orbits and clocks, multipath) changes over
  // minutes, not from one fix to the next: a vehicle logging 1 Hz GGA for five minutes at the
  // surface has a few independent fixes' worth of information, not 300. Treated as independent they
  // would pin the survey to their common error with a seventeenth of its sigma. The error is modelled as
  // first-order Gauss-Markov with this correlation time per source (0: independent fixes): a fix dt
  // after the previous fix of its source, rho = exp(-dt / tau), enters the solve with its information
  // times (1 - rho) / (1 + rho). Summed over a run of fixes that is exactly the information a
  // correlated series holds about a common offset (1 + (n - 1)(1 - rho) / (1 + rho) fixes' worth).
  // Each fix is still gated against its own sigma. USBL errors are mostly the acoustic noise of each
  // reply (independent); a USBL system known for slow errors (sound-speed profile, a mounting
  // misalignment) can set a time.
  double gnss_fix_correlation_s = 300.0;
  double usbl_fix_correlation_s = 0.0;

  // ---- calibration of the DR sensors -----------------------------------------------------------------
  // DVL scale factor s (DR's horizontal odometry is (1 + s) times the distance flown) and the INS
  // heading error e(psi) = b + a_c cos(psi) + a_s sin(psi): a constant bias, and the error of one
  // cycle per revolution (gyrocompass steaming and alignment residuals) that does not cancel on the
  // reversed lines of a lawnmower. Estimated at full smoothing with zero-mean priors of these sigmas,
  // then held by the window. Absolute fixes observe all of them. Closures alone observe a_c and a_s
  // (reversed lines drift apart) but not b (it turns the whole survey), and the scale mostly through
  // the turns' length, where it cannot be told from the matcher's separation bias (README, measured:
  // "always" without fixes gave scale errors of 2-8 sigma on randomised missions).
  //   "auto": everything once fixes were accepted, else nothing;
  //   "heading": the heading error always, the scale once fixes were accepted;
  //   "always": everything always; "never".
  std::string calibration = "auto";
  double calibration_scale_sigma = 0.005;
  double calibration_heading_bias_sigma_rad = 0.005;
  double calibration_heading_deviation_sigma_rad = 0.005;
  // While the mission runs the window holds the last estimate; a full smoothing re-estimates it once
  // this much mission time has passed since the last one (the live optimiser then corrects with
  // it as a post-processing run would). 0: only at the end of the mission.
  double calibration_period_s = 600.0;
  // odometry_drift_fraction models the scale and heading errors as independent per edge; once they
  // are estimated, what is left drifts by this (slowly varying gyro bias, scale changing with the
  // seabed): otherwise every edge's slack absorbs what the calibration should explain.
  double calibrated_odometry_drift_fraction = 0.001;

  int variance_component_iterations = 20;
  double variance_factor_min = 0.1;
  double variance_factor_max = 100.0;

  // ---- corrections --------------------------------------------------------------------------------
  double degraded_after_s = 1800.0;   // status DEGRADED when the newest accepted closure is older
  double nominal_speed_m_s = 2.0;     // DR growth after the newest node when no speed is known yet
};

std::vector<std::string> validatePoseGraphOptions(const PoseGraphOptions& options);
void readPoseGraphOptions(sss::core::ConfigSection& section, PoseGraphOptions& options);

// Result of an input call: ok, or why the input was refused (the graph is unchanged then).
using Status = sss::core::Status;

// A loop closure from the matcher (SSS_LOOP).
struct LoopClosure {
  int64_t subframe_id_a = 0;
  int64_t subframe_id_b = 0;
  sss::core::Pose T_a_b;  // B's centre body frame in A's
  sss::core::Matrix6d covariance = sss::core::Matrix6d::Identity();  // [dt, dr] at T_a_b (boxPlus)
  int association_round = 0;  // a newer round of the same pair supersedes the older closure
  int num_inliers = 0;
  double total_cost = 0.0;
};

// The INS's own 1-sigma accuracy of its horizontal position at a time (SSS_NAV's
// position_std_ned_m; 0 or not finite: not reported).
struct NavAccuracy {
  int64_t utime_us = 0;
  double north_std_m = 0.0;
  double east_std_m = 0.0;
  double distance_travelled_m = std::numeric_limits<double>::quiet_NaN();  // the INS odometer (NaN: unknown)
};
// What a navigation sample reports of its accuracy.
inline NavAccuracy navAccuracyOf(const sss::core::NavSample& nav) {
  return {nav.utime_us, nav.position_std_north_m, nav.position_std_east_m, nav.distance_travelled_m};
}

// An absolute horizontal position fix in the local NED world (GNSS at the surface, USBL).
struct AbsoluteFix {
  int64_t utime_us = 0;
  Eigen::Vector2d position_ne_m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance_m2 = Eigen::Matrix2d::Identity();  // north/east
  // DR position and distance travelled at the fix time, from the navigation the nodes come from: the
  // fix is tied to its node through the DR displacement between them.
  Eigen::Vector3d dr_position_m = Eigen::Vector3d::Zero();
  double dr_distance_m = 0.0;
  std::string source = "gnss";  // "gnss" or "usbl" (reported)
};

enum class FixStatus { kPending, kAccepted, kRejected };

struct FixRecord {
  AbsoluteFix fix;
  FixStatus status = FixStatus::kPending;
  int64_t subframe_id = -1;   // the node it is tied to; -1 until a node at or after its time exists
  double innovation_chi2 = std::numeric_limits<double>::quiet_NaN();  // at the gate
  // After the solve: the fix less the node's estimate carried to the fix time (north, east), m.
  Eigen::Vector2d residual_ne_m = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  // The share of the fix's own information the solve takes (1: independent of the fixes before it;
  // PoseGraphOptions::gnss_fix_correlation_s).
  double information_weight = 1.0;
};

struct FixCounters {
  uint64_t received = 0;
  uint64_t refused = 0;       // not finite, covariance not positive definite, no navigation
  uint64_t accepted = 0;
  uint64_t rejected_gate = 0;
};

enum class ClosureStatus { kPending, kAccepted, kRejected, kSuperseded };
enum class ClosureRejection {
  kNone,
  kChiSquareGate,    // innovation against the current estimate beyond gate_chi2, or (at full
                     // smoothing) its leave-one-out innovation beyond smoothed_gate_chi2
  kInconsistent,     // outside the largest pairwise-consistent set
  kNoSupport,        // left the PCM horizon without ever being in a large enough consistent set
};
const char* closureRejectionName(ClosureRejection rejection);

struct ClosureRecord {
  LoopClosure closure;
  ClosureStatus status = ClosureStatus::kPending;
  ClosureRejection rejection = ClosureRejection::kNone;
  // Its information is in the marginalisation prior: a later rejection cannot withdraw it from the
  // window (counted in closures_withdrawn_after_marginalisation), but full smoothing drops it.
  bool marginalised = false;
};

struct NodeState {
  int64_t subframe_id = 0;
  int64_t utime_us = 0;
  sss::core::Pose T_world_body_dr;
  sss::core::Pose T_world_body;  // current estimate (frozen once marginalised, until fullSmoothing)
  double distance_travelled_m = 0.0;
  bool marginalised = false;
};

struct PoseGraphCounters {
  uint64_t nodes_added = 0;
  uint64_t nodes_refused = 0;         // bad input (order, duplicate id, non-finite)
  uint64_t nodes_marginalised = 0;
  uint64_t closures_received = 0;
  uint64_t closures_refused = 0;      // unknown id, self loop, bad covariance, too few inliers...
  // Decisions now (a PCM decision may change while the closure is in the PCM horizon):
  uint64_t closures_pending = 0;
  uint64_t closures_accepted = 0;
  uint64_t closures_rejected_gate = 0;
  uint64_t closures_rejected_inconsistent = 0;
  uint64_t closures_rejected_no_support = 0;
  uint64_t closures_superseded = 0;
  uint64_t closures_withdrawn_after_marginalisation = 0;
  uint64_t updates = 0;
  uint64_t full_smoothings = 0;
  uint64_t solver_failures = 0;
  double last_update_s = 0.0;         // whole optimize(): decisions, solve, marginalisation, covariance
  double last_solve_s = 0.0;          // the Ceres solve alone
  int last_iterations = 0;
};

// The size of the optimisation problem solved by the last update (before that update marginalised
// the oldest node): constant once the window is full.
struct WindowStats {
  int active_nodes = 0;
  int variable_blocks = 0;   // active nodes
  int constant_blocks = 0;   // marginalised nodes referenced by accepted closures
  int residual_blocks = 0;
  int prior_nodes = 0;
  int prior_rows = 0;
  int pcm_candidates = 0;
};

struct UpdateReport {
  bool ok = true;
  std::string message;  // why the solve failed (the previous estimate is kept)
  int iterations = 0;
  double solve_s = 0.0;
  double update_s = 0.0;
  int closures_decided = 0;  // closures whose status changed in this update
};

// Factors on the configured closure and odometry covariances (1 until full smoothing estimates them,
// see PoseGraphOptions::variance_component_iterations), with what the last estimate rested on.
struct VarianceFactors {
  double closure = 1.0;
  double odometry = 1.0;
  double closure_redundancy = 0.0;   // rows of the accepted closures the solution does not absorb
  double odometry_redundancy = 0.0;
  // Odometry residuals over their model at the last full smoothing, with the final weights: above 1
  // the closures bend DR further than its own error model allows, a sign of closures with a common
  // error (measured on randomised missions: above 1 exactly where SLAM ended worse than DR). NaN
  // before any full smoothing or when nothing is redundant.
  double odometry_strain = std::numeric_limits<double>::quiet_NaN();
  int closures = 0;                  // accepted closures in the last estimate
  int iterations = 0;                // estimates over the mission
};

// The survey-wide separation bias of opposite-side closures (PoseGraphOptions::separation_bias_sigma_m):
// how much closer together the closures place the lines than they are.
struct SeparationBias {
  double estimate_m = 0.0;  // applied to the closures (0 unless significant)
  double tested_m = 0.0;    // the last full smoothing's estimate, applied or not
  double sigma_m = std::numeric_limits<double>::quiet_NaN();  // of tested_m; NaN until estimated
  bool significant = false; // |tested_m| >= separation_bias_significance x sigma_m
  bool applied = false;     // significant and separation_bias_apply
  int closures = 0;         // accepted opposite-side closures at the last estimate
};

// The DR sensor calibration (PoseGraphOptions::calibration) as last estimated.
struct DrCalibration {
  bool estimated = false;          // the odometry and INS factors use it (held between smoothings)
  bool scale_estimated = false;    // the DVL scale too (with fixes); else it stays 0, sigma NaN
  double dvl_scale = 0.0;          // s: DR distance = (1 + s) x true
  double heading_bias_rad = 0.0;   // b
  double heading_cos_rad = 0.0;    // a_c: e(psi) = b + a_c cos(psi) + a_s sin(psi)
  double heading_sin_rad = 0.0;    // a_s
  // 1-sigma of each, from the solve's covariance; NaN before an estimate.
  Eigen::Vector4d sigma = Eigen::Vector4d::Constant(std::numeric_limits<double>::quiet_NaN());
  double headingErrorRad(double heading_rad) const {
    return heading_bias_rad + heading_cos_rad * std::cos(heading_rad) + heading_sin_rad * std::sin(heading_rad);
  }
};

enum class CorrectionStatus { kDrOnly, kCorrected, kDegraded };

// corrected = T_corrected_dr * T_world_body_dr for the same time (world-frame correction).
struct Correction {
  sss::core::Pose T_corrected_dr;
  // Of the corrected pose in its [dt, dr] tangent: the covariance of the node nearest in time plus
  // the DR odometry model over the distance travelled between that node and the query time.
  sss::core::Matrix6d covariance = sss::core::Matrix6d::Identity();
  CorrectionStatus status = CorrectionStatus::kDrOnly;
  int64_t update_utime_us = 0;  // newest node of the update the correction comes from
  int accepted_closures = 0;
};

// Not thread-safe: one owner (the optimiser process loop) calls it. Copyable, so a caller can keep
// a snapshot; deterministic for the same input when max_solver_time_s is 0.
class SlidingWindowPoseGraph {
 public:
  // Options must validate (validatePoseGraphOptions); invalid options are a programming error
  // and throw std::invalid_argument.
  explicit SlidingWindowPoseGraph(const PoseGraphOptions& options);

  // A subframe centre: DR pose (local NED world, FRD body) and DR distance travelled since the
  // mission start. Nodes must come in time order with unique ids; O(1), no solve.
  Status addNode(int64_t subframe_id, int64_t utime_us, const sss::core::Pose& T_world_body_dr,
                 double distance_travelled_m);
  // The INS's own 1-sigma accuracy of its position, north and east, at the first node (what it
  // reports, e.g. a GNSS-aided start before the dive). The anchor that fixes the survey's position
  // widens to it (never below first_node_sigma_m), so absolute fixes may move the survey's start as
  // far as the INS was unsure of it instead of bending the track. Without fixes it changes only the
  // reported absolute covariances (the anchor is the one thing that places the survey). Refused
  // for a negative or non-finite sigma, and once the first node is marginalised (its anchor is
  // then part of the prior). May come before the first node.
  Status setFirstNodeHorizontalSigma(double north_m, double east_m);
  // What setFirstNodeHorizontalSigma set (zero: not set).
  const Eigen::Vector2d& firstNodeInsSigma() const { return first_node_ins_sigma_ne_m_; }
  // The anchor's 1-sigma north and east as held: first_node_sigma_m, or the INS's sigma where wider
  // and first_node_sigma_from_ins is on.
  Eigen::Vector2d firstNodeHorizontalSigma() const;
  // The odometry's drift fraction (per axis, of the distance between nodes) from now on, e.g. the
  // INS's reported drift (odometry_drift_from_ins). Every stored edge's odometry information is
  // rebuilt with it; a marginalisation prior already formed keeps what it was built with. Refused
  // unless finite and >= 0.
  Status setOdometryDriftFraction(double fraction);
  double odometryDriftFraction() const { return options_.odometry_drift_fraction; }
  // Queues a closure for the next optimize(); refused (with the reason) when an id is unknown, the
  // input is not finite, the covariance is not positive definite or it has too few inliers. A
  // closure to a marginalised node acts through that node held constant (see pose_graph.cpp); one
  // between two marginalised nodes only counts in fullSmoothing().
  Status addLoopClosure(const LoopClosure& closure);
  // Queues an absolute fix: it waits for a node at or after its time (full smoothing ties the rest
  // to the newest node), then the next update gates it. Refused when not finite or the covariance
  // is not positive definite.
  Status addFix(const AbsoluteFix& fix);

  // Decides pending closures, solves the window, marginalises nodes beyond window_size and
  // updates the covariances. Never throws on field data.
  UpdateReport optimize();
  // Re-optimises all nodes with all odometry and accepted closures (end of mission), then
  // re-derives the marginalisation prior at the smoothed estimate so the window can go on.
  UpdateReport fullSmoothing() { return smoothAll(true); }

  // ---- queries ------------------------------------------------------------------------------------
  std::optional<sss::core::Pose> estimate(int64_t subframe_id) const;
  // [dt, dr] covariance of the node: from the window's information matrix at the last update, or
  // for a marginalised node the one it had when it left the window.
  std::optional<sss::core::Matrix6d> covariance(int64_t subframe_id) const;
  std::vector<NodeState> nodes() const;
  std::optional<NodeState> newestNode() const;  // O(1)
  size_t numNodes() const { return nodes_.size(); }
  std::optional<int64_t> firstNodeUtime() const {  // O(1)
    return nodes_.empty() ? std::nullopt : std::optional<int64_t>(nodes_.front().utime_us);
  }
  std::vector<ClosureRecord> closures() const;  // in arrival order
  std::vector<FixRecord> fixes() const;         // in arrival order, with residuals at the estimate
  const FixCounters& fixCounters() const { return fix_counters_; }
  const PoseGraphCounters& counters() const { return counters_; }
  const WindowStats& windowStats() const { return window_stats_; }
  const VarianceFactors& varianceFactors() const { return variance_factors_; }
  const SeparationBias& separationBias() const { return separation_bias_; }
  const DrCalibration& calibration() const { return calibration_; }
  const PoseGraphOptions& options() const { return options_; }
  Correction correctionAt(int64_t utime_us) const;

  // ---- checkpoint ---------------------------------------------------------------------------------
  // Everything needed to resume (nodes, closures and their decisions, prior, counters), versioned
  // text with a checksum, written to a temporary file, fsync'ed and renamed into place. Options are
  // not stored: a restored graph runs with the options it was constructed with (the deployment's).
  Status saveCheckpoint(const std::string& path) const;
  // Replaces this graph's state; a missing, truncated or corrupt file leaves it unchanged.
  Status loadCheckpoint(const std::string& path);
  // The same without the file and its checksum line (embedded in the optimiser's checkpoint).
  std::string checkpointText() const;
  Status restoreCheckpointText(const std::string& text);

  // The odometry model (see PoseGraphOptions) for distance d.
  static sss::core::Matrix6d odometryCovariance(const PoseGraphOptions& options, double distance_m);
  // The same with other systematic drift fractions along track (forward: the DVL scale) and across
  // (starboard: the heading error), for the calibrated model.
  static sss::core::Matrix6d odometryCovariance(const PoseGraphOptions& options, double distance_m,
                                                double along_drift_fraction, double cross_drift_fraction);

 private:
  struct Node {
    int64_t id = 0;
    int64_t utime_us = 0;
    sss::core::Pose dr;
    double distance_m = 0.0;
    sss::core::Pose estimate;
    // Odometry from the previous node (identity for the first).
    sss::core::Pose odometry;
    sss::core::Matrix6d odometry_sqrt_information = sss::core::Matrix6d::Identity();
    // The DR path's heading moments since the previous node (CalibratedOdometryError), north/east.
    Eigen::Vector2d moment_cos = Eigen::Vector2d::Zero();
    Eigen::Vector2d moment_sin = Eigen::Vector2d::Zero();
    // Sum over the chain edges e < this node of Ad(dr_{e+1}) Sigma_e Ad(dr_{e+1})^T: the DR chain
    // covariance between any two nodes in O(1) (see chainCovariance()).
    sss::core::Matrix6d chain_prefix = sss::core::Matrix6d::Zero();
    bool has_covariance = false;
    sss::core::Matrix6d covariance = sss::core::Matrix6d::Zero();
    // Covariance given the rest of the window when it was marginalised (H_mm^-1): the uncertainty
    // of this node relative to the window it stayed tied to.
    sss::core::Matrix6d conditional_covariance = sss::core::Matrix6d::Zero();
    std::vector<int> closures;  // indices into closures_ of closures touching this node
    std::vector<int> fixes;     // indices into fixes_ of the fixes tied to this node
  };

  struct Fix {
    FixRecord record;
    int node = -1;                                      // index; -1 until tied
    Eigen::Vector3d p_body = Eigen::Vector3d::Zero();   // DR position at the fix time, node's DR frame
    Eigen::Matrix2d sqrt_information = Eigen::Matrix2d::Identity();  // fix (weighted) + DR between node and fix
    Eigen::Matrix2d gate_covariance = Eigen::Matrix2d::Identity();   // fix (its own sigma) + DR: the gate's
  };

  struct Closure {
    ClosureRecord record;
    int a = -1, b = -1;  // node indices
    bool gate_checked = false;
    sss::core::Matrix6d sqrt_information = sss::core::Matrix6d::Identity();  // of the closure alone
  };

  struct Prior {
    std::vector<int> nodes;
    std::vector<sss::core::Pose> linearisation;
    Eigen::MatrixXd jacobian;
    Eigen::VectorXd residual;
    bool empty() const { return nodes.empty(); }
  };

  enum class FactorKind { kFirstNode, kInsAbsolute, kOdometry, kClosure, kPrior, kFix };
  struct Factor {
    FactorKind kind;
    int index;  // node (first node, INS absolute; odometry: the newer node), closure or fix index
  };

  struct LinearisedFactor {
    std::vector<int> nodes;  // variable nodes only
    Eigen::MatrixXd jacobian;  // rows x 6 * nodes.size(), tangent space
    Eigen::VectorXd residual;
    double robust_weight = 1.0;  // sqrt(rho') of the robust loss: jacobian and residual are scaled by it
  };

  // Factors of the current window: nodes >= first_active_ are variables, older ones constants.
  std::vector<Factor> windowFactors() const;
  // Every odometry edge and accepted closure over all nodes (full smoothing).
  std::vector<Factor> allFactors() const;
  // The window factors that involve node m (the one being marginalised), the prior included.
  std::vector<Factor> factorsTouching(int m) const;
  std::vector<int> factorNodes(const Factor& factor) const;
  ceres::CostFunction* makeCost(const Factor& factor) const;
  ceres::LossFunction* makeLoss(const Factor& factor) const;
  sss::core::Matrix6d closureCovarianceInWindow(const Closure& closure) const;
  // The closure's own whitening with the current variance factor (no window inflation).
  sss::core::Matrix6d closureSqrtInformation(const Closure& closure) const;
  bool linearise(const Factor& factor, LinearisedFactor& out) const;

  void decideClosures(UpdateReport& report);
  // Ties waiting fixes to their node (all of them when final), then gates the tied, pending ones.
  void decideFixes(bool final);
  // Ties fix f to node n: its body-frame offset and whitening (also used by the checkpoint).
  bool tieFix(Fix& f, int n) const;
  // The information weight of a fix arriving after fixes_ (see gnss_fix_correlation_s): from the
  // nearest earlier fix of its source among them.
  double fixInformationWeight(const AbsoluteFix& fix) const;
  // North/east covariance of node n's position relative to node m that the DR calibration's
  // uncertainty leaves (its sigma once estimated, else the priors): the window holds the
  // calibration constant, so its covariance does not carry the systematic drift between them.
  Eigen::Matrix2d calibrationDriftCovariance(int m, int n) const;
  bool passesGate(const Closure& closure, const Eigen::MatrixXd& covariance, const std::vector<int>& slot) const;
  bool pairConsistent(const Closure& i, const Closure& j) const;
  sss::core::Matrix6d chainCovariance(int from, int to) const;
  // estimate_separation_bias: the separation bias is a variable of this solve (full smoothing).
  // estimate_calibration: the DR calibration is a variable too (full smoothing).
  bool solve(const std::vector<Factor>& factors, int max_iterations, UpdateReport& report,
             bool estimate_separation_bias = false, bool estimate_calibration = false);
  // Whether full smoothing estimates the calibration (PoseGraphOptions::calibration), and the DVL
  // scale with it.
  bool calibrationWanted() const;
  bool scaleWanted() const;
  // Whether a window update should be a full smoothing that re-estimates it (calibration_period_s).
  bool calibrationDue() const;
  // fullSmoothing(); mission_ended: fixes after the newest node are tied to it, as no later node
  // will come (a smoothing during the mission leaves them for the next node).
  UpdateReport smoothAll(bool mission_ended);
  // Whitening of node k's odometry edge: the configured model, or with the calibration in use
  // (calibrated_odometry_drift_fraction); divided by the odometry variance factor.
  sss::core::Matrix6d odometrySqrtInformation(int k, bool calibrated) const;
  // Node k's odometry edge under the calibration model, holding the last estimate. Its whitening:
  // with the calibration a variable of the same solve (estimated), only the drift the calibration
  // does not explain (calibrated_odometry_drift_fraction); with the calibration held constant, the
  // configured model: a held estimate corrects the edge's mean, but its own error is common to every
  // edge, and the window has no variable to carry it (the unobserved constant heading bias keeps
  // its prior sigma, wider than the drift model) -- tighter edges would gate out good fixes.
  CalibratedOdometryError calibratedOdometry(int k, bool estimated) const;
  // The first node's anchor: its DR pose, with the calibrated heading error removed when in use.
  sss::core::Pose firstNodePrior() const;
  // Unit direction (in A's body frame) along which the separation bias moves the closure's
  // measured B, or zero when the closure is not between opposite-side lines.
  Eigen::Vector3d separationDirection(const Closure& closure) const;
  // separation_bias_widen (or separation_bias_widen_with_fixes with accepted fixes and the DVL scale
  // estimated) in effect: the last estimate significant, a shortening and not applied.
  bool separationWidened() const;
  // Variance components of closures and odometry at the current estimate, solving again with the
  // new factors until they settle (full smoothing, every node active).
  void reweighFromResiduals(const std::vector<Factor>& factors, UpdateReport& report, bool estimate_calibration);
  // smoothed_gate_chi2 at full smoothing: rejects the worst closure beyond it and solves again
  // (factors follow), until every accepted closure holds. False when a solve failed.
  bool rejectClosuresTheSurveyDoesNotHold(std::vector<Factor>& factors, UpdateReport& report,
                                          bool estimate_calibration);
  // The leave-one-out chi-square of every closure among the factors (NaN for other factors and when
  // it cannot be computed), linearised at the current estimate with every node a variable: the
  // closure's innovation against the solution the other factors give, under the covariance of both.
  std::vector<double> closureLeaveOneOutChi2(const std::vector<Factor>& factors) const;
  void marginaliseOldest();
  // marginaliseOldest() until the window holds window_size nodes.
  void marginaliseBeyondWindow();
  // Joint covariance of the active nodes (6 x 6 blocks in node order); slot[n - first_active_] is
  // the block of node n.
  bool computeWindowCovariance(Eigen::MatrixXd& covariance, std::vector<int>& slot) const;
  void refreshCovariances();
  void refreshWindowStats(const std::vector<Factor>& factors);
  void setStatus(Closure& closure, ClosureStatus status, ClosureRejection rejection);
  void setupDerived(Node& node, const Node* previous) const;
  bool isActive(int node) const { return node >= first_active_; }
  bool useInsAbsolute() const;
  int64_t closureUtime(const Closure& closure) const;

  PoseGraphOptions options_;
  std::vector<Node> nodes_;
  std::unordered_map<int64_t, int> index_of_;
  std::vector<Closure> closures_;
  std::vector<Fix> fixes_;
  FixCounters fix_counters_;
  int64_t newest_accepted_fix_utime_us_ = -1;
  int64_t calibration_utime_us_ = -1;  // newest node of the last full smoothing that estimated the calibration
  Eigen::Vector2d first_node_ins_sigma_ne_m_ = Eigen::Vector2d::Zero();  // setFirstNodeHorizontalSigma
  std::map<std::pair<int64_t, int64_t>, int> latest_for_pair_;  // (smaller id, larger id) -> closure
  std::map<std::pair<int, int>, bool> pcm_cache_;               // pair consistency within the horizon
  int pcm_horizon_start_ = 0;  // closures before it are decided for good
  int first_active_ = 0;
  Prior prior_;
  PoseGraphCounters counters_;
  WindowStats window_stats_;
  VarianceFactors variance_factors_;
  SeparationBias separation_bias_;
  DrCalibration calibration_;
  int64_t update_utime_us_ = 0;
  // Newest node time of an accepted closure that left the PCM horizon (its decision is final).
  int64_t frozen_newest_accepted_utime_us_ = -1;
  int64_t newest_accepted_closure_utime_us_ = -1;
};

}  // namespace sss::optimiser
