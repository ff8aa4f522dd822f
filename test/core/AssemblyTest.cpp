#include "mobility_analysis/Assembly.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "TextFile.hpp"
#include "core/TestModels.hpp"

using namespace mobility_analysis;

TEST(Assembly, LoopWrittenFiveDegreesOpenCloses) {
  const Mechanism mechanism = loadOrFail(fixturePath("four_bar_open.urdf"));
  const LinkPoses start = computeTreePoses(mechanism, {});
  const double lc = computeCharacteristicLength(mechanism, start);
  const std::optional<int> j4 = mechanism.findJoint("j4");
  ASSERT_TRUE(j4);
  EXPECT_GT(computeJointResidual(mechanism, start, *j4, lc), 0.01);  // really open as written
  const Result<AssembledMechanism> assembled = assembleMechanism(mechanism, start, AnalysisMode::Planar);
  ASSERT_TRUE(isOk(assembled)) << diagnosticOf(assembled).toString();
  const AssembledMechanism& a = valueOf(assembled);
  EXPECT_GT(a.initialResidual, 0.01);
  EXPECT_LT(a.finalResidual, 1e-9);
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    EXPECT_LT(computeJointResidual(mechanism, a.poses, static_cast<int>(j), lc), 1e-8)
        << mechanism.joints[j].name;
  }
  // Least change: the ground does not move, and the crank stays near where it was written.
  EXPECT_TRUE(a.poses[mechanism.rootLink].isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  const int crank = *mechanism.findLink("crank");
  EXPECT_LT((a.poses[crank].linear() - start[crank].linear()).norm(), 0.2);
}

TEST(Assembly, ClosedMechanismIsLeftWhereItIs) {
  const Mechanism mechanism = loadOrFail(fixturePath("four_bar_closed.urdf"));
  const LinkPoses start = computeTreePoses(mechanism, {});
  const Result<AssembledMechanism> assembled = assembleMechanism(mechanism, start, AnalysisMode::Spatial);
  ASSERT_TRUE(isOk(assembled));
  EXPECT_EQ(valueOf(assembled).iterations, 0);  // closed as written: nothing to do
  for (size_t l = 0; l < start.size(); ++l) {
    EXPECT_TRUE(valueOf(assembled).poses[l].isApprox(start[l], 1e-9)) << mechanism.links[l].name;
  }
}

TEST(Assembly, ImpossibleLoopFailsNamingTheLoopJointAndItsResidual) {
  const Mechanism mechanism = loadOrFail(fixturePath("bad_unclosable.urdf"));
  const Result<AssembledMechanism> assembled =
      assembleMechanism(mechanism, computeTreePoses(mechanism, {}), AnalysisMode::Auto);
  ASSERT_FALSE(isOk(assembled));
  const Diagnostic& d = diagnosticOf(assembled);
  EXPECT_EQ(d.elementKind, "loop_joint");
  EXPECT_EQ(d.elementName, "j4");
  EXPECT_NE(d.what.find("residual"), std::string::npos) << d.toString();
  EXPECT_EQ(d.file, "bad_unclosable.urdf");
}

TEST(Assembly, GivenPositionsAreTheStartingGuess) {
  const Mechanism mechanism = loadOrFail(fixturePath("four_bar_closed.urdf"));
  const LinkPoses start = computeTreePoses(mechanism, {{"j1", 0.9}});
  const Result<AssembledMechanism> assembled = assembleMechanism(mechanism, start, AnalysisMode::Planar);
  ASSERT_TRUE(isOk(assembled)) << diagnosticOf(assembled).toString();
  const double lc = computeCharacteristicLength(mechanism, start);
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    EXPECT_LT(computeJointResidual(mechanism, valueOf(assembled).poses, static_cast<int>(j), lc), 1e-8);
  }
}

