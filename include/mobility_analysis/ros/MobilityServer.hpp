#pragma once

#include <memory>
#include <optional>
#include <string>

#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "mobility_analysis/GetDof.h"
#include "mobility_analysis/GetRedundancy.h"
#include "mobility_analysis/LoadRobot.h"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/MobilityAnalysis.hpp"

namespace mobility_analysis {

/**
 * @brief The `mobility_server` node: parameters, three services, the latched marker publisher, the static tf
 *        broadcaster and the currently served analysis. It only translates between ROS and the core.
 *
 * Parameters: `robot_description` (node namespace, as robot_state_publisher reads it), `~mode`
 * ("auto" | "planar" | "spatial", default "auto"), `~rank_tolerance` (relative, in (0, 1); default: the core's),
 * `~fixed_frame` (default "mobility_world", published as identity above the root link; "" disables).
 */
class MobilityServer {
 public:
  /**
   * @brief Reads the parameters, analyses `robot_description`, advertises and publishes.
   * @param[in] nodeHandle handle in the node's namespace (robot_description).
   * @param[in] privateNodeHandle handle "~" (parameters, services, markers).
   * @note On an invalid parameter the constructor logs ROS_FATAL, requests shutdown and isConfigured() is false.
   */
  MobilityServer(ros::NodeHandle& nodeHandle, ros::NodeHandle& privateNodeHandle);

  /// @return False when a parameter was invalid and the node is shutting down.
  bool isConfigured() const { return configured_; }

 private:
  /// The model being served: the mechanism and its analysis at the loaded pose.
  struct ServedModel {
    Mechanism mechanism;
    MobilityAnalysis analysis;
  };

  /// Reads ~mode, ~rank_tolerance, ~fixed_frame once; false (after ROS_FATAL) on an invalid value.
  bool readParameters();
  /// Loads and analyses the URDF text; nothing is changed here.
  Result<ServedModel> analyseDescription(const std::string& urdfText, const std::string& source,
                                         AnalysisMode mode) const;
  /// Analysis options for this node (tolerance, progress logging).
  AnalysisOptions makeOptions(AnalysisMode mode, const JointPositions& positions) const;
  /// The served report, or the analysis at the requested positions; Diagnostic when none is served.
  template <class Request>
  Result<MobilityReport> reportFor(const Request& request) const;
  /// Publishes the markers (DELETEALL first) and the tf frames of the served model.
  void publish();

  bool getDof(GetDof::Request& request, GetDof::Response& response);
  bool getRedundancy(GetRedundancy::Request& request, GetRedundancy::Response& response);
  bool loadRobot(LoadRobot::Request& request, LoadRobot::Response& response);

  ros::NodeHandle& nodeHandle_;
  ros::NodeHandle& privateNodeHandle_;
  bool configured_ = false;
  AnalysisMode mode_ = AnalysisMode::Auto;
  double rankTolerance_ = -1.0;
  std::string fixedFrame_ = "mobility_world";
  std::optional<ServedModel> served_;
  std::string loadError_;  ///< Why nothing is served (robot_description missing or bad).
  ros::ServiceServer getDofServer_;
  ros::ServiceServer getRedundancyServer_;
  ros::ServiceServer loadRobotServer_;
  ros::Publisher markerPublisher_;
  std::unique_ptr<tf2_ros::StaticTransformBroadcaster> tfBroadcaster_;
};

}  // namespace mobility_analysis
