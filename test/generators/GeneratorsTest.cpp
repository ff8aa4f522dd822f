#include "MotionCheck.hpp"

#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/FamilyRegistry.hpp"
#include "mobility_analysis/generators/ParametricFamilies.hpp"
#include "mobility_analysis/generators/ReferenceMechanisms.hpp"
#include "mobility_analysis/generators/ScalingFamilies.hpp"

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <cstdlib>
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

using namespace mobility_analysis;

namespace {

struct NamedModel {
  std::string label;
  std::function<MechanismDescription()> make;
};

/// Small instances of every family: small enough for a dense numeric Jacobian.
std::vector<NamedModel> smallModels() {
  return {
      {"four_bar", [] { return makeFourBar(); }},
      {"puma560", [] { return makePuma560(); }},
      {"parallelogram_crank", [] { return makeParallelogramCrank(); }},
      {"three_sliders", [] { return makeThreeSliders(); }},
      {"rppr", [] { return makeRppr(); }},
      {"bennett", [] { return makeBennett(); }},
      {"bennett_mm", [] { return makeBennett(1000.0); }},
      {"sarrus", [] { return makeSarrus(); }},
      {"bricard", [] { return makeBricard(); }},
      {"goldberg", [] { return makeGoldberg(); }},
      {"rssr", [] { return makeRssr(); }},
      {"flattened_four_bar", [] { return makeFlattenedFourBar(); }},
      {"parallelogram_bifurcation", [] { return makeParallelogramBifurcation(); }},
      {"collinear_bars", [] { return makeCollinearBars(); }},
      {"stewart_6sps", [] { return makeStewart6Sps(); }},
      {"delta_robot", [] { return makeDeltaRobot(); }},
      {"door_1", [] { return makeDoor(1); }},
      {"door_3", [] { return makeDoor(3); }},
      {"door_5", [] { return makeDoor(5); }},
      {"sle_planar_1", [] { return makeSlePlanarMast(1); }},
      {"sle_planar_4", [] { return makeSlePlanarMast(4); }},
      {"sle_triangular_1", [] { return makeSleTriangularMast(1); }},
      {"sle_triangular_2", [] { return makeSleTriangularMast(2); }},
      {"sle_triangular_3", [] { return makeSleTriangularMast(3); }},
      {"sle_spatial_2", [] { return makeSleSpatialMast(2); }},
      {"hoberman_3", [] { return makeHobermanRing(3); }},
      {"hoberman_6", [] { return makeHobermanRing(6); }},
      {"hoberman_9", [] { return makeHobermanRing(9); }},
      {"grid_1x1", [] { return makeParallelogramGrid(1, 1); }},
      {"grid_2x3", [] { return makeParallelogramGrid(2, 3); }},
      {"grid_3x2", [] { return makeParallelogramGrid(3, 2); }},
      {"chain_3", [] { return makeChain(3); }},
      {"chain_5_zigzag", [] { return makeChain(5, ChainShape::Zigzag); }},
      {"chain_4_leaf_first", [] { return makeChain(4, ChainShape::Zigzag, ChainOrder::LeafFirst); }},
      {"star_1", [] { return makeStar(1); }},
      {"star_6", [] { return makeStar(6); }},
      {"ring_4", [] { return makeRing(4); }},
      {"ring_7", [] { return makeRing(7); }},
  };
}

/// Models that do not move (truss), have no spatial expectation (bar lattices) or carry cables: checked for
/// closure and well-formed XML, their counts in ScalingFamiliesTest.
std::vector<NamedModel> structureModels() {
  return {
      {"bar_lattice_2x3", [] { return makeBarLattice(2, 3); }},
      {"braced_lattice_3x2", [] { return makeBarLattice(3, 2, true); }},
      {"truss_mast_1", [] { return makeTrussMast(1); }},
      {"truss_mast_3", [] { return makeTrussMast(3); }},
      {"ring_pantograph_net_4", [] { return makeRingPantographNet(4, 150); }},
      {"ring_pantograph_net_5_deployed", [] { return makeRingPantographNet(5, 60); }},
  };
}

std::vector<NamedModel> allModels() {
  std::vector<NamedModel> models = smallModels();
  for (NamedModel& model : structureModels()) {
    models.push_back(std::move(model));
  }
  return models;
}

const FamilyExpectation* findMode(const MechanismDescription& m, const std::string& mode) {
  for (const FamilyExpectation& e : m.expectations) {
    if (e.mode == mode) {
      return &e;
    }
  }
  return nullptr;
}

/// Largest closure error of the layout, recomposing link frames from the written numbers only.
double maxClosureError(const MechanismDescription& mechanism, const ClosedLoopLayout& layout) {
  std::unordered_map<std::string, Eigen::Isometry3d> frames;
  frames[layout.links.front()] = Eigen::Isometry3d::Identity();
  for (const TreeJointLayout& joint : layout.treeJoints) {
    frames[joint.child] = frames.at(joint.parent) * toIsometry(joint.origin);
  }
  double worst = 0;
  for (size_t l = 0; l < layout.links.size(); ++l) {
    worst = std::max(
        worst, (frames.at(layout.links[l]).matrix() - layout.linkFrames[l].matrix()).cwiseAbs().maxCoeff());
  }
  std::unordered_map<std::string, const Connection*> connections;
  for (const Connection& c : mechanism.connections) {
    connections[c.name] = &c;
  }
  for (const LoopJointLayout& loop : layout.loopJoints) {
    const Eigen::Isometry3d& f1 = frames.at(loop.link1);
    const Eigen::Isometry3d& f2 = frames.at(loop.link2);
    if (loop.type == ConnectionType::Distance) {
      const Connection& c = *connections.at(loop.name);
      const double written = (f1 * loop.frame1.xyz - f2 * loop.frame2.xyz).norm();
      worst = std::max(worst, std::abs(written - (c.frame.translation() - c.point2).norm()));
      continue;
    }
    const Eigen::Isometry3d w1 = f1 * toIsometry(loop.frame1);
    const Eigen::Isometry3d w2 = f2 * toIsometry(loop.frame2);
    worst = std::max(worst, (w1.matrix() - w2.matrix()).cwiseAbs().maxCoeff());
    // The written axis, seen from either side, is the description's world axis.
    const Connection& c = *connections.at(loop.name);
    worst = std::max(worst, (w1.linear() * loop.axis - c.axis).cwiseAbs().maxCoeff());
  }
  // Tree joint axes too.
  for (const TreeJointLayout& joint : layout.treeJoints) {
    if (joint.type == "floating") {
      continue;
    }
    const Connection& c = *connections.at(joint.name);
    worst = std::max(worst, (frames.at(joint.child).linear() * joint.axis - c.axis).cwiseAbs().maxCoeff());
  }
  return worst;
}

double modelSize(const MechanismDescription& mechanism) {
  double size = 1.0;
  for (const Connection& c : mechanism.connections) {
    size = std::max(size, c.frame.translation().norm());
  }
  return size;
}

}  // namespace

