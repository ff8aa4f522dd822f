#include "mobility_analysis/generators/MechanismDescription.hpp"

#include <cmath>
#include <utility>

namespace mobility_analysis {

const char* toString(ConnectionType type) {
  switch (type) {
    case ConnectionType::Revolute:
      return "revolute";
    case ConnectionType::Continuous:
      return "continuous";
    case ConnectionType::Prismatic:
      return "prismatic";
    case ConnectionType::Cylindrical:
      return "cylindrical";
    case ConnectionType::Spherical:
      return "spherical";
    case ConnectionType::Universal:
      return "universal";
    case ConnectionType::Fixed:
      return "fixed";
    case ConnectionType::Distance:
      return "distance";
  }
  return "unknown";
}

bool isTreeCapable(ConnectionType type) {
  return type == ConnectionType::Revolute || type == ConnectionType::Continuous ||
         type == ConnectionType::Prismatic || type == ConnectionType::Fixed;
}

std::optional<int> connectionFreedom(ConnectionType type, int lambda) {
  // Spatial freedoms: R 1, P 1, C 2, S 3, U 2, fixed 0, distance 5 (it removes one).
  // Planar (lambda 3) only knows pins, sliders and welds.
  switch (type) {
    case ConnectionType::Revolute:
    case ConnectionType::Continuous:
    case ConnectionType::Prismatic:
      return 1;
    case ConnectionType::Fixed:
      return 0;
    case ConnectionType::Cylindrical:
    case ConnectionType::Universal:
      return lambda == 6 ? std::optional<int>(2) : std::nullopt;
    case ConnectionType::Spherical:
      return lambda == 6 ? std::optional<int>(3) : std::nullopt;
    case ConnectionType::Distance:
      return lambda == 6 ? std::optional<int>(5) : std::optional<int>(2);
  }
  return std::nullopt;
}

Eigen::Isometry3d frameFromAxis(const Eigen::Vector3d& origin, const Eigen::Vector3d& axis) {
  const Eigen::Vector3d z = axis.normalized();
  // The world axis least aligned with z keeps x well conditioned; for z = world z this gives identity.
  Eigen::Index helperIndex = 0;
  z.cwiseAbs().minCoeff(&helperIndex);
  const Eigen::Vector3d helper = Eigen::Vector3d::Unit(helperIndex);
  const Eigen::Vector3d x = (helper - helper.dot(z) * z).normalized();
  Eigen::Matrix3d rotation;
  rotation.col(0) = x;
  rotation.col(1) = z.cross(x);
  rotation.col(2) = z;
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.linear() = rotation;
  frame.translation() = origin;
  return frame;
}

namespace {

Connection makeAxial(std::string name, ConnectionType type, std::string link1, std::string link2,
                     const Eigen::Vector3d& origin, const Eigen::Vector3d& axis) {
  Connection connection;
  connection.name = std::move(name);
  connection.type = type;
  connection.link1 = std::move(link1);
  connection.link2 = std::move(link2);
  connection.frame = frameFromAxis(origin, axis);
  connection.axis = axis.normalized();
  return connection;
}

}  // namespace

Connection makeRevolute(std::string name, std::string link1, std::string link2, const Eigen::Vector3d& origin,
                        const Eigen::Vector3d& axis) {
  return makeAxial(std::move(name), ConnectionType::Revolute, std::move(link1), std::move(link2), origin,
                   axis);
}

Connection makePrismatic(std::string name, std::string link1, std::string link2,
                         const Eigen::Vector3d& origin, const Eigen::Vector3d& axis) {
  return makeAxial(std::move(name), ConnectionType::Prismatic, std::move(link1), std::move(link2), origin,
                   axis);
}

Connection makeCylindrical(std::string name, std::string link1, std::string link2,
                           const Eigen::Vector3d& origin, const Eigen::Vector3d& axis) {
  return makeAxial(std::move(name), ConnectionType::Cylindrical, std::move(link1), std::move(link2), origin,
                   axis);
}

Connection makeSpherical(std::string name, std::string link1, std::string link2,
                         const Eigen::Vector3d& origin) {
  return makeAxial(std::move(name), ConnectionType::Spherical, std::move(link1), std::move(link2), origin,
                   Eigen::Vector3d::UnitZ());
}

Connection makeUniversal(std::string name, std::string link1, std::string link2,
                         const Eigen::Vector3d& origin, const Eigen::Vector3d& axis1,
                         const Eigen::Vector3d& axis2) {
  Connection connection = makeAxial(std::move(name), ConnectionType::Universal, std::move(link1),
                                    std::move(link2), origin, axis1);
  connection.axis2 = axis2.normalized();
  return connection;
}

Connection makeFixed(std::string name, std::string link1, std::string link2, const Eigen::Isometry3d& frame) {
  Connection connection;
  connection.name = std::move(name);
  connection.type = ConnectionType::Fixed;
  connection.link1 = std::move(link1);
  connection.link2 = std::move(link2);
  connection.frame = frame;
  connection.axis = frame.linear().col(2);
  return connection;
}

Connection makeDistance(std::string name, std::string link1, const Eigen::Vector3d& p1, std::string link2,
                        const Eigen::Vector3d& p2) {
  Connection connection;
  connection.name = std::move(name);
  connection.type = ConnectionType::Distance;
  connection.link1 = std::move(link1);
  connection.link2 = std::move(link2);
  connection.frame = Eigen::Isometry3d::Identity();
  connection.frame.translation() = p1;
  connection.point2 = p2;
  return connection;
}

std::optional<int> computeGrublerCount(const MechanismDescription& mechanism, int lambda) {
  const int numLinks = static_cast<int>(mechanism.links.size());
  const int numJoints = static_cast<int>(mechanism.connections.size());
  int freedom = 0;
  for (const Connection& connection : mechanism.connections) {
    const std::optional<int> f = connectionFreedom(connection.type, lambda);
    if (!f) {
      return std::nullopt;
    }
    freedom += *f;
  }
  return lambda * (numLinks - numJoints - 1) + freedom;
}

void scaleMechanism(MechanismDescription& mechanism, double factor) {
  for (LinkDescription& link : mechanism.links) {
    for (Eigen::Vector3d& point : link.visualPath) {
      point *= factor;
    }
    if (link.floatingFrame) {
      link.floatingFrame->translation() *= factor;
    }
  }
  for (Connection& connection : mechanism.connections) {
    connection.frame.translation() *= factor;
    connection.point2 *= factor;
  }
  for (CableDescription& cable : mechanism.cables) {
    cable.point1 *= factor;
    cable.point2 *= factor;
    cable.length *= factor;
  }
  mechanism.visualRadius *= factor;
}

}  // namespace mobility_analysis
