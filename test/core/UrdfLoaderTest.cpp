#include "mobility_analysis/UrdfLoader.hpp"

#include <gtest/gtest.h>

#include "core/TestModels.hpp"

using namespace mobility_analysis;

TEST(UrdfLoader, ReadsTreeJointsLoopJointsDistanceConstraintsAndCablesInEquationOrder) {
  const Result<Mechanism> result = loadMechanismFromString(allJointKindsUrdf(), "dir/all_kinds.urdf");
  ASSERT_TRUE(isOk(result)) << diagnosticOf(result).toString();
  const Mechanism& m = valueOf(result);
  EXPECT_EQ(m.name, "all_kinds");
  EXPECT_EQ(m.file, "all_kinds.urdf");
  EXPECT_EQ(m.links.size(), 8u);
  EXPECT_EQ(m.links[m.rootLink].name, "ground");
  std::vector<std::string> names;
  for (const Joint& j : m.joints) names.push_back(j.name);
  // Tree joints in document order, then distance constraints, cables, loop joints (DESIGN.md §3).
  EXPECT_EQ(names, (std::vector<std::string>{"r", "p", "fx", "pl", "fl", "cont", "fl2", "dist", "cab", "lr", "lp",
                                             "lc", "ls", "lu", "lf"}));
  const Joint& r = m.joints[0];
  EXPECT_EQ(r.type, JointType::Revolute);
  EXPECT_TRUE(r.axis.isApprox(Eigen::Vector3d(0, 0.6, 0.8)));
  EXPECT_TRUE(r.frame1.translation().isApprox(Eigen::Vector3d(0.1, 0.2, 0.3)));
  EXPECT_EQ(m.joints[3].type, JointType::Planar);
  EXPECT_EQ(m.joints[4].type, JointType::Floating);
  EXPECT_EQ(m.joints[7].kind, ConnectionKind::DistanceConstraint);
  EXPECT_EQ(m.joints[8].kind, ConnectionKind::Cable);
  EXPECT_DOUBLE_EQ(m.joints[8].length, 10.0);
  const Joint& lu = m.joints[13];
  EXPECT_EQ(lu.type, JointType::Universal);
  EXPECT_TRUE(lu.axis2.isApprox(Eigen::Vector3d::UnitY()));
  const Joint& lr = m.joints[9];
  EXPECT_EQ(lr.kind, ConnectionKind::LoopJoint);
  EXPECT_EQ(m.links[lr.link1].name, "d");
  EXPECT_EQ(m.links[lr.link2].name, "e");
  // rpy is URDF's fixed-axis roll-pitch-yaw.
  EXPECT_TRUE(lr.frame2.linear().isApprox(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()).toRotationMatrix()));
}

TEST(UrdfLoader, IsaacSimSphericalLoopJointLoadsAsItIs) {
  const char* text = R"(<?xml version="1.0"?>
<robot name="isaac">
  <link name="base"/><link name="arm"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <loop_joint name="ball" type="spherical">
    <link1 link="arm" rpy="0 0 0" xyz="0.5 0 0"/>
    <link2 link="base" rpy="0 0 0" xyz="0.5 0 0"/>
  </loop_joint>
</robot>)";
  const Result<Mechanism> result = loadMechanismFromString(text, "isaac.urdf");
  ASSERT_TRUE(isOk(result)) << diagnosticOf(result).toString();
  EXPECT_EQ(valueOf(result).joints[1].type, JointType::Spherical);
}

struct BadFixture {
  const char* file;
  const char* elementKind;
  const char* elementName;
  const char* fragment;
};

class UrdfLoaderBadInput : public ::testing::TestWithParam<BadFixture> {};

TEST_P(UrdfLoaderBadInput, NamesTheFileTheElementAndTheProblem) {
  const BadFixture& f = GetParam();
  const Result<Mechanism> result = loadMechanismFromFile(fixturePath(f.file));
  ASSERT_FALSE(isOk(result)) << f.file << " loaded";
  const Diagnostic& d = diagnosticOf(result);
  EXPECT_EQ(d.file, f.file);
  EXPECT_EQ(d.elementKind, f.elementKind) << d.toString();
  EXPECT_EQ(d.elementName, f.elementName) << d.toString();
  EXPECT_NE(d.what.find(f.fragment), std::string::npos) << d.toString();
  EXPECT_EQ(d.toString().find('\n'), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(
    EveryErrorClass, UrdfLoaderBadInput,
    ::testing::Values(BadFixture{"bad_xml.urdf", "xml", "", "not well-formed"},
                      BadFixture{"bad_not_robot.urdf", "xml", "", "not <robot>"},
                      BadFixture{"bad_unknown_link.urdf", "loop_joint", "j4", "'rockr' is not a link"},
                      BadFixture{"bad_two_parents.urdf", "joint", "j5", "already has a parent"},
                      BadFixture{"bad_number.urdf", "joint", "j2", "'abc'"},
                      BadFixture{"bad_nonfinite.urdf", "loop_joint", "j4", "not finite"},
                      BadFixture{"bad_zero_axis.urdf", "loop_joint", "j4", "zero vector"},
                      BadFixture{"bad_duplicate_name.urdf", "loop_joint", "j2", "name of another"},
                      BadFixture{"bad_disconnected.urdf", "link", "orphan", "not connected to the ground"},
                      BadFixture{"bad_loop_type.urdf", "loop_joint", "j4", "'hinge'"}),
    [](const ::testing::TestParamInfo<BadFixture>& info) {
      std::string name = info.param.file;
      return name.substr(0, name.find('.'));
    });

TEST(UrdfLoader, MissingFileIsADiagnostic) {
  const Result<Mechanism> result = loadMechanismFromFile("/nonexistent/x.urdf");
  ASSERT_FALSE(isOk(result));
  EXPECT_NE(diagnosticOf(result).toString().find("cannot open"), std::string::npos);
}

TEST(UrdfLoader, JointPositionsAreCheckedAgainstTheMechanism) {
  const Mechanism m = loadOrFail(fixturePath("four_bar_closed.urdf"));
  const Result<JointPositions> ok = parseJointPositions("j1=0.3,j3=-1", m);
  ASSERT_TRUE(isOk(ok));
  EXPECT_DOUBLE_EQ(valueOf(ok).at("j3"), -1.0);
  const Result<JointPositions> sizes = makeJointPositions({"j1", "j2"}, {0.1}, m);
  ASSERT_FALSE(isOk(sizes));
  EXPECT_NE(diagnosticOf(sizes).what.find("1 values for 2 joint_names"), std::string::npos);
  const Result<JointPositions> unknown = parseJointPositions("j9=1", m);
  ASSERT_FALSE(isOk(unknown));
  EXPECT_EQ(diagnosticOf(unknown).elementName, "j9");
  const Result<JointPositions> loop = parseJointPositions("j4=1", m);
  ASSERT_FALSE(isOk(loop));
  EXPECT_NE(diagnosticOf(loop).what.find("loop_joint"), std::string::npos);
  EXPECT_FALSE(isOk(makeJointPositions({"j1"}, {std::nan("")}, m)));
  EXPECT_FALSE(isOk(parseJointPositions("j1=abc", m)));
}