TEST(RpyConversion, RoundTripIsExactNearGimbalLock) {
  for (double pitch : {0.3, M_PI / 2, -M_PI / 2, M_PI / 2 - 1e-9, -M_PI / 2 + 1e-7}) {
    const Eigen::Matrix3d r = rotationFromRpy(Eigen::Vector3d(0.7, pitch, -1.1));
    const Eigen::Matrix3d back = rotationFromRpy(rpyFromRotation(r));
    EXPECT_LT((r - back).cwiseAbs().maxCoeff(), 1e-15) << "pitch " << pitch;
  }
}

TEST(ClosedLoopUrdf, EveryFamilyClosesExactlyAtTheWrittenPose) {
  for (const NamedModel& model : allModels()) {
    const MechanismDescription m = model.make();
    const auto layout = computeClosedLoopLayout(m);
    ASSERT_TRUE(std::holds_alternative<ClosedLoopLayout>(layout)) << model.label;
    EXPECT_LT(maxClosureError(m, std::get<ClosedLoopLayout>(layout)), 1e-12 * modelSize(m)) << model.label;
  }
}

TEST(ClosedLoopUrdf, EveryFamilyWritesWellFormedXml) {
  for (const NamedModel& model : allModels()) {
    const MechanismDescription m = model.make();
    const auto text = toClosedLoopUrdf(m);
    ASSERT_TRUE(std::holds_alternative<std::string>(text)) << model.label;
    tinyxml2::XMLDocument doc;
    ASSERT_EQ(doc.Parse(std::get<std::string>(text).c_str()), tinyxml2::XML_SUCCESS) << model.label;
    const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
    ASSERT_NE(robot, nullptr) << model.label;
    int links = 0;
    int joints = 0;
    int loops = 0;
    std::unordered_map<std::string, int> parentsOf;
    for (const tinyxml2::XMLElement* e = robot->FirstChildElement(); e != nullptr;
         e = e->NextSiblingElement()) {
      const std::string tag = e->Name();
      if (tag == "link") {
        ++links;
      } else if (tag == "joint") {
        ++joints;
        ++parentsOf[e->FirstChildElement("child")->Attribute("link")];
      } else if (tag == "loop_joint" || tag == "distance_constraint") {
        ++loops;
      }
    }
    EXPECT_EQ(links, static_cast<int>(m.links.size())) << model.label;
    // A tree: every non-root link has exactly one parent.
    EXPECT_EQ(joints, links - 1) << model.label;
    for (const auto& [child, count] : parentsOf) {
      EXPECT_EQ(count, 1) << model.label << " " << child;
    }
    EXPECT_EQ(parentsOf.count(m.links.front().name), 0u) << model.label;
    const auto layout = std::get<ClosedLoopLayout>(computeClosedLoopLayout(m));
    EXPECT_EQ(loops, static_cast<int>(layout.loopJoints.size())) << model.label;
  }
}