namespace {

std::string motionFixture(const std::string& name) {
  return fixturePath("motion/" + name);
}

/// Assembles @p file from its written pose and checks that every connection holds.
AssembledMechanism assembleAndCheck(const std::string& file) {
  const Mechanism mechanism = loadOrFail(motionFixture(file));
  const LinkPoses start = computeTreePoses(mechanism, {});
  const double lc = computeCharacteristicLength(mechanism, start);
  const Result<AssembledMechanism> assembled = assembleMechanism(mechanism, start, AnalysisMode::Auto);
  if (!isOk(assembled)) {
    ADD_FAILURE() << diagnosticOf(assembled).toString();
    return AssembledMechanism{};
  }
  const AssembledMechanism& a = valueOf(assembled);
  EXPECT_LE(a.finalResidual, 1e-12 * lc) << file;
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    EXPECT_LT(computeJointResidual(mechanism, a.poses, static_cast<int>(j), lc), 1e-9 * lc)
        << file << ": " << mechanism.joints[j].name;
  }
  return a;
}

}  // namespace

TEST(Assembly, PublishedModelsWrittenStraightClose) {
  // Drake's FourBar and FourBar2 and generalized_rbda's six-bar are published with every joint at 0: the bars
  // stand in one line, the loop is open by metres, and the start is a stationary point of the loop residual.
  for (const char* file :
       {"drake_four_bar_straight.urdf", "drake_four_bar2_straight.urdf", "six_bar_straight.urdf"}) {
    const AssembledMechanism a = assembleAndCheck(file);
    EXPECT_GT(a.initialResidual, 0.1) << file;  // really open as written
    EXPECT_GT(a.iterations, 0) << file;
  }
}

TEST(Assembly, WeldClosesWithItsFramesEqualNotTurnedOver) {
  const Mechanism mechanism = loadOrFail(motionFixture("weld_leg.urdf"));
  const AssembledMechanism a = assembleAndCheck("weld_leg.urdf");
  ASSERT_EQ(a.poses.size(), mechanism.links.size());
  const Joint& weld = mechanism.joints[*mechanism.findJoint("weld")];
  const Eigen::Matrix3d r1 = (a.poses[weld.link1] * weld.frame1).linear();
  const Eigen::Matrix3d r2 = (a.poses[weld.link2] * weld.frame2).linear();
  // The angle of r1^T r2: 0 for a weld that holds, pi for one turned over.
  EXPECT_NEAR(Eigen::AngleAxisd(r1.transpose() * r2).angle(), 0.0, 1e-9);
  EXPECT_EQ(a.model.mode, AnalysisMode::Planar);
}

TEST(Assembly, UnclosableMessageIsOneLineWithTheResidualAndThePoseReached) {
  const Mechanism mechanism = loadOrFail(fixturePath("bad_unclosable.urdf"));
  const Result<AssembledMechanism> assembled =
      assembleMechanism(mechanism, computeTreePoses(mechanism, {}), AnalysisMode::Auto);
  ASSERT_FALSE(isOk(assembled));
  const std::string line = diagnosticOf(assembled).toString();
  EXPECT_EQ(line.find('\n'), std::string::npos) << line;
  EXPECT_NE(line.find("residual"), std::string::npos) << line;
  EXPECT_NE(line.find("pose reached: j1="), std::string::npos) << line;
}

TEST(Assembly, JointPositionsAreReadBackByNameWhateverTheirLength) {
  // Names sorted by a key of eight bytes after their common prefix: short tails (j1 .. j12, out of their
  // lexicographic order), tails of eight bytes and more, and long tails that share their first eight bytes.
  const std::vector<std::function<std::string(int)>> namings = {
      [](int i) { return "j" + std::to_string(i); },
      [](int i) { return "joint_" + std::to_string(i); },
      [](int i) { return "abcdefghijklmnop_" + std::to_string(i); },
      [](int i) { return (i % 2 == 1 ? std::string("p") : "q" + std::string(10, 'z')) + std::to_string(i); },
      [](int i) { return std::string(static_cast<size_t>(i), 'k'); },
  };
  for (size_t n = 0; n < namings.size(); ++n) {
    SCOPED_TRACE(n);
    std::string text = straightChainUrdf(12);
    for (int i = 12; i >= 1; --i) {
      const std::string from = "name='j" + std::to_string(i) + "'";
      const size_t at = text.find(from);
      ASSERT_NE(at, std::string::npos);
      text.replace(at, from.size(), "name='" + namings[n](i) + "'");
    }
    Result<Mechanism> loaded = loadMechanismFromString(text, "names.urdf");
    ASSERT_TRUE(isOk(loaded)) << diagnosticOf(loaded).toString();
    const Mechanism& mechanism = valueOf(loaded);
    JointPositions written;
    for (int i = 1; i <= 12; ++i)
      written[namings[n](i)] = 0.01 * i;
    const JointPositions back = computeJointPositions(mechanism, computeTreePoses(mechanism, written));
    ASSERT_EQ(back.size(), written.size());
    auto b = back.begin();
    for (auto w = written.cbegin(); w != written.cend(); ++w, ++b) {
      EXPECT_EQ(b->first, w->first);  // the same names, in the map's order
      EXPECT_NEAR(b->second, w->second, 1e-12);
    }
  }
}

