#pragma once

#include <string>
#include <vector>

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/TransformStamped.h>
#include <ros/time.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/ColorRGBA.h>
#include <visualization_msgs/MarkerArray.h>

#include "mobility_analysis/Deploy.h"
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
/// The forces of a state of self-stress or of the prestress (toForceMarkers).
constexpr const char* kForcesNamespace = "forces";

/// `~forces_state` beside a state index k >= 0: the prestress found, or automatic (the prestress when the
/// structure is prestressable, else state 0).
constexpr int kForcesPrestress = -1;
constexpr int kForcesAuto = -2;

/**
 * @brief The colour of an element class: Redundant red (1, 0, 0), OverConstrainedLoop orange (1, 0.5, 0),
 *        Neutral grey for links and blue for joints. Alpha is always 1.
 * @param[in] elementClass the class decided by the core.
 * @param[in] isLink whether the element is a link (neutral grey) or a connection (neutral blue).
 */
std_msgs::ColorRGBA toColor(ElementClass elementClass, bool isLink);

/**
 * @brief How a cable is drawn in ns `joints`: a solid line in the colour of its class when it is taut (or an
 *        active cable locked), a dashed grey (0.55, 0.55, 0.55) line when it is slack, and a solid magenta
 *        (0.85, 0.2, 0.85) line while it is the driving active cable.
 * @param[in] state the report's cable state: "taut", "locked", "slack" or "driving".
 * @param[in] elementClass the class of the cable (for taut and locked cables).
 * @param[out] dashed whether the line is drawn dashed.
 */
std_msgs::ColorRGBA toCableColor(const std::string& state, ElementClass elementClass, bool& dashed);

/**
 * @brief The colour of one element's force in ns `forces` (@p force relative to the largest, in [-1, 1]).
 *
 * Signed elements (cables, distance constraints; tension positive): tension blue, from (0.6, 0.65, 0.8) at 0
 * to (0.1, 0.35, 1) at 1; compression red, from (0.8, 0.6, 0.6) to (1, 0.1, 0.05) at -1. Links, joints and
 * boundaries carry the norm of their equations' multipliers, which has no sign: green, from (0.6, 0.8, 0.6)
 * to (0.1, 0.8, 0.2) at 1. The colour goes from the first to the second with sqrt(|force|), so a tenth of the
 * largest force is a third of the way; alpha is 1.
 * @param[in] force relative force (clamped to [-1, 1]).
 * @param[in] isSigned true for cables and distance constraints.
 */
std_msgs::ColorRGBA toForceColor(double force, bool isSigned);

/// One set of element forces chosen for display: what it is and the forces (empty when none).
struct ForcesSelection {
  std::string title;                 ///< "prestress", "state of self-stress 2 of 4", or why there is none.
  std::vector<ElementForce> forces;  ///< The elements with their relative forces.
};

/**
 * @brief The forces @p choice asks for: kForcesPrestress the prestress found, k >= 0 state k, kForcesAuto the
 *        prestress when @p info is prestressable, else state 0.
 * @return The selection; its forces are empty (and its title says why) when the choice does not exist.
 */
ForcesSelection selectForces(const SelfStressInfo& info, int choice);

/**
 * @brief Markers of ns `forces`: every element that carries the chosen forces (selectForces) drawn over its
 *        ordinary marker, coloured by toForceColor and as wide as 1 + 2 sqrt|force| link widths
 *        (links, boundaries: their lines, or a sphere for a one-point link; joints: a sphere at the joint;
 *        cables and distance constraints: their line), plus a legend (id 0, TEXT_VIEW_FACING) below the
 * model. Ids: 0 legend, 1 + link index, 1 + links + connection index, 1 + links + connections + link index
 *        for a boundary. Elements the mechanism does not name are skipped.
 * @param[in] mechanism the mechanism (names as in the report).
 * @param[in] poses link poses in the root frame.
 * @param[in] report the report whose self_stress is drawn.
 * @param[in] choice see selectForces.
 * @param[in] stamp header stamp.
 */
std::vector<visualization_msgs::Marker> toForceMarkers(const Mechanism& mechanism, const LinkPoses& poses,
                                                       const MobilityReport& report, int choice,
                                                       const ros::Time& stamp = ros::Time(0));

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
 * @brief Fills a Deploy response from a deployment's final report (success = true, message empty): the
 *        report's `deployment` (a report without one leaves the deployment fields empty), its cables and
 *        self_stress.
 */
void toResponse(const MobilityReport& report, Deploy::Response& response);

/// @return The deployment a Deploy response carries (inverse of toResponse: the steps keep length and DOF).
DeploymentInfo fromResponse(const Deploy::Response& response);

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
 * (ns `title`). A cable is drawn as its state in the report says (toCableColor: taut solid, slack dashed
 * grey, driving magenta); one the report does not list is taut when its ends are its length apart. Then the
 * markers of ns `forces` (toForceMarkers with @p forcesChoice). Sizes scale with the report's characteristic
 * length; no scale is zero, every quaternion is normalised.
 * @param[in] mechanism the mechanism.
 * @param[in] poses link poses in the root frame (dim mechanism.links.size()).
 * @param[in] report the report whose links/joints classes decide the colours (same indexing as mechanism).
 * @param[in] stamp header stamp (ros::Time(0): the latest transform).
 * @param[in] forcesChoice which forces ns `forces` shows (see selectForces).
 */
visualization_msgs::MarkerArray toMarkerArray(const Mechanism& mechanism, const LinkPoses& poses,
                                              const MobilityReport& report,
                                              const ros::Time& stamp = ros::Time(0),
                                              int forcesChoice = kForcesAuto);

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