TEST(Expectations, GrublerCountMatchesTheClosedForms) {
  for (const NamedModel& model : smallModels()) {
    const MechanismDescription m = model.make();
    ASSERT_FALSE(m.expectations.empty()) << model.label;
    for (const FamilyExpectation& e : m.expectations) {
      const std::optional<int> count = computeGrublerCount(m, e.lambda);
      ASSERT_TRUE(count.has_value()) << model.label;
      EXPECT_EQ(*count, e.grubler) << model.label << " " << e.mode;
      EXPECT_EQ(e.redundant, e.dof - e.grubler) << model.label << " " << e.mode;
    }
  }
}

TEST(Expectations, ClosedFormsAtLargeCounts) {
  EXPECT_EQ(*computeGrublerCount(makeSleTriangularMast(40), 6), expectSleTriangularMast(40).front().grubler);
  EXPECT_EQ(*computeGrublerCount(makeSleSpatialMast(40), 6), 1 - 3 * 40);
  EXPECT_EQ(*computeGrublerCount(makeSlePlanarMast(40), 3), 1);
  EXPECT_EQ(*computeGrublerCount(makeHobermanRing(40), 3), -3);
  EXPECT_EQ(*computeGrublerCount(makeDoor(12), 6), 6 - 5 * 12);
  EXPECT_EQ(*computeGrublerCount(makeParallelogramGrid(7, 5), 3),
            expectParallelogramGrid(7, 5).front().grubler);
}

TEST(Mobility, JacobianNullityIsTheExpectedDof) {
  for (const NamedModel& model : smallModels()) {
    const MechanismDescription m = model.make();
    const FamilyExpectation* spatial = findMode(m, "spatial");
    ASSERT_NE(spatial, nullptr) << model.label;
    const MotionCheck check(m);
    const auto poses = check.initialPoses();
    EXPECT_LT(check.residual(poses).norm(), 1e-13) << model.label;
    EXPECT_EQ(check.nullity(poses), spatial->dof) << model.label;
  }
}

TEST(Mobility, EveryModelMovesAlongAFiniteMotion) {
  for (const NamedModel& model : smallModels()) {
    const MechanismDescription m = model.make();
    const MotionCheck check(m);
    const MotionCheck::Walk walk = check.walk(8, 0.03);
    EXPECT_LT(walk.residual, 1e-12) << model.label;
    // A real motion carries the points about as far as the steps went; an infinitesimal one does not. The
    // collinear bars have only an infinitesimal one (finite_dof 0): the walk must not get anywhere.
    if (model.label == "collinear_bars") {
      EXPECT_LT(walk.displacement, 1e-3 * walk.pathLength) << model.label;
    } else {
      EXPECT_GT(walk.displacement, 0.3 * walk.pathLength / std::sqrt(6.0 * m.links.size())) << model.label;
    }
  }
}