// A large model may read its joint values off the poses on a second thread while its model is built: the
// same assembly, bit for bit (a chain above the side thread's threshold, at a pose with nonzero joints).
TEST(Assembly, SideThreadGivesTheSameAssembly) {
  const int links = 12000;
  const Result<Mechanism> loaded = loadMechanismFromString(straightChainUrdf(links), "long_chain.urdf");
  ASSERT_TRUE(isOk(loaded)) << diagnosticOf(loaded).toString();
  const Mechanism& mechanism = valueOf(loaded);
  JointPositions bent;
  for (int i = 1; i <= links; i += 7)
    bent["j" + std::to_string(i)] = 0.001 * (i % 13);
  const LinkPoses start = computeTreePoses(mechanism, bent);
  const Result<AssembledMechanism> alone = assembleMechanism(mechanism, start, AnalysisMode::Auto, {}, false);
  const Result<AssembledMechanism> beside = assembleMechanism(mechanism, start, AnalysisMode::Auto, {}, true);
  ASSERT_TRUE(isOk(alone)) << diagnosticOf(alone).toString();
  ASSERT_TRUE(isOk(beside)) << diagnosticOf(beside).toString();
  EXPECT_EQ(valueOf(alone).positions, valueOf(beside).positions);
  EXPECT_EQ(valueOf(alone).positions.size(), static_cast<size_t>(links));
  EXPECT_TRUE(valueOf(alone).q == valueOf(beside).q);
  EXPECT_EQ(valueOf(alone).model.numConstraints(), valueOf(beside).model.numConstraints());
}

// At the written pose, where the loops close already, nothing moves: the poses are the written ones bit for
// bit and every joint value is the written 0, not the rounding read back off the poses (the PUMA 560's joint2
// read -5.6e-17 rad, the Bennett linkage's joints +-1e-16). Read off, the same joints come out within 1e-12
// of 0 (the independent check); the 12 000-link chain is above the side thread's threshold, with and without
// it.
TEST(Assembly, AtTheWrittenPoseNothingMovesAndEveryJointIsExactlyAtItsWrittenZero) {
  std::vector<std::pair<std::string, Mechanism>> models{{"puma560", loadOrFail(urdfPath("puma560.urdf"))},
                                                        {"bennett", loadOrFail(urdfPath("bennett.urdf"))}};
  const Result<Mechanism> chain = loadMechanismFromString(straightChainUrdf(12000), "long_chain.urdf");
  ASSERT_TRUE(isOk(chain)) << diagnosticOf(chain).toString();
  models.emplace_back("chain", valueOf(chain));
  for (const auto& [name, mechanism] : models) {
    const LinkPoses written = computeTreePoses(mechanism, {});
    for (const bool sideThread : {false, true}) {
      SCOPED_TRACE(name + (sideThread ? ", side thread" : ""));
      const Result<AssembledMechanism> assembled =
          assembleMechanism(mechanism, AnalysisMode::Auto, sideThread);
      ASSERT_TRUE(isOk(assembled)) << diagnosticOf(assembled).toString();
      const AssembledMechanism& a = valueOf(assembled);
      EXPECT_EQ(a.iterations, 0);
      ASSERT_EQ(a.poses.size(), written.size());
      for (size_t l = 0; l < written.size(); ++l)
        ASSERT_TRUE(a.poses[l].matrix() == written[l].matrix()) << mechanism.links[l].name;
      const JointPositions readOff = computeJointPositions(mechanism, a.poses);
      ASSERT_EQ(a.positions.size(), readOff.size());
      ASSERT_FALSE(a.positions.empty());
      for (auto p = a.positions.begin(), r = readOff.begin(); p != a.positions.end(); ++p, ++r) {
        EXPECT_EQ(p->first, r->first);
        EXPECT_EQ(p->second, 0.0) << p->first;
        EXPECT_NEAR(r->second, 0.0, 1e-12) << r->first;
      }
      // The same model as from the written poses given as a start (re-posed): the same counts.
      const Result<AssembledMechanism> given = assembleMechanism(mechanism, written, AnalysisMode::Auto);
      ASSERT_TRUE(isOk(given));
      EXPECT_EQ(a.model.numCoordinates(), valueOf(given).model.numCoordinates());
      EXPECT_EQ(a.model.numConstraints(), valueOf(given).model.numConstraints());
      EXPECT_LT((a.q - valueOf(given).q).cwiseAbs().maxCoeff(), 1e-12);
    }
  }
  // The report says so too.
  const MobilityAnalysis puma = analyzeOrFail(urdfPath("puma560.urdf"), AnalysisMode::Auto);
  ASSERT_EQ(puma.report.positions.size(), 6u);
  for (const JointValue& value : puma.report.positions)
    EXPECT_EQ(value.value, 0.0) << value.name;
}

