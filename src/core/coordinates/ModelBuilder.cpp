#include "mobility_analysis/coordinates/ModelBuilder.hpp"

namespace mobility_analysis {

int ModelBuilder::addElement(int body, bool isPoint, const Eigen::Vector3d& local, ElementRole role,
                             int joint) {
  Element e;
  e.body = body;
  e.isPoint = isPoint;
  e.role = role;
  e.joint = joint;
  e.local = local;
  model.elements.push_back(e);
  world.push_back(
      isPoint ? (poses[body].linear() * local + poses[body].translation() / model.characteristicLength)
              : (poses[body].linear() * local).eval());
  model.bodyElements[body].push_back(static_cast<int>(model.elements.size()) - 1);
  return static_cast<int>(model.elements.size()) - 1;
}

Eigen::Vector3d ModelBuilder::project(const Eigen::Vector3d& w) const {
  // In the plane an element is its projection; vectors along the normal carry no planar information.
  return planar() ? Eigen::Vector3d(w.dot(model.planeE1), w.dot(model.planeE2), 0.0) : w;
}

Eigen::Vector3d ModelBuilder::coordinates(int e) const {
  return project(world[e]);
}

Eigen::Vector3d ModelBuilder::directionValue(const Direction& d) const {
  return d.tail < 0 ? coordinates(d.head) : (coordinates(d.head) - coordinates(d.tail)).eval();
}

Eigen::Vector3d ModelBuilder::worldOf(const Direction& d) const {
  return d.tail < 0 ? world[d.head] : (world[d.head] - world[d.tail]).eval();
}

Eigen::Vector3d worldAxis(const Joint& joint, const LinkPoses& poses) {
  const Eigen::Matrix3d r1 = poses[joint.link1].linear() * joint.frame1.linear();
  return r1 * joint.axis;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> worldAxes(const Joint& joint, const LinkPoses& poses) {
  const Eigen::Matrix3d r2 = poses[joint.link2].linear() * joint.frame2.linear();
  return {worldAxis(joint, poses), r2 * joint.axis2};
}

}  // namespace mobility_analysis