TEST(Mobility, CheckDetectsRigidLoops) {
  // The check must be able to fail: a Bricard with one axis tilted off the symmetry is a generic, rigid 6R,
  // and a Bennett with a wrong twist is a rigid 4R.
  MechanismDescription bricard = makeBricard();
  Connection& j2 = bricard.connections[1];
  j2.axis = (Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()) * j2.axis).normalized();
  j2.frame = frameFromAxis(j2.frame.translation(), j2.axis);
  const MotionCheck brokenBricard(bricard);
  EXPECT_EQ(brokenBricard.nullity(brokenBricard.initialPoses()), 0);
  MechanismDescription bennett = makeBennett();
  Connection& j3 = bennett.connections[2];
  j3.axis = (Eigen::AngleAxisd(0.05, j3.frame.linear().col(0)) * j3.axis).normalized();
  j3.frame = frameFromAxis(j3.frame.translation(), j3.axis);
  const MotionCheck brokenBennett(bennett);
  EXPECT_EQ(brokenBennett.nullity(brokenBennett.initialPoses()), 0);
}

TEST(Mobility, ClosedFormConfigurationsKeepEveryLinkRigid) {
  // The four-bar and Bennett built at other input angles by their closed forms: joint points on each link
  // keep their mutual distances, so the families are real motions, not one closed pose.
  auto distances = [](const MechanismDescription& m) {
    std::vector<double> d;
    for (const LinkDescription& link : m.links) {
      std::vector<Eigen::Vector3d> points;
      std::vector<Eigen::Vector3d> axes;
      for (const Connection& c : m.connections) {
        if (c.link1 == link.name || c.link2 == link.name) {
          points.push_back(c.frame.translation());
          axes.push_back(c.axis);
        }
      }
      for (size_t i = 0; i < points.size(); ++i) {
        for (size_t j = i + 1; j < points.size(); ++j) {
          d.push_back((points[i] - points[j]).norm());
          d.push_back(axes[i].dot(axes[j]));
          d.push_back(axes[i].dot(points[j] - points[i]));
        }
      }
    }
    return d;
  };
  for (double angle : {0.4, 1.2, 2.5}) {
    const std::vector<double> a = distances(makeFourBar(1.0));
    const std::vector<double> b = distances(makeFourBar(angle));
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_NEAR(a[i], b[i], 1e-12) << "four_bar at " << angle;
    }
    const std::vector<double> c = distances(makeBennett(1.0, 1.0));
    const std::vector<double> d = distances(makeBennett(1.0, angle));
    for (size_t i = 0; i < c.size(); ++i) {
      EXPECT_NEAR(std::abs(c[i]), std::abs(d[i]), 1e-12) << "bennett at " << angle;
    }
    const std::vector<double> e = distances(makeGoldberg(1.3));
    const std::vector<double> f = distances(makeGoldberg(angle + 0.3));
    for (size_t i = 0; i < e.size(); ++i) {
      EXPECT_NEAR(std::abs(e[i]), std::abs(f[i]), 1e-12) << "goldberg at " << angle;
    }
  }
}

TEST(ClosedLoopUrdf, RejectsBadDescriptions) {
  MechanismDescription m = makeFourBar();
  m.connections[1].link2 = "nope";
  EXPECT_TRUE(std::holds_alternative<GeneratorError>(computeClosedLoopLayout(m)));
  m = makeFourBar();
  m.connections[2].name = m.connections[0].name;
  EXPECT_TRUE(std::holds_alternative<GeneratorError>(computeClosedLoopLayout(m)));
  m = makeFourBar();
  m.connections[0].axis = Eigen::Vector3d::Zero();
  EXPECT_TRUE(std::holds_alternative<GeneratorError>(computeClosedLoopLayout(m)));
}

