#pragma once

#include <Eigen/Geometry>

#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace mobility_analysis {

/**
 * @brief Kind of connection a generator places between two links (DESIGN.md §2 joint types).
 *
 * Revolute, Continuous, Prismatic and Fixed can become URDF tree `<joint>`s; every other kind is
 * always written as a `<loop_joint>` (or `<distance_constraint>` for Distance).
 */
enum class ConnectionType {
  Revolute,
  Continuous,
  Prismatic,
  Cylindrical,
  Spherical,
  Universal,
  Fixed,
  Distance
};

/// @return The dialect's type name ("revolute", …, "distance").
const char* toString(ConnectionType type);

/// @return True for the types a URDF `<joint>` can express (revolute, continuous, prismatic, fixed).
bool isTreeCapable(ConnectionType type);

/**
 * @brief Freedom F of a connection for the Grübler–Kutzbach count.
 * @param[in] type Connection type.
 * @param[in] lambda 6 (spatial) or 3 (planar).
 * @return F, or nothing when the type has no planar counterpart (spherical, universal, … with lambda 3).
 */
std::optional<int> connectionFreedom(ConnectionType type, int lambda);

/**
 * @brief One connection between two links, described at one configuration in WORLD terms.
 *
 * Both sides share the same world frame, so the written URDF closes exactly at this pose:
 * the writer expresses `frame` once in link1's frame and once in link2's frame.
 */
struct Connection {
  std::string name;  ///< Unique among connections.
  ConnectionType type = ConnectionType::Revolute;
  std::string link1;  ///< First link (URDF link1 / the guide of a slider).
  std::string link2;  ///< Second link.
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();  ///< Joint frame in world [m].
  Eigen::Vector3d axis =
      Eigen::Vector3d::UnitZ();  ///< Motion axis (first universal axis, on link1), world unit vector.
  Eigen::Vector3d axis2 =
      Eigen::Vector3d::UnitX();  ///< Universal only: second axis (on link2), world unit vector.
  Eigen::Vector3d point2 =
      Eigen::Vector3d::Zero();  ///< Distance only: end on link2 (end on link1 is frame origin) [m].
};

/// A rigid link of the description: a name and what to draw.
struct LinkDescription {
  std::string name;  ///< Unique among links; the first link is the ground.
  std::vector<Eigen::Vector3d>
      visualPath;  ///< World points [m] joined by cylinders; empty: star over its joint points.
  std::optional<Eigen::Isometry3d>
      floatingFrame;  ///< World frame used if the link hangs by a `floating` joint.
};

/**
 * @brief What the analysis should find for a model, in one mode.
 *
 * grubler = lambda (N − J − 1) + Σ F (N links incl. ground, J joints, floating joints excluded);
 * redundant = dof − grubler (DESIGN.md §3).
 */
struct FamilyExpectation {
  std::string mode;   ///< "planar" or "spatial".
  int lambda = 6;     ///< 3 (planar) or 6 (spatial).
  int dof = 0;        ///< True degrees of freedom (nullity of the constraint Jacobian).
  int grubler = 0;    ///< Grübler–Kutzbach count for this lambda.
  int redundant = 0;  ///< Number of redundant equations = dof − grubler.
};

/// A cable between two world points on two links (DESIGN.md §2): never a tree joint, never in Grübler.
struct CableDescription {
  std::string name;
  std::string link1;
  Eigen::Vector3d point1 = Eigen::Vector3d::Zero();  ///< World end on link1 [m].
  std::string link2;
  Eigen::Vector3d point2 = Eigen::Vector3d::Zero();  ///< World end on link2 [m].
  double length = 0.0;                               ///< Declared length [m].
  bool active = false;                               ///< Active (the driver) or passive.
};

/// A mechanism at one configuration: links, connections and what the analysis should report.
struct MechanismDescription {
  std::string name;                             ///< URDF robot name.
  std::string comment;                          ///< Where the numbers come from; written as an XML comment.
  std::vector<LinkDescription> links;           ///< links.front() is the ground (URDF root).
  std::vector<Connection> connections;          ///< In document order; the order decides the spanning tree.
  std::vector<FamilyExpectation> expectations;  ///< One per mode the model is meant to be analysed in.
  std::vector<CableDescription> cables;         ///< Written after the loop joints as `<cable>` elements.
  double visualRadius = 0.01;                   ///< Radius of the drawn cylinders [m].
  bool treeJointsLeafFirst = false;  ///< Write the tree `<joint>`s children first (a leaf-first file).
};

/// Why a description or a command line could not be turned into a URDF.
struct GeneratorError {
  std::string what;  ///< One line, naming the element or argument.
};

/// Either a value or the GeneratorError that explains why there is none.
template <class T>
using GeneratorResult = std::variant<T, GeneratorError>;

/**
 * @brief A right-handed frame whose z axis is @p axis.
 * @param[in] origin World origin [m].
 * @param[in] axis Direction of z (need not be unit, must be non-zero).
 * @return The frame; x is the unit vector of the world axis least aligned with @p axis, made orthogonal,
 *         so a joint about world z gets the identity rotation.
 */
Eigen::Isometry3d frameFromAxis(const Eigen::Vector3d& origin, const Eigen::Vector3d& axis);

/// @return A revolute connection at @p origin about world @p axis.
Connection makeRevolute(std::string name, std::string link1, std::string link2, const Eigen::Vector3d& origin,
                        const Eigen::Vector3d& axis);

/// @return A prismatic connection: link2 slides on link1 along world @p axis through @p origin.
Connection makePrismatic(std::string name, std::string link1, std::string link2,
                         const Eigen::Vector3d& origin, const Eigen::Vector3d& axis);

/// @return A spherical connection centred at @p origin.
Connection makeSpherical(std::string name, std::string link1, std::string link2,
                         const Eigen::Vector3d& origin);

/// @return A cylindrical connection along world @p axis through @p origin.
Connection makeCylindrical(std::string name, std::string link1, std::string link2,
                           const Eigen::Vector3d& origin, const Eigen::Vector3d& axis);

/// @return A universal connection at @p origin, @p axis1 fixed on link1, @p axis2 fixed on link2 (world).
Connection makeUniversal(std::string name, std::string link1, std::string link2,
                         const Eigen::Vector3d& origin, const Eigen::Vector3d& axis1,
                         const Eigen::Vector3d& axis2);

/// @return A fixed connection whose frame is @p frame (world).
Connection makeFixed(std::string name, std::string link1, std::string link2, const Eigen::Isometry3d& frame);

/// @return A distance constraint between world point @p p1 on link1 and @p p2 on link2.
Connection makeDistance(std::string name, std::string link1, const Eigen::Vector3d& p1, std::string link2,
                        const Eigen::Vector3d& p2);

/**
 * @brief Grübler–Kutzbach count λ(N − J − 1) + Σ F of a description.
 * @param[in] mechanism The description (floating joints are not connections, so they do not enter).
 * @param[in] lambda 6 or 3.
 * @return The count, or nothing if a connection has no freedom for this lambda.
 */
std::optional<int> computeGrublerCount(const MechanismDescription& mechanism, int lambda);

/**
 * @brief Multiplies every length of @p mechanism by @p factor (a unit change: mm = 1000).
 * @param[in,out] mechanism Description to scale in place.
 * @param[in] factor Positive factor.
 */
void scaleMechanism(MechanismDescription& mechanism, double factor);

}  // namespace mobility_analysis
