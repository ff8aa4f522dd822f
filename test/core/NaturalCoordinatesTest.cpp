#include "mobility_analysis/NaturalCoordinates.hpp"

#include <cstring>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "core/TestModels.hpp"
#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/RedundancyAnalysis.hpp"
#include "mobility_analysis/Tolerances.hpp"

using namespace mobility_analysis;

namespace {

/// Every link pose moved by a random rotation of @p size rad and a translation of @p size Lc: what an
/// assembly that stopped at a residual of that size leaves.
LinkPoses perturb(const LinkPoses& poses, double lc, double size, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal;
  LinkPoses out = poses;
  for (Eigen::Isometry3d& pose : out) {
    const Eigen::Vector3d axis = Eigen::Vector3d(normal(random), normal(random), normal(random)).normalized();
    const Eigen::Vector3d shift =
        Eigen::Vector3d(normal(random), normal(random), normal(random)).normalized();
    pose.linear() = Eigen::AngleAxisd(size, axis).toRotationMatrix() * pose.linear();
    pose.translation() += size * lc * shift;
  }
  return out;
}

/// The nullity of the model built at @p poses (its own q0), with the default rank tolerance.
int dofAt(const Mechanism& mechanism, const LinkPoses& poses, AnalysisMode mode, double lc) {
  const Result<CoordinateModel> model = buildCoordinateModel(mechanism, poses, mode, lc);
  EXPECT_TRUE(isOk(model));
  if (!isOk(model))
    return -1;
  return computeOrderedRank(computeConstraintJacobian(valueOf(model), valueOf(model).q0), tolerances::kRank)
      .dof();
}

void expectDofSurvivesPerturbation(const Mechanism& mechanism, AnalysisMode mode, int expected) {
  AnalysisOptions options;
  options.mode = mode;
  const Result<MobilityAnalysis> analysis = analyzeMechanism(mechanism, options);
  ASSERT_TRUE(isOk(analysis)) << diagnosticOf(analysis).toString();
  const AssembledMechanism& assembled = valueOf(analysis).assembled;
  EXPECT_EQ(valueOf(analysis).report.dof, expected) << mechanism.name;
  const double lc = assembled.model.characteristicLength;
  for (unsigned seed = 1; seed <= 6; ++seed) {
    EXPECT_EQ(dofAt(mechanism, perturb(assembled.poses, lc, 1e-7, seed), mode, lc), expected)
        << mechanism.name << " (" << toString(mode) << ") perturbed by 1e-7, seed " << seed;
  }
}

/// Links welded end to end along the weld's own axis (x), between pins about z: the weld's two bodies share
/// only directions parallel to each other, the case where a dot form a.b = 1 cannot see the twist.
const char* collinearWeldsUrdf() {
  return R"(<robot name="collinear_welds">
  <link name="ground"/><link name="a"/><link name="b"/><link name="c"/><link name="d"/>
  <joint name="pin1" type="revolute"><parent link="ground"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="weld1" type="fixed"><parent link="a"/><child link="b"/><origin xyz="1 0 0"/></joint>
  <joint name="pin2" type="revolute"><parent link="b"/><child link="c"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="weld2" type="fixed"><parent link="c"/><child link="d"/><origin xyz="0.7 0 0"/></joint>
</robot>)";
}

}  // namespace

TEST(NaturalCoordinates, FixedTwistKeepsTheDofAtAPoseOffByTheAssemblyResidual) {
  const Result<Mechanism> welds = loadMechanismFromString(collinearWeldsUrdf(), "collinear_welds.urdf");
  ASSERT_TRUE(isOk(welds));
  // Two pins in series: 2 in space and in the plane; the welds add nothing.
  expectDofSurvivesPerturbation(valueOf(welds), AnalysisMode::Spatial, 2);
  expectDofSurvivesPerturbation(valueOf(welds), AnalysisMode::Planar, 2);
  // The weld's equation keeps the form it has at the exact pose: the pair parallel by design stays parallel.
  const Mechanism& mechanism = valueOf(welds);
  const LinkPoses poses = computeTreePoses(mechanism, {});
  const double lc = computeCharacteristicLength(mechanism, poses);
  auto twistForms = [&](const LinkPoses& at) {
    std::vector<EquationForm> forms;
    const Result<CoordinateModel> model = buildCoordinateModel(mechanism, at, AnalysisMode::Spatial, lc);
    for (const ConstraintEquation& eq : valueOf(model).equations) {
      if (eq.kind == EquationKind::FixedTwist)
        forms.push_back(eq.form);
    }
    return forms;
  };
  const std::vector<EquationForm> exact = twistForms(poses);
  ASSERT_EQ(exact.size(), 2u);
  for (unsigned seed = 1; seed <= 6; ++seed)
    EXPECT_EQ(twistForms(perturb(poses, lc, 1e-7, seed)), exact) << "seed " << seed;
}

// Only mechanisms without redundancy: an over-constrained one moved off its closed pose is rigid (the pose,
// not the equation forms, is wrong there).
TEST(NaturalCoordinates, EveryNonRedundantReferenceKeepsItsDofAtAPoseOffByTheAssemblyResidual) {
  const struct {
    const char* file;
    AnalysisMode mode;
    int dof;
  } rows[] = {{"four_bar.urdf", AnalysisMode::Planar, 1},
              {"rssr.urdf", AnalysisMode::Spatial, 2},
              {"rppr.urdf", AnalysisMode::Planar, 1},
              {"puma560.urdf", AnalysisMode::Spatial, 6},
              {"sle_mast.urdf", AnalysisMode::Planar, 1}};
  for (const auto& row : rows)
    expectDofSurvivesPerturbation(loadOrFail(urdfPath(row.file)), row.mode, row.dof);
}

TEST(NaturalCoordinates, ModelCoordinatesAreThoseOfItsPoseBitForBit) {
  // assembleMechanism takes q from q0 instead of computing it again: they must agree to the last bit, in the
  // plane and in space, for points and unit vectors, auxiliary elements included.
  for (const char* name : {"four_bar.urdf", "bennett.urdf", "sarrus.urdf", "puma560.urdf", "delta_robot.urdf",
                           "peaucellier.urdf", "stewart_6sps.urdf", "sle_mast.urdf"}) {
    for (const AnalysisMode mode : {AnalysisMode::Auto, AnalysisMode::Spatial}) {
      SCOPED_TRACE(name);
      const Mechanism mechanism = loadOrFail(urdfPath(name));
      const LinkPoses poses = computeTreePoses(mechanism, {});
      const Result<CoordinateModel> model =
          buildCoordinateModel(mechanism, poses, mode, computeCharacteristicLength(mechanism, poses));
      ASSERT_TRUE(isOk(model)) << diagnosticOf(model).toString();
      const Eigen::VectorXd q = computeCoordinates(valueOf(model), poses);
      ASSERT_EQ(q.size(), valueOf(model).q0.size());
      for (Eigen::Index i = 0; i < q.size(); ++i)
        EXPECT_EQ(std::memcmp(&q(i), &valueOf(model).q0(i), sizeof(double)), 0) << i;
    }
  }
}
