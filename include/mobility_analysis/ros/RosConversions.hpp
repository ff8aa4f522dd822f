#pragma once

#include <string>
#include <vector>

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/TransformStamped.h>
#include <ros/time.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/ColorRGBA.h>
#include <visualization_msgs/MarkerArray.h>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/GetDof.h"
#include "mobility_analysis/GetRedundancy.h"
#include "mobility_analysis/Kinematics.hpp"
#include "mobility_analysis/LoadRobot.h"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/MobilityReport.hpp"

/**
 * Core <-> ROS message conversions: the only code of the package that touches message fields.
 * Free functions named toX / fromX (STYLE.md §3); none of them analyses anything.
 */
namespace mobility_analysis {

/// Marker namespaces (DESIGN.md §4); `title` holds the one "DOF d (Grübler g), r redundant" label.
constexpr const char* kLinksNamespace = "links";
constexpr const char* kJointsNamespace = "joints";
constexpr const char* kLabelsNamespace = "labels";
constexpr const char* kTitleNamespace = "title";

/**
 * @brief The colour of an element class: Redundant red (1, 0, 0), OverConstrainedLoop orange (1, 0.5, 0),
 *        Neutral grey for links and blue for joints. Alpha is always 1.
 * @param[in] elementClass the class decided by the core.
 * @param[in] isLink whether the element is a link (neutral grey) or a connection (neutral blue).
 */
std_msgs::ColorRGBA toColor(ElementClass elementClass, bool isLink);

/// @return The JSON spelling of @p elementClass parsed back; Neutral for anything unknown.
ElementClass fromClassName(const std::string& name);

/// @return @p pose as a message (quaternion normalised).
geometry_msgs::Pose toPose(const Eigen::Isometry3d& pose);

/// @return The rigid transform of @p transform (rotation re-normalised).
Eigen::Isometry3d fromTransform(const geometry_msgs::Transform& transform);

/**
 * @brief Fills the report fields of a GetDof response (success = true, message empty).
 * @param[in] report the core's report.
 * @param[out] response the response; every report field is overwritten.
 */
void toResponse(const MobilityReport& report, GetDof::Response& response);

/// @brief Fills every report field of a GetRedundancy response (success = true, message empty).
void toResponse(const MobilityReport& report, GetRedundancy::Response& response);

/// @brief Fills every report field of a LoadRobot response (success = true, message empty): the full report.
void toResponse(const MobilityReport& report, LoadRobot::Response& response);

/**
 * @brief Fills @p response with a failure: success = false, message = diagnostic.toString().
 * @note Template over the three response types: each has `success` and `message`.
 */
template <class Response>
void toFailure(const Diagnostic& diagnostic, Response& response) {
  response.success = false;
  response.message = diagnostic.toString();
}

/**
 * @brief The report carried by a GetRedundancy response, inverse of toResponse: toJson(fromResponse(r))
 * equals the CLI's `--json` output for the same model (the file field is whatever the server was given).
 */
MobilityReport fromResponse(const GetRedundancy::Response& response);
/// @copydoc fromResponse(const GetRedundancy::Response&)
MobilityReport fromResponse(const LoadRobot::Response& response);
/// @return The report fields a GetDof response carries (the redundancy lists, classes and cables stay empty).
MobilityReport fromResponse(const GetDof::Response& response);

/**
 * @brief The `joint_states` message of a state: every 1-DOF tree joint of the report's `positions`, in
 * document order, as robot_state_publisher wants them.
 * @param[in] report the report of the state.
 * @param[in] stamp the stamp of the input the state answers (or now).
 */
sensor_msgs::JointState toJointState(const MobilityReport& report, const ros::Time& stamp);

/**
 * @brief The joint positions of a service request, checked against @p mechanism (sizes, names, finiteness).
 * @return The positions (empty for an empty request), or the core's Diagnostic.
 */
Result<JointPositions> fromRequest(const GetDof::Request& request, const Mechanism& mechanism);
/// @copydoc fromRequest(const GetDof::Request&, const Mechanism&)
Result<JointPositions> fromRequest(const GetRedundancy::Request& request, const Mechanism& mechanism);

/**
 * @brief The markers of one analysed mechanism, in the root link's frame.
 *
 * First a DELETEALL marker, then per link (ns `links`, id = link index) a LINE_LIST through its joint points
 * (a SPHERE when it has fewer than two distinct points), per connection (ns `joints`, id = joint index) a
 * CYLINDER along a revolute/continuous/cylindrical axis, an ARROW along a prismatic axis, a SPHERE for a
 * spherical or floating joint, a CUBE for universal/fixed/planar joints and a LINE_LIST for distance
 * constraints and cables (a link with more than six distinct joint points is a star from its centroid; the
 * whole array is built in O(J log J)); per element a TEXT_VIEW_FACING label (ns `labels`, id = link index,
 * then number of links + joint index) with text = name and colour = the element's colour; and one title label
 * (ns `title`). Sizes scale with the report's characteristic length; no scale is zero, every quaternion is
 * normalised.
 * @param[in] mechanism the mechanism.
 * @param[in] poses link poses in the root frame (dim mechanism.links.size()).
 * @param[in] report the report whose links/joints classes decide the colours (same indexing as mechanism).
 * @param[in] stamp header stamp (ros::Time(0): the latest transform).
 */
visualization_msgs::MarkerArray toMarkerArray(const Mechanism& mechanism, const LinkPoses& poses,
                                              const MobilityReport& report,
                                              const ros::Time& stamp = ros::Time(0));

/// Which link frames the node broadcasts itself.
enum class LinkFrames {
  All,          ///< Every non-root link from the root (no robot_state_publisher beside the node).
  FloatingHung  ///< Only links hung from their tree parent by a floating joint, from that parent: the ones
                ///< robot_state_publisher does not publish (it publishes the others from joint_states).
};

/**
 * @brief The link transforms of a state (tf frame ids are the URDF link names), plus `fixedFrame` -> root as
 *        identity when @p fixedFrame is non-empty and not a link name.
 * @param[in] mechanism the mechanism (names, root).
 * @param[in] poses link poses in the root frame.
 * @param[in] fixedFrame a frame rviz can always use as Fixed Frame ("mobility_world"), or empty.
 * @param[in] stamp header stamp.
 * @param[in] frames All: root -> every non-root link; FloatingHung: tree parent -> child of every floating
 * tree joint.
 */
std::vector<geometry_msgs::TransformStamped> toTransforms(const Mechanism& mechanism, const LinkPoses& poses,
                                                          const std::string& fixedFrame,
                                                          const ros::Time& stamp,
                                                          LinkFrames frames = LinkFrames::All);

}  // namespace mobility_analysis