// Written open, the loop has to be closed: the joints move, and their values are read off the closed poses.
TEST(Assembly, FromAWrittenPoseThatDoesNotCloseTheValuesAreReadOffTheClosedPoses) {
  const Mechanism mechanism = loadOrFail(fixturePath("four_bar_open.urdf"));
  const Result<AssembledMechanism> assembled = assembleMechanism(mechanism, AnalysisMode::Planar);
  ASSERT_TRUE(isOk(assembled)) << diagnosticOf(assembled).toString();
  const AssembledMechanism& a = valueOf(assembled);
  EXPECT_GT(a.iterations, 0);
  EXPECT_EQ(a.positions, computeJointPositions(mechanism, a.poses));
  double largest = 0.0;
  for (const auto& [name, value] : a.positions)
    largest = std::max(largest, std::abs(value));
  EXPECT_GT(largest, 1e-3);
}

TEST(Assembly, aMechanismFarFromTheOriginOfItsModelClosesAndReportsAsNearIt) {
  // Welded 10^3 to 10^5 m off the origin and turned (a new root link): the loops close (their residual can
  // be no smaller than the rounding of poses that far out, ClosureLayout::target) and the report's counts
  // and idle motions are those of the mechanism at the origin. Before, from 10^4 m every loop was refused
  // ("cannot be closed: residual 1.6e-12 m").
  for (const char* file : {"delta_robot.urdf", "stewart_6sps.urdf", "bennett.urdf"}) {
    const MobilityReport near = analyzeOrFail(urdfPath(file), AnalysisMode::Spatial).report;
    for (const char* offset : {"1000 -1000 1000", "10000 10000 -10000", "100000 100000 100000"}) {
      SCOPED_TRACE(std::string(file) + " at " + offset);
      const Result<Mechanism> moved =
          loadMechanismFromString(placedAt(readTextFile(urdfPath(file)), offset), file);
      ASSERT_TRUE(isOk(moved)) << diagnosticOf(moved).toString();
      const MobilityReport far = analyzeOrFail(valueOf(moved), AnalysisMode::Spatial).report;
      expectSameCounts(near, far);
      ASSERT_EQ(far.passiveMotions.size(), near.passiveMotions.size());
      for (size_t k = 0; k < near.passiveMotions.size(); ++k)
        EXPECT_EQ(far.passiveMotions[k].description, near.passiveMotions[k].description);
      EXPECT_LE(far.closureResidualAfter, 1e-9 * far.characteristicLength);
    }
  }
}
