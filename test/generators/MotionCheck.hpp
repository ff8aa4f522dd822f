#pragma once

#include "mobility_analysis/generators/MechanismDescription.hpp"

#include <Eigen/Dense>

#include <unordered_map>
#include <vector>

namespace mobility_analysis {

/**
 * @brief Test-only rigid-body check that a description's geometry really moves.
 *
 * Every link is a rigid body whose pose starts at the identity, so the features of each connection (joint
 * point, axes, frame) read from the description's world frames are at once the body-fixed features of both
 * links. The joint conditions of DESIGN.md §2 on the link poses give Φ(poses); its Jacobian's nullity is the
 * spatial DOF, and a predictor–corrector walk along the null space shows the motion is finite, not only
 * infinitesimal. Lengths are divided by the model's size so tolerances are scale-free.
 */
class MotionCheck {
 public:
  /// Link poses: rotation and translation per link (index as in the description).
  struct Poses {
    std::vector<Eigen::Matrix3d> rotation;
    std::vector<Eigen::Vector3d> translation;
  };

  explicit MotionCheck(const MechanismDescription& mechanism) : mechanism_(mechanism) {
    for (size_t l = 0; l < mechanism.links.size(); ++l) {
      linkIndex_[mechanism.links[l].name] = static_cast<int>(l);
    }
    for (const Connection& c : mechanism.connections) {
      scale_ = std::max(scale_, c.frame.translation().norm());
      scale_ = std::max(scale_, c.point2.norm());
    }
    scale_ = std::max(scale_, 1e-6);
  }

  /// @return The identity pose of every link (the written configuration).
  Poses initialPoses() const {
    Poses poses;
    poses.rotation.assign(mechanism_.links.size(), Eigen::Matrix3d::Identity());
    poses.translation.assign(mechanism_.links.size(), Eigen::Vector3d::Zero());
    return poses;
  }