TEST(ClosedLoopUrdf, RssrRodHangsByAFloatingJoint) {
  const auto layout = std::get<ClosedLoopLayout>(computeClosedLoopLayout(makeRssr()));
  int floating = 0;
  for (const TreeJointLayout& joint : layout.treeJoints) {
    floating += joint.type == "floating" ? 1 : 0;
    if (joint.type == "floating") {
      EXPECT_EQ(joint.child, "rod");
    }
  }
  EXPECT_EQ(floating, 1);
  EXPECT_EQ(layout.loopJoints.size(), 2u);
}

TEST(ClosedLoopUrdf, BennettIsClosedByJ4) {
  const auto layout = std::get<ClosedLoopLayout>(computeClosedLoopLayout(makeBennett()));
  ASSERT_EQ(layout.loopJoints.size(), 1u);
  EXPECT_EQ(layout.loopJoints.front().name, "j4");
}

TEST(ClosedLoopUrdf, LargeModelsStayClosed) {
  for (const MechanismDescription& m :
       {makeSlePlanarMast(3000), makeSleTriangularMast(1000), makeHobermanRing(2000)}) {
    const auto layout = computeClosedLoopLayout(m, UrdfWriterOptions{false, ""});
    ASSERT_TRUE(std::holds_alternative<ClosedLoopLayout>(layout)) << m.name;
    // Rounding accumulates along a tree thousands of joints deep; relative to the model size it stays tiny.
    EXPECT_LT(maxClosureError(m, std::get<ClosedLoopLayout>(layout)), 1e-12 * modelSize(m)) << m.name;
  }
}

TEST(FamilyRegistry, EveryFamilyGenerates) {
  for (const FamilyInfo& info : listFamilies()) {
    std::vector<std::string> args = {info.name};
    for (int k = 0; k < info.minCounts; ++k) {
      args.push_back("3");
    }
    const auto request = parseGenerateArguments(args);
    ASSERT_TRUE(std::holds_alternative<GenerateRequest>(request)) << info.name;
    const auto mechanism = generateMechanism(std::get<GenerateRequest>(request));
    ASSERT_TRUE(std::holds_alternative<MechanismDescription>(mechanism)) << info.name;
    EXPECT_TRUE(
        std::holds_alternative<std::string>(toClosedLoopUrdf(std::get<MechanismDescription>(mechanism))));
  }
}

TEST(ClosedLoopUrdf, LeafFirstChainListsChildrenBeforeParents) {
  // The tree joints of a leaf-first chain are written from the free end down, links likewise after the
  // ground.
  const auto text = toClosedLoopUrdf(makeChain(4, ChainShape::Straight, ChainOrder::LeafFirst));
  ASSERT_TRUE(std::holds_alternative<std::string>(text));
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.Parse(std::get<std::string>(text).c_str()), tinyxml2::XML_SUCCESS);
  std::vector<std::string> joints, links;
  for (const tinyxml2::XMLElement* e = doc.FirstChildElement("robot")->FirstChildElement(); e != nullptr;
       e = e->NextSiblingElement()) {
    if (std::string(e->Name()) == "joint")
      joints.push_back(e->Attribute("name"));
    if (std::string(e->Name()) == "link")
      links.push_back(e->Attribute("name"));
  }
  EXPECT_EQ(joints, (std::vector<std::string>{"joint_4", "joint_3", "joint_2", "joint_1"}));
  EXPECT_EQ(links, (std::vector<std::string>{"ground", "link_4", "link_3", "link_2", "link_1"}));
}

