// A simulated survey cut into subframes in process (sonar rendered, DR nav, the real subframe
// buffer), and the exact ground truth of its pixels: where a pixel lies on the true seabed and
// which pixel of another subframe sees that point. Matcher and optimiser tests and benchmarks.
#pragma once

#include <Eigen/Core>

#include <memory>
#include <optional>
#include <vector>

#include "pipeline/subframe/subframe_buffer.hpp"
#include "tools/sim/ground_truth_geometry.hpp"
#include "tools/sim/mission.hpp"

namespace sss::sim {

struct SimulatedSurvey {
  std::unique_ptr<Mission> mission;
  // Subframes of the DR navigation (what the live chain produces); ping_number = mission ping.
  std::vector<sss::core::Subframe> subframes;
};

// Renders every ping (OpenMP) and runs them with the DR nav through a SubframeBuffer, as the
// live chain does. The buffer's sonar geometry must match the simulator's (the defaults do).
SimulatedSurvey simulateSurvey(const SimOptions& options, const sss::subframe::SubframeBufferOptions& buffer = {});

// B's DR poses moved rigidly in the world by along_m along A's centre heading and lateral_m to
// A's starboard: a known DR error between two lines for tests and benchmarks.
std::vector<sss::core::Pose> posesWithDrError(const sss::core::Subframe& a, const sss::core::Subframe& b,
                                              double along_m, double lateral_m);

// The INS/DVL input the subframe buffer takes, from a pose and an altitude.
sss::subframe::NavInput navInputFrom(int64_t utime_us, const sss::core::Pose& T_world_body, double altitude_m);

// True T_world_body of every ping (row) of a subframe.
std::vector<sss::core::Pose> truePoses(const Mission& mission, const sss::core::Subframe& subframe);

// Ground truth of subframe pixels.
class SubframeTruth {
 public:
  explicit SubframeTruth(const Mission& mission);

  // The true seabed point seen by pixel (row, column) of the subframe: the ray-cast seabed at the
  // slant range the canonical transform gave that column (ground range and the ping's altitude).
  std::optional<Eigen::Vector3d> seabedPoint(const sss::core::Subframe& subframe, int row, double column) const;

  // The (fractional) row and column of the subframe whose fan plane and slant range contain the
  // point; nullopt when no ping of the subframe passes it within range.
  std::optional<Eigen::Vector2d> pixelOf(const sss::core::Subframe& subframe, const Eigen::Vector3d& point) const;
  // The same with the subframe's true sonar poses given (sonarPoses), for many points of one subframe.
  std::optional<Eigen::Vector2d> pixelOf(const sss::core::Subframe& subframe, const Eigen::Vector3d& point,
                                         const std::vector<sss::core::Pose>& sonar_poses) const;
  // True T_world_sonar of every row of the subframe.
  std::vector<sss::core::Pose> sonarPoses(const sss::core::Subframe& subframe) const;

  // True relative pose of the centre pings: B's centre body frame in A's.
  sss::core::Pose trueRelativePose(const sss::core::Subframe& a, const sss::core::Subframe& b) const;

 private:
  const Mission& mission_;
  GroundTruthGeometry geometry_;
};

}  // namespace sss::sim