  /// @return Φ(poses): the joint conditions of every connection (normalised lengths).
  Eigen::VectorXd residual(const Poses& poses) const {
    std::vector<double> r;
    r.reserve(mechanism_.connections.size() * 12);
    for (const Connection& c : mechanism_.connections) {
      const int i = linkIndex_.at(c.link1);
      const int j = linkIndex_.at(c.link2);
      const Eigen::Matrix3d& ri = poses.rotation[i];
      const Eigen::Matrix3d& rj = poses.rotation[j];
      const Eigen::Vector3d o = c.frame.translation() / scale_;
      const Eigen::Vector3d xi = ri * o + poses.translation[i];
      const Eigen::Vector3d xj = rj * o + poses.translation[j];
      const Eigen::Vector3d ai = ri * c.axis;
      const Eigen::Vector3d aj = rj * c.axis;
      auto push = [&r](const auto& v) {
        for (Eigen::Index k = 0; k < v.size(); ++k) {
          r.push_back(v(k));
        }
      };
      const Eigen::Matrix<double, 9, 1> dr =
          Eigen::Map<const Eigen::Matrix<double, 9, 1>>((ri - rj).eval().data());
      switch (c.type) {
        case ConnectionType::Revolute:
        case ConnectionType::Continuous:
          push(xi - xj);
          push(ai.cross(aj));
          break;
        case ConnectionType::Prismatic:
          push(dr);
          push((xj - xi).cross(ai));
          break;
        case ConnectionType::Cylindrical:
          push(ai.cross(aj));
          push((xj - xi).cross(ai));
          break;
        case ConnectionType::Spherical:
          push(xi - xj);
          break;
        case ConnectionType::Universal:
          push(xi - xj);
          r.push_back((ri * c.axis).dot(rj * c.axis2) - c.axis.dot(c.axis2));
          break;
        case ConnectionType::Fixed:
          push(xi - xj);
          push(dr);
          break;
        case ConnectionType::Distance: {
          const Eigen::Vector3d p2 = c.point2 / scale_;
          r.push_back((xi - (rj * p2 + poses.translation[j])).norm() - (o - p2).norm());
          break;
        }
      }
    }
    return Eigen::Map<Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()));
  }

  /// @return Poses moved by the twist @p dx (6 per non-ground link: rotation vector, translation).
  Poses apply(const Poses& poses, const Eigen::VectorXd& dx) const {
    Poses moved = poses;
    for (size_t l = 1; l < mechanism_.links.size(); ++l) {
      const Eigen::Vector3d w = dx.segment<3>(6 * (l - 1));
      const double angle = w.norm();
      if (angle > 0) {
        moved.rotation[l] = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix() * poses.rotation[l];
      }
      moved.translation[l] += dx.segment<3>(6 * (l - 1) + 3);
    }
    return moved;
  }

  /// @return dΦ/d(twists) by central differences (ground fixed).
  Eigen::MatrixXd jacobian(const Poses& poses) const {
    const Eigen::Index n = 6 * static_cast<Eigen::Index>(mechanism_.links.size() - 1);
    const Eigen::VectorXd r0 = residual(poses);
    Eigen::MatrixXd jac(r0.size(), n);
    const double h = 1e-6;
    Eigen::VectorXd dx = Eigen::VectorXd::Zero(n);
    for (Eigen::Index k = 0; k < n; ++k) {
      dx(k) = h;
      const Eigen::VectorXd plus = residual(apply(poses, dx));
      dx(k) = -h;
      const Eigen::VectorXd minus = residual(apply(poses, dx));
      dx(k) = 0;
      jac.col(k) = (plus - minus) / (2 * h);
    }
    return jac;
  }

  /// @return Number of singular values of the Jacobian below 1e-6 of the largest: the spatial DOF.
  int nullity(const Poses& poses) const {
    const Eigen::MatrixXd jac = jacobian(poses);
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(jac);
    const Eigen::VectorXd& s = svd.singularValues();
    const Eigen::Index n = jac.cols();
    int rank = 0;
    for (Eigen::Index k = 0; k < s.size(); ++k) {
      rank += s(k) > 1e-6 * s(0) ? 1 : 0;
    }
    return static_cast<int>(n) - rank;
  }

  /// What a walk along the motion found.
  struct Walk {
    double residual = 0;      ///< |Φ| at the end (normalised).
    double displacement = 0;  ///< Largest move of a joint point from its written place (normalised).
    double pathLength = 0;    ///< Sum of the predictor steps (normalised).
  };

  /**
   * @brief Predictor (a null-space step of length @p step) then Gauss–Newton corrector (minimum norm),
   *        @p steps times.
   */
  Walk walk(int steps, double step) const {
    Poses poses = initialPoses();
    Eigen::VectorXd previous;
    Walk result;
    for (int s = 0; s < steps; ++s) {
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(jacobian(poses), Eigen::ComputeFullV);
      const Eigen::VectorXd& sv = svd.singularValues();
      const Eigen::Index n = svd.matrixV().cols();
      int rank = 0;
      for (Eigen::Index k = 0; k < sv.size(); ++k) {
        rank += sv(k) > 1e-6 * sv(0) ? 1 : 0;
      }
      const Eigen::MatrixXd nullBasis = svd.matrixV().rightCols(n - rank);
      Eigen::VectorXd direction = nullBasis.col(nullBasis.cols() - 1);
      if (previous.size() == n) {
        // Keep going the same way: project the previous direction onto the new null space.
        const Eigen::VectorXd projected = nullBasis * (nullBasis.transpose() * previous);
        if (projected.norm() > 1e-3) {
          direction = projected.normalized();
        }
      }
      previous = direction;
      poses = apply(poses, step * direction);
      result.pathLength += step;
      for (int iteration = 0; iteration < 30; ++iteration) {
        const Eigen::VectorXd r = residual(poses);
        if (r.norm() < 1e-14) {
          break;
        }
        Eigen::JacobiSVD<Eigen::MatrixXd> corrector(jacobian(poses),
                                                    Eigen::ComputeThinU | Eigen::ComputeThinV);
        corrector.setThreshold(1e-8);
        poses = apply(poses, -corrector.solve(r));
      }
    }
    result.residual = residual(poses).norm();
    // Joint points can stay put (a door turns about its hinge points), so the drawn points count too.
    auto moved = [&](int link, const Eigen::Vector3d& worldPoint) {
      const Eigen::Vector3d p = worldPoint / scale_;
      result.displacement =
          std::max(result.displacement, (poses.rotation[link] * p + poses.translation[link] - p).norm());
    };
    for (const Connection& c : mechanism_.connections) {
      moved(linkIndex_.at(c.link1), c.frame.translation());
      moved(linkIndex_.at(c.link2), c.type == ConnectionType::Distance ? c.point2 : c.frame.translation());
    }
    for (size_t l = 0; l < mechanism_.links.size(); ++l) {
      for (const Eigen::Vector3d& point : mechanism_.links[l].visualPath) {
        moved(static_cast<int>(l), point);
      }
    }
    return result;
  }

 private:
  const MechanismDescription& mechanism_;
  std::unordered_map<std::string, int> linkIndex_;
  double scale_ = 0;
};

}  // namespace mobility_analysis
