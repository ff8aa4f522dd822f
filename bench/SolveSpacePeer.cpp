#include "SolveSpacePeer.hpp"

#include <chrono>
#include <cmath>
#include <vector>

#include <slvs.h>

namespace mobility_analysis::bench {

namespace {

constexpr Slvs_hGroup kFixed = 1;   ///< Workplane and ground points: not solved.
constexpr Slvs_hGroup kSolved = 2;  ///< Every other point and every constraint.

/// The sketch being built: SolveSpace's three arrays and the next free handles.
struct Sketch {
  std::vector<Slvs_Param> params;
  std::vector<Slvs_Entity> entities;
  std::vector<Slvs_Constraint> constraints;
  Slvs_hEntity workplane = 0;

  Slvs_hEntity addPoint(Slvs_hGroup group, const Eigen::Vector3d& p) {
    const auto u = static_cast<Slvs_hParam>(params.size() + 1);
    params.push_back(Slvs_MakeParam(u, group, p.x()));
    params.push_back(Slvs_MakeParam(u + 1, group, p.y()));
    const auto h = static_cast<Slvs_hEntity>(entities.size() + 1);
    entities.push_back(Slvs_MakePoint2d(h, group, workplane, u, u + 1));
    return h;
  }
  void addConstraint(int type, double value, Slvs_hEntity a, Slvs_hEntity b) {
    const auto h = static_cast<Slvs_hConstraint>(constraints.size() + 1);
    constraints.push_back(Slvs_MakeConstraint(h, kSolved, type, workplane, value, a, b, 0, 0));
  }
};

}  // namespace

SolveSpaceResult solveWithSolveSpace(const Mechanism& mechanism, const LinkPoses& poses, bool findFailed) {
  SolveSpaceResult result;
  Sketch sketch;
  const size_t numLinks = mechanism.links.size();
  sketch.params.reserve(8 * numLinks + 8);
  sketch.entities.reserve(4 * numLinks + 4);
  sketch.constraints.reserve(3 * mechanism.joints.size() + numLinks);
  // The x-y workplane: origin and normal in the fixed group.
  sketch.params.push_back(Slvs_MakeParam(1, kFixed, 0.0));
  sketch.params.push_back(Slvs_MakeParam(2, kFixed, 0.0));
  sketch.params.push_back(Slvs_MakeParam(3, kFixed, 0.0));
  sketch.entities.push_back(Slvs_MakePoint3d(1, kFixed, 1, 2, 3));
  sketch.params.push_back(Slvs_MakeParam(4, kFixed, 1.0));
  sketch.params.push_back(Slvs_MakeParam(5, kFixed, 0.0));
  sketch.params.push_back(Slvs_MakeParam(6, kFixed, 0.0));
  sketch.params.push_back(Slvs_MakeParam(7, kFixed, 0.0));
  sketch.entities.push_back(Slvs_MakeNormal3d(2, kFixed, 4, 5, 6, 7));
  sketch.entities.push_back(Slvs_MakeWorkplane(3, kFixed, 1, 2));
  sketch.workplane = 3;

  // Joint points per link (at most two distinct ones for a bar).
  struct LinkPoint {
    Eigen::Vector3d world;
    Slvs_hEntity entity;
  };
  std::vector<std::vector<LinkPoint>> points(numLinks);
  auto pointOn = [&](int link, const Eigen::Vector3d& world) -> Slvs_hEntity {
    for (const LinkPoint& p : points[link]) {
      if ((p.world - world).norm() < 1e-9) {
        return p.entity;
      }
    }
    const Slvs_hEntity h = sketch.addPoint(link == mechanism.rootLink ? kFixed : kSolved, world);
    points[link].push_back(LinkPoint{world, h});
    return h;
  };
  std::vector<std::pair<Slvs_hEntity, Slvs_hEntity>> pins;
  pins.reserve(mechanism.joints.size());
  for (const Joint& joint : mechanism.joints) {
    if (joint.kind == ConnectionKind::TreeJoint && joint.type == JointType::Floating) {
      continue;
    }
    const bool revolute = joint.type == JointType::Revolute || joint.type == JointType::Continuous;
    if (!revolute || (joint.kind != ConnectionKind::TreeJoint && joint.kind != ConnectionKind::LoopJoint)) {
      result.status = std::string("unsupported: ") + toString(joint.kind) + " '" + joint.name + "' of type " +
                      toString(joint.type);
      return result;
    }
    const Eigen::Isometry3d world1 = poses[joint.link1] * joint.frame1;
    const Eigen::Vector3d axis = world1.linear() * joint.axis;
    if (std::abs(std::abs(axis.z()) - 1.0) > 1e-9 || std::abs(world1.translation().z()) > 1e-9) {
      result.status = "unsupported: joint '" + joint.name + "' is not a pin of the x-y plane";
      return result;
    }
    const Eigen::Vector3d p1 = world1.translation();
    const Eigen::Vector3d p2 = (poses[joint.link2] * joint.frame2).translation();
    pins.emplace_back(pointOn(joint.link1, p1), pointOn(joint.link2, p2));
  }
  for (size_t l = 0; l < numLinks; ++l) {
    if (static_cast<int>(l) == mechanism.rootLink) {
      continue;
    }
    if (points[l].empty() || points[l].size() > 2) {
      result.status = "unsupported: link '" + mechanism.links[l].name + "' has " +
                      std::to_string(points[l].size()) + " joint points (bars have 1 or 2)";
      return result;
    }
    if (points[l].size() == 1) {
      // A bar at the end of a chain: a second point gives it its orientation.
      const Eigen::Vector3d tip = points[l][0].world + Eigen::Vector3d(0.1, 0.0, 0.0);
      points[l].push_back(LinkPoint{tip, sketch.addPoint(kSolved, tip)});
    }
    sketch.addConstraint(SLVS_C_PT_PT_DISTANCE, (points[l][0].world - points[l][1].world).norm(),
                         points[l][0].entity, points[l][1].entity);
  }
  for (const auto& [a, b] : pins) {
    sketch.addConstraint(SLVS_C_POINTS_COINCIDENT, 0.0, a, b);
  }

  std::vector<Slvs_hConstraint> failed(sketch.constraints.size() + 1);
  Slvs_System system{};
  system.param = sketch.params.data();
  system.params = static_cast<int>(sketch.params.size());
  system.entity = sketch.entities.data();
  system.entities = static_cast<int>(sketch.entities.size());
  system.constraint = sketch.constraints.data();
  system.constraints = static_cast<int>(sketch.constraints.size());
  system.failed = failed.data();
  system.faileds = static_cast<int>(failed.size());
  system.calculateFaileds = findFailed ? 1 : 0;
  result.parameters = system.params - 7;
  result.constraints = system.constraints;
  const auto start = std::chrono::steady_clock::now();
  Slvs_Solve(&system, kSolved);
  result.solveSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.dof = system.dof;
  result.failed = findFailed ? system.faileds : -1;
  switch (system.result) {
    case SLVS_RESULT_OKAY:
      result.status = "ok";
      break;
    case SLVS_RESULT_INCONSISTENT:
      result.status = "inconsistent";
      break;
    case SLVS_RESULT_DIDNT_CONVERGE:
      result.status = "didnt_converge";
      break;
    case SLVS_RESULT_TOO_MANY_UNKNOWNS:
      result.status = "too_many_unknowns";
      break;
    default:
      result.status = "result_" + std::to_string(system.result);
  }
  return result;
}

}  // namespace mobility_analysis::bench
