#pragma once

#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "mobility_analysis/mobility_analysis.hpp"

namespace mobility_analysis {

inline std::string urdfPath(const std::string& name) {
  return std::string(MA_URDF_DIR) + "/" + name;
}
inline std::string fixturePath(const std::string& name) {
  return std::string(MA_FIXTURE_DIR) + "/" + name;
}

/// Loads a file that must load; fails the test with the diagnostic otherwise.
inline Mechanism loadOrFail(const std::string& path) {
  Result<Mechanism> mechanism = loadMechanismFromFile(path);
  if (!isOk(mechanism)) {
    ADD_FAILURE() << diagnosticOf(mechanism).toString();
    return Mechanism{};
  }
  return valueOf(std::move(mechanism));
}

/// Analyses @p mechanism in @p mode; fails the test with the diagnostic when it cannot.
inline MobilityAnalysis analyzeOrFail(const Mechanism& mechanism, AnalysisMode mode) {
  AnalysisOptions options;
  options.mode = mode;
  Result<MobilityAnalysis> analysis = analyzeMechanism(mechanism, options);
  if (!isOk(analysis)) {
    ADD_FAILURE() << diagnosticOf(analysis).toString();
    return MobilityAnalysis{};
  }
  return valueOf(std::move(analysis));
}

/// Analyses a file in @p mode; fails the test with the diagnostic when it cannot.
inline MobilityAnalysis analyzeOrFail(const std::string& path, AnalysisMode mode) {
  return analyzeOrFail(loadOrFail(path), mode);
}

/// @p actual's counts are @p expected's: DOF, finite and passive DOF, Grübler, redundant equations, singular.
inline void expectSameCounts(const MobilityReport& expected, const MobilityReport& actual) {
  EXPECT_EQ(actual.dof, expected.dof);
  EXPECT_EQ(actual.finiteDof, expected.finiteDof);
  EXPECT_EQ(actual.passiveDof, expected.passiveDof);
  EXPECT_EQ(actual.grublerKutzbachDof, expected.grublerKutzbachDof);
  EXPECT_EQ(actual.numRedundant, expected.numRedundant);
  EXPECT_EQ(actual.singular, expected.singular);
}

/// A mechanism assembled from its written (tree) pose, with the constraint Jacobian there.
struct ModelAtTreePose {
  Mechanism mechanism;
  AssembledMechanism assembled;
  SparseJacobian J;
};

/// Assembles @p mechanism in @p mode from its tree pose; fails the test with the diagnostic when it cannot.
inline ModelAtTreePose assembleAtTreePose(Mechanism mechanism, AnalysisMode mode) {
  ModelAtTreePose model;
  model.mechanism = std::move(mechanism);
  Result<AssembledMechanism> assembled =
      assembleMechanism(model.mechanism, computeTreePoses(model.mechanism, {}), mode);
  EXPECT_TRUE(isOk(assembled)) << diagnosticOf(assembled).toString();
  model.assembled = valueOf(std::move(assembled));
  model.J = computeConstraintJacobian(model.assembled.model, model.assembled.q);
  return model;
}

/// @p urdf with its root link welded, at @p offset ("x y z" [m]) and turned, to a new root: the same
/// mechanism far from the origin of the model.
inline std::string placedAt(const std::string& urdf, const std::string& offset) {
  const size_t root = urdf.find("<link name=\"");
  const size_t nameStart = root + 12;
  const std::string name = urdf.substr(nameStart, urdf.find('"', nameStart) - nameStart);
  return urdf.substr(0, root) +
         "<link name=\"far_world\"/><joint name=\"far\" type=\"fixed\"><parent link=\"" +
         "far_world\"/><child link=\"" + name + "\"/><origin xyz=\"" + offset +
         "\" rpy=\"0.3 0.2 0.1\"/></joint>\n" + urdf.substr(root);
}

/// A straight chain of @p links revolute joints about z, 0.1 m apart: DOF @p links in the plane and in space.
inline std::string straightChainUrdf(int links) {
  std::string text = "<robot name='chain'><link name='l0'/>";
  text.reserve(static_cast<size_t>(links) * 160);
  for (int i = 1; i <= links; ++i) {
    const std::string n = std::to_string(i), p = std::to_string(i - 1);
    text += "<link name='l" + n + "'/><joint name='j" + n + "' type='revolute'><parent link='l" + p +
            "'/><child link='l" + n + "'/><origin xyz='0.1 0 0'/><axis xyz='0 0 1'/></joint>";
  }
  return text + "</robot>";
}

/// A URDF with one joint of every kind the dialect knows; its loops need not close (Jacobian tests).
inline const char* allJointKindsUrdf() {
  return R"(<robot name="all_kinds">
  <link name="ground"/><link name="a"/><link name="b"/><link name="c"/><link name="d"/><link name="e"/>
  <link name="f"/><link name="g"/>
  <joint name="r" type="revolute"><parent link="ground"/><child link="a"/><origin xyz="0.1 0.2 0.3" rpy="0.1 0.2 0.3"/>
    <axis xyz="0 0.6 0.8"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="p" type="prismatic"><parent link="a"/><child link="b"/><origin xyz="0.5 0 0" rpy="0 0.4 0"/>
    <axis xyz="1 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="fx" type="fixed"><parent link="b"/><child link="c"/><origin xyz="0 0.3 0.1" rpy="0.3 0 0"/></joint>
  <joint name="pl" type="planar"><parent link="c"/><child link="d"/><origin xyz="0.2 0 0.2"/><axis xyz="0 0 1"/></joint>
  <joint name="fl" type="floating"><parent link="ground"/><child link="e"/><origin xyz="0.4 0.4 0.4"/></joint>
  <joint name="cont" type="continuous"><parent link="ground"/><child link="f"/><origin xyz="-0.3 0.1 0"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="fl2" type="floating"><parent link="ground"/><child link="g"/><origin xyz="0.1 -0.4 0.2"/></joint>
  <distance_constraint name="dist"><link1 link="a" xyz="0.2 0 0"/><link2 link="e" xyz="0 0 0.1"/></distance_constraint>
  <cable name="cab" type="passive" length="10"><link1 link="f" xyz="0.1 0 0"/><link2 link="g" xyz="0 0 0"/></cable>
  <loop_joint name="lr" type="revolute"><link1 link="d" xyz="0.1 0 0"/><link2 link="e" xyz="0 0.1 0" rpy="0.2 0 0"/>
    <axis xyz="0 1 0"/></loop_joint>
  <loop_joint name="lp" type="prismatic"><link1 link="e" xyz="0 0 0.2"/><link2 link="f" xyz="0.1 0.1 0" rpy="0 0 0.5"/>
    <axis xyz="0 0 1"/></loop_joint>
  <loop_joint name="lc" type="cylindrical"><link1 link="f" xyz="0 0.2 0"/><link2 link="g" xyz="0.1 0 0"/>
    <axis xyz="1 0 0"/></loop_joint>
  <loop_joint name="ls" type="spherical"><link1 link="g" xyz="0 0 0.3"/><link2 link="b" xyz="0.1 0.1 0.1"/></loop_joint>
  <loop_joint name="lu" type="universal"><link1 link="c" xyz="0.3 0 0"/><link2 link="g" xyz="0 0.2 0"/>
    <axis xyz="1 0 0"/><axis2 xyz="0 1 0"/></loop_joint>
  <loop_joint name="lf" type="fixed"><link1 link="d" xyz="0 0.3 0"/><link2 link="f" xyz="0 0 0.3"/></loop_joint>
</robot>)";
}

}  // namespace mobility_analysis

