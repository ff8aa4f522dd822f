#include "mobility_analysis/analysis/DriveableJoints.hpp"

#include <Eigen/QR>

#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/Kinematics.hpp"

namespace mobility_analysis {

namespace {

/// Step along a (unit) null vector for the central difference of the joint rates [-, scaled coordinates].
constexpr double kRateStep = 1e-6;
/// A joint adds a direction when its rate row keeps this much of its norm off the rows chosen before it [-].
constexpr double kIndependent = 1e-5;
/// Singular values below this fraction of the largest span the null space [-].
constexpr double kNullTolerance = 1e-9;

}  // namespace

std::vector<std::string> findDriveableJoints(const Mechanism& mechanism, const MobilityAnalysis& analysis) {
  const int dof = analysis.report.dof;
  std::vector<std::string> chosen;
  const LinkPoses& poses = analysis.assembled.poses;
  // Planar coordinates do not give back the links' turns (recoverPoses keeps the reference's rotations
  // there), so the rates come from the spatial model at the same pose; its null space holds the planar
  // motions.
  CoordinateModel spatial;
  const CoordinateModel* model = &analysis.assembled.model;
  Eigen::VectorXd q = analysis.assembled.q;
  if (model->mode == AnalysisMode::Planar) {
    Result<CoordinateModel> built =
        buildCoordinateModel(mechanism, poses, AnalysisMode::Spatial, model->characteristicLength);
    if (!isOk(built))
      return chosen;
    spatial = valueOf(std::move(built));
    model = &spatial;
    q = computeCoordinates(spatial, poses);
  }
  if (dof <= 0 || model->numCoordinates() > kMaxDriveableSearchCoordinates)
    return chosen;
  const Eigen::MatrixXd J = Eigen::MatrixXd(computeConstraintJacobian(*model, q));
  Eigen::MatrixXd nullSpace;
  if (J.rows() == 0) {
    nullSpace = Eigen::MatrixXd::Identity(model->numCoordinates(), model->numCoordinates());
  } else {
    // A rank-revealing QR of Jᵀ: Jᵀ P = Q R, so the last n − rank columns of Q are an orthonormal basis of
    // the null space (the joint choice below only needs some orthonormal basis: it is invariant under
    // rotating it). A full SVD gives the same space; its divide-and-conquer template alone cost a minute of
    // every build.
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(J.transpose());
    qr.setThreshold(kNullTolerance);
    const Eigen::MatrixXd orthonormal = qr.householderQ();
    nullSpace = orthonormal.rightCols(model->numCoordinates() - static_cast<int>(qr.rank()));
  }
  const JointPositions here = computeJointPositions(mechanism, poses);
  // rates(j, i): rate of tree joint j along null vector i.
  std::vector<std::string> names;
  for (const Joint& joint : mechanism.joints) {
    if (here.count(joint.name) && joint.kind == ConnectionKind::TreeJoint)
      names.push_back(joint.name);
  }
  Eigen::MatrixXd rates(names.size(), nullSpace.cols());
  for (int i = 0; i < nullSpace.cols(); ++i) {
    const Eigen::VectorXd step = kRateStep * nullSpace.col(i);
    const JointPositions plus = computeJointPositions(mechanism, recoverPoses(*model, q + step, poses), here);
    const JointPositions minus =
        computeJointPositions(mechanism, recoverPoses(*model, q - step, poses), here);
    for (size_t j = 0; j < names.size(); ++j) {
      rates(j, i) = (plus.at(names[j]) - minus.at(names[j])) / (2.0 * kRateStep);
    }
  }
  // Greedy in document order: Gram-Schmidt of the rate rows.
  std::vector<Eigen::VectorXd> basis;
  for (size_t j = 0; j < names.size() && static_cast<int>(chosen.size()) < dof; ++j) {
    Eigen::VectorXd r = rates.row(j).transpose();
    const double norm = r.norm();
    if (norm < kIndependent)
      continue;  // This joint does not move in any free direction.
    for (const Eigen::VectorXd& b : basis)
      r -= b.dot(r) * b;
    if (r.norm() > kIndependent * norm) {
      basis.push_back(r.normalized());
      chosen.push_back(names[j]);
    }
  }
  return chosen;
}

}  // namespace mobility_analysis
