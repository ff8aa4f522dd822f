#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include "mobility_analysis/Deploy.h"
#include "mobility_analysis/GetDof.h"
#include "mobility_analysis/GetRedundancy.h"
#include "mobility_analysis/LoadRobot.h"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/MobilityAnalysis.hpp"
#include "mobility_analysis/Move.h"

namespace mobility_analysis {

/**
 * @brief The `mobility_server` node: parameters, services, the joint-state loop, markers and tf of the served
 *        mechanism. It only translates between ROS and the core.
 *
 * Parameters: `robot_description` (node namespace, as robot_state_publisher reads it), `~mode`
 * ("auto" | "planar" | "spatial", default "auto"), `~rank_tolerance` (relative, in (0, 1); default: the
 * core's),
 * `~fixed_frame` (default "mobility_world", published as identity above the root link; "" disables),
 * `~publish_link_tf` (default true: every link's frame from the root on /tf_static; false when a
 * robot_state_publisher beside the node turns `joint_states` into tf: then only the links hung by a floating
 * joint, which it does not publish), `~load_timeout` (s, default 600: a longer ~load_robot is refused),
 * `~animate` (default false: sweep the first driveable joint back and forth while no input arrives),
 * `~publish_rate` (default 10 Hz: the current joint_states is repeated so robot_state_publisher keeps tf
 * fresh; 0 publishes only on change), `~forces_state` (int, read at every publication: which forces the
 * marker namespace `forces` shows, -1 the prestress, k >= 0 state of self-stress k; unset or -2: the
 * prestress when the structure is prestressable, else state 0; a change is drawn within 1 / publish_rate).
 *
 * Threads: services run on the spinner threads of the global queue; `input_joint_states` and the animation on
 * a queue of their own. Every answer is read from an immutable State behind a shared pointer, swapped under a
 * short lock, so `get_dof` answers from the model in force while `~load_robot` analyses a new one.
 */
class MobilityServer {
 public:
  /**
   * @brief Reads the parameters, analyses `robot_description`, advertises, subscribes and publishes.
   * @param[in] nodeHandle handle in the node's namespace (robot_description, joint_states).
   * @param[in] privateNodeHandle handle "~" (parameters, services, markers).
   * @note On an invalid parameter the constructor logs ROS_FATAL, requests shutdown and isConfigured() is
   * false.
   */
  MobilityServer(ros::NodeHandle& nodeHandle, ros::NodeHandle& privateNodeHandle);
  ~MobilityServer();

  /// @return False when a parameter was invalid and the node is shutting down.
  bool isConfigured() const { return configured_; }

 private:
  /// One state of the served model: the mechanism and its analysis there. Immutable once served.
  struct State {
    std::shared_ptr<const Mechanism> mechanism;
    std::string description;  ///< The URDF text it was read from.
    AnalysisMode mode = AnalysisMode::Auto;
    MobilityAnalysis analysis;
    uint64_t generation = 0;  ///< Which load it belongs to (states of an older load are dropped).
  };
  using StatePtr = std::shared_ptr<const State>;

  /// Reads the parameters once; false (after ROS_FATAL) on an invalid value.
  bool readParameters();
  /// The state in force (null when nothing is served).
  StatePtr current() const;
  /// Loads and analyses the URDF text within ~load_timeout; nothing is changed here.
  Result<std::shared_ptr<State>> loadDescription(const std::string& urdfText, const std::string& source,
                                                 AnalysisMode mode) const;
  /// Analysis options for this node (tolerance, progress logging, deadline).
  AnalysisOptions makeOptions(AnalysisMode mode, const JointPositions& positions, double timeout) const;
  /**
   * @brief The state reached from @p from when @p driven are held: continuation from the previous state on
   * its branch. A Diagnostic when a driven value is not reached.
   */
  Result<StatePtr> solve(const StatePtr& from, const JointPositions& driven) const;
  /// Makes @p state the one in force and publishes it, unless a newer load replaced its model meanwhile.
  bool commit(const StatePtr& state, const ros::Time& stamp);
  /// The served report, or the analysis at the requested positions; Diagnostic when none is served.
  template <class Request>
  Result<MobilityReport> reportFor(const Request& request) const;
  /// Publishes joint_states, markers and tf of @p state.
  void publish(const State& state, const ros::Time& stamp, bool newModel);

  bool getDof(GetDof::Request& request, GetDof::Response& response);
  bool getRedundancy(GetRedundancy::Request& request, GetRedundancy::Response& response);
  bool loadRobot(LoadRobot::Request& request, LoadRobot::Response& response);
  bool move(Move::Request& request, Move::Response& response);
  /**
   * @brief ~deploy: shortens an active cable (deployMechanism) from the state in force; each step is
   * committed as a display state (the start's report with the step's positions, poses and cables) and
   * published, the final state with its full analysis then stays in force.
   */
  bool deploy(Deploy::Request& request, Deploy::Response& response);
  /// `~forces_state` as it is now (cached parameter); kForcesAuto when unset or invalid.
  int forcesChoice() const;
  void onJointStates(const sensor_msgs::JointStateConstPtr& message);
  void animate();

  ros::NodeHandle& nodeHandle_;
  ros::NodeHandle& privateNodeHandle_;
  bool configured_ = false;
  AnalysisMode mode_ = AnalysisMode::Auto;
  double rankTolerance_ = -1.0;
  double loadTimeout_ = 600.0;
  double publishRate_ = 10.0;
  bool publishLinkTf_ = true;
  bool animate_ = false;
  std::string fixedFrame_ = "mobility_world";
  std::string closuresFile_;  ///< ~closures: a Pinocchio/Gepetto closure file for a tree-only URDF; empty: none.

  mutable std::mutex stateMutex_;  ///< Guards served_ and loadError_ (held only to copy or swap them).
  StatePtr served_;
  std::string loadError_;   ///< Why nothing is served (robot_description missing or bad).
  std::mutex loadMutex_;    ///< One ~load_robot at a time.
  std::mutex motionMutex_;  ///< One state change (joint states, ~move, animation, swap) at a time.
  std::mutex deployMutex_;  ///< One ~deploy at a time (another is refused, not queued).
  std::atomic<uint64_t> generation_{0};
  bool unreachableLogged_ = false;  ///< An unreachable input was logged in this episode (motionMutex_).
  std::atomic<double> lastInputTime_{0.0};

  ros::ServiceServer getDofServer_;
  ros::ServiceServer getRedundancyServer_;
  ros::ServiceServer loadRobotServer_;
  ros::ServiceServer moveServer_;
  ros::ServiceServer deployServer_;
  std::atomic<int> publishedForces_{-2};  ///< The forces choice of the last published markers.
  ros::Publisher markerPublisher_;
  ros::Publisher jointStatePublisher_;
  ros::Publisher tfStaticPublisher_;
  ros::Publisher descriptionPublisher_;
  ros::CallbackQueue motionQueue_;
  std::unique_ptr<ros::AsyncSpinner> motionSpinner_;
  ros::Subscriber jointStateSubscriber_;
  ros::WallTimer republishTimer_;
  std::atomic<bool> stopping_{false};
  std::thread animation_;
};

}  // namespace mobility_analysis