TEST(Expectations, ScalingFamiliesCountWhatTheyBuild) {
  // Links and joints as the closed forms' derivations count them.
  for (int n : {3, 6}) {
    EXPECT_EQ(makeChain(n).links.size(), static_cast<size_t>(n + 1));
    EXPECT_EQ(makeRing(n).connections.size(), static_cast<size_t>(n));
    EXPECT_EQ(makeTrussMast(n).connections.size(), static_cast<size_t>(9 * n));
    EXPECT_EQ(makeRingPantographNet(n, 150).cables.size(), static_cast<size_t>(2 * n + 1));
  }
  for (auto [r, c] : {std::pair{1, 1}, std::pair{3, 5}}) {
    const MechanismDescription lattice = makeBarLattice(r, c);
    const int nodes = (r + 1) * (c + 1), bars = r * (c + 1) + c * (r + 1);
    EXPECT_EQ(lattice.links.size(), static_cast<size_t>(bars));
    EXPECT_EQ(lattice.connections.size(), static_cast<size_t>(2 * bars - nodes));
    EXPECT_EQ(*computeGrublerCount(lattice, 3), r + c - 1);
    EXPECT_EQ(makeBarLattice(r, c, true).cables.size(), static_cast<size_t>(2 * r * c));
  }
  EXPECT_EQ(*computeGrublerCount(makeTrussMast(5), 6), -15);
  EXPECT_EQ(*computeGrublerCount(makeRing(1000), 3), 997);
  EXPECT_EQ(*computeGrublerCount(makeChain(1000, ChainShape::Zigzag, ChainOrder::LeafFirst), 3), 1000);
}

TEST(FamilyRegistry, RejectsBadArguments) {
  const std::vector<std::vector<std::string>> bad = {
      {},
      {"no_such_family"},
      {"sle_planar"},
      {"sle_planar", "0"},
      {"sle_planar", "x"},
      {"sle_planar", "3", "4"},
      {"four_bar", "--scale", "-1"},
      {"four_bar", "--colour", "red"},
      {"four_bar", "--scale"},
      {"parallelogram_grid", "3"},
      {"chain", "3", "--shape", "curly"},
      {"chain", "3", "--order", "sideways"},
      {"ring", "3", "--shape", "zigzag"},
      {"bar_lattice", "3"},
  };
  for (const auto& args : bad) {
    EXPECT_TRUE(std::holds_alternative<GeneratorError>(parseGenerateArguments(args))) << args.size();
  }
  const auto hoberman = parseGenerateArguments({"hoberman", "2"});
  ASSERT_TRUE(std::holds_alternative<GenerateRequest>(hoberman));
  EXPECT_TRUE(std::holds_alternative<GeneratorError>(generateMechanism(std::get<GenerateRequest>(hoberman))));
}

TEST(FamilyRegistry, ChainOptionsReachTheGenerator) {
  const auto request = parseGenerateArguments({"chain", "5", "--shape", "zigzag", "--order", "leaf-first"});
  ASSERT_TRUE(std::holds_alternative<GenerateRequest>(request));
  const auto mechanism = generateMechanism(std::get<GenerateRequest>(request));
  ASSERT_TRUE(std::holds_alternative<MechanismDescription>(mechanism));
  const MechanismDescription& m = std::get<MechanismDescription>(mechanism);
  EXPECT_TRUE(m.treeJointsLeafFirst);
  EXPECT_EQ(m.links[1].name, "link_5");
  EXPECT_NEAR(m.connections.back().frame.translation().y(), 0.0, 1e-15);   // joint_1 at the origin
  EXPECT_NEAR(m.connections.front().frame.translation().y(), 0.0, 1e-15);  // joint_5 at x = 0.4, y = 0
  EXPECT_NEAR(m.connections[1].frame.translation().y(), 0.05, 1e-15);      // joint_4 at x = 0.3, off axis
  const auto ring = parseGenerateArguments({"ring", "2"});
  ASSERT_TRUE(std::holds_alternative<GenerateRequest>(ring));
  EXPECT_TRUE(std::holds_alternative<GeneratorError>(generateMechanism(std::get<GenerateRequest>(ring))));
}

TEST(MobilityGenerateCli, BadArgumentsExitTwo) {
  const std::string exe = MA_GENERATE_EXE;
  for (const std::string args :
       {"", "no_such_family", "sle_spatial", "sle_spatial -4", "door 2 --visuals 7"}) {
    const int status = std::system((exe + " " + args + " > /dev/null 2>&1").c_str());
    ASSERT_TRUE(WIFEXITED(status)) << args;
    EXPECT_EQ(WEXITSTATUS(status), 2) << args;
  }
  const int ok = std::system((exe + " sle_spatial 5 > /dev/null").c_str());
  EXPECT_EQ(WEXITSTATUS(ok), 0);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