namespace mobility_analysis {

/// A planar model with a pin, a slider, a weld and a distance constraint (Jacobian tests in the plane).
inline const char* planarJointKindsUrdf() {
  return R"(<robot name="planar_kinds">
  <link name="ground"/><link name="a"/><link name="b"/><link name="c"/><link name="d"/>
  <joint name="pin" type="revolute"><parent link="ground"/><child link="a"/><origin xyz="0 0 0" rpy="0 0 0.4"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="slide" type="prismatic"><parent link="a"/><child link="b"/><origin xyz="0.3 0 0" rpy="0 0 0.2"/>
    <axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="weld" type="fixed"><parent link="b"/><child link="c"/><origin xyz="0.1 0.1 0" rpy="0 0 0.3"/></joint>
  <joint name="pin2" type="revolute"><parent link="ground"/><child link="d"/><origin xyz="0.8 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <distance_constraint name="dist"><link1 link="c" xyz="0.1 0 0"/><link2 link="d" xyz="0 0.2 0"/></distance_constraint>
  <loop_joint name="loop_slide" type="prismatic"><link1 link="d" xyz="0 0.1 0"/><link2 link="a" xyz="0.2 0.05 0"/>
    <axis xyz="0 1 0"/></loop_joint>
</robot>)";
}

}  // namespace mobility_analysis
