#include "mobility_analysis/MobilityReport.hpp"

#include <limits>
#include <regex>
#include <sstream>
#include <string>
#include <variant>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "core/TestModels.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/FamilyRegistry.hpp"
#include "mobility_analysis/generators/ParametricFamilies.hpp"
#include "mobility_analysis/generators/ScalingFamilies.hpp"
// A private header of the core: toJson with its threshold for the second thread.
#include "../../src/core/JsonHalves.hpp"

using namespace mobility_analysis;

namespace {

/// The JSON without the fields that carry the unit or the file name.
std::string unitFree(std::string json) {
  // assembly.residual is in metres, the closure residuals and the rank margin's are rounding. The positions
  // stay: at the written pose they are its values exactly, in either unit.
  for (const char* key :
       {"robot", "file", "characteristic_length", "closure_residual", "rank_margin", "assembly"}) {
    json = std::regex_replace(json, std::regex(std::string("\\n  \"") + key + "\": [^\\n]*"), "");
  }
  return json;
}

/// @p description written as URDF without visuals and read back; fails the test when either step does.
Mechanism mechanismOf(const MechanismDescription& description) {
  UrdfWriterOptions noVisuals;
  noVisuals.visuals = false;
  const GeneratorResult<std::string> urdf = toClosedLoopUrdf(description, noVisuals);
  if (!std::holds_alternative<std::string>(urdf)) {
    ADD_FAILURE() << "the generator could not write " << description.name;
    return Mechanism{};
  }
  Result<Mechanism> mechanism =
      loadMechanismFromString(std::get<std::string>(urdf), description.name + ".urdf");
  if (!isOk(mechanism)) {
    ADD_FAILURE() << diagnosticOf(mechanism).toString();
    return Mechanism{};
  }
  return valueOf(std::move(mechanism));
}

/// The report of @p mechanism in @p mode, or the one line that refuses it.
std::string reportOrRefusal(const Mechanism& mechanism, AnalysisMode mode, bool lockActiveCables = false) {
  AnalysisOptions options;
  options.mode = mode;
  options.lockActiveCables = lockActiveCables;
  const Result<MobilityAnalysis> analysis = analyzeMechanism(mechanism, options);
  // Cable lengths and distances are in metres.
  static const std::regex cables("\\n  \"cables\": [^\\n]*");
  return isOk(analysis) ? std::regex_replace(unitFree(toJson(valueOf(analysis).report)), cables, "")
                        : diagnosticOf(analysis).toString();
}

}  // namespace

TEST(MobilityReport, JsonCarriesEveryDocumentedKey) {
  const MobilityReport report =
      analyzeOrFail(fixturePath("four_bar_closed.urdf"), AnalysisMode::Spatial).report;
  const std::string json = toJson(report);
  for (const char* key :
       {"\"robot\": \"four_bar\"", "\"mode\": \"spatial\"", "\"lambda\": 6", "\"dof\": 1",
        "\"grubler_kutzbach_dof\": -2",
        "\"num_coordinates\": ", "\"num_constraints\": ", "\"rank\": ", "\"nullity_trace\": [",
        "\"redundant_constraints\": [{\"index\": ", "\"source\": \"joint\", \"name\": \"j4\"",
        "\"redundant_joints\": [{\"name\": \"j4\", \"redundant_equations\": 3, \"equations\": 5}]",
        "\"redundant_links\": []", "\"redundant_boundaries\": []", "\"rank_margin\": {"}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << "\n" << json;
  }
  EXPECT_EQ(report.nullityTrace.size(), static_cast<size_t>(report.numConstraints));
  EXPECT_EQ(report.nullityTrace.back(), report.dof);
  EXPECT_EQ(report.rank, report.numConstraints - report.numRedundant);
}

TEST(MobilityReport, JsonEscapesNames) {
  MobilityReport report;
  report.robot = "a\"b\\c\n";
  EXPECT_NE(toJson(report).find("\"robot\": \"a\\\"b\\\\c\\n\""), std::string::npos);
}

TEST(MobilityReport, TextSaysDofGrublerAndTheRedundantJoint) {
  const std::string text =
      toText(analyzeOrFail(fixturePath("four_bar_closed.urdf"), AnalysisMode::Spatial).report);
  EXPECT_NE(text.find("degrees of freedom (nullity of the constraint Jacobian): 1"), std::string::npos)
      << text;
  EXPECT_NE(text.find("joint j4: 3 of 5 equations redundant"), std::string::npos) << text;
}

TEST(MobilityReport, BennettInMillimetresAndMetresGiveTheSameReport) {
  const MobilityReport metres = analyzeOrFail(urdfPath("bennett.urdf"), AnalysisMode::Auto).report;
  const MobilityReport millimetres = analyzeOrFail(urdfPath("bennett_mm.urdf"), AnalysisMode::Auto).report;
  EXPECT_EQ(unitFree(toJson(metres)), unitFree(toJson(millimetres)));
  EXPECT_NEAR(millimetres.characteristicLength / metres.characteristicLength, 1000.0, 1e-6);
  EXPECT_EQ(metres.dof, 1);
  EXPECT_EQ(metres.numRedundant, 3);
}

// The same model in metres, millimetres and kilometres gives the same report but for its units. Each family
// here broke it through its rounding before: a continuous-bar grid's states hold forces that agree to the
// last few bits (0.894427191 twice, 1 and 1 - 2^-53), listed in the order of those bits; a truss mast's and a
// ring pantograph's states hold cables pulling against each other with equal forces, and which was "largest"
// (tension positive) set the sign of the whole state; a braced lattice's prestress program has many optima,
// and which vertex Clp reached followed the states' last bits. Now ties to the nine digits printed keep the
// elements' order, and the program's coefficients are rounded to 2^-40.
struct ScaledFamily {
  const char* name;
  MechanismDescription (*make)();
  AnalysisMode mode;
  bool lockActiveCables;
};

void PrintTo(const ScaledFamily& family, std::ostream* out) {
  *out << family.name;
}

class SameReportInAnyUnit : public ::testing::TestWithParam<ScaledFamily> {};

TEST_P(SameReportInAnyUnit, OnlyTheUnitsDiffer) {
  const ScaledFamily& family = GetParam();
  auto mechanismAt = [&](double factor) {
    MechanismDescription description = family.make();
    scaleMechanism(description, factor);
    return mechanismOf(description);
  };
  const Mechanism metres = mechanismAt(1.0);
  const MobilityReport inMetres = analyzeOrFail(metres, family.mode).report;
  ASSERT_GT(inMetres.selfStress.count, 0);
  for (const double factor : {1000.0, 0.001}) {
    SCOPED_TRACE(factor);
    const Mechanism scaled = mechanismAt(factor);
    EXPECT_EQ(reportOrRefusal(metres, family.mode, family.lockActiveCables),
              reportOrRefusal(scaled, family.mode, family.lockActiveCables));
    EXPECT_NEAR(
        analyzeOrFail(scaled, family.mode).report.characteristicLength / inMetres.characteristicLength,
        factor, 1e-9 * factor);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Families, SameReportInAnyUnit,
    ::testing::Values(
        ScaledFamily{"grid", [] { return makeParallelogramGrid(3, 4); }, AnalysisMode::Auto, false},
        ScaledFamily{"truss", [] { return makeTrussMast(3); }, AnalysisMode::Spatial, false},
        ScaledFamily{"pantograph", [] { return makeRingPantograph(4, 60.0); }, AnalysisMode::Auto, false},
        ScaledFamily{"pantograph_locked", [] { return makeRingPantograph(4, 60.0); }, AnalysisMode::Auto,
                     true},
        ScaledFamily{"braced", [] { return makeBarLattice(3, 3, true); }, AnalysisMode::Auto, false}),
    [](const ::testing::TestParamInfo<ScaledFamily>& info) { return std::string(info.param.name); });

// Every family the generator knows, at a small size, in both modes: the same report at x1, x1000 and x0.001
// but for its units (the failure message names the family, the mode and the scale).
TEST(MobilityReport, EveryGeneratedFamilyGivesTheSameReportInAnyUnit) {
  int compared = 0;
  for (const FamilyInfo& family : listFamilies()) {
    GenerateRequest request;
    request.family = family.name;
    request.visuals = false;
    // The fewest counts it takes, each 3 (every family is closed and small there; a ring pantograph needs 3).
    request.counts.assign(static_cast<size_t>(family.minCounts), 3);
    for (const AnalysisMode mode : {AnalysisMode::Auto, AnalysisMode::Spatial}) {
      std::string first;
      for (const double factor : {1.0, 1000.0, 0.001}) {
        SCOPED_TRACE(family.name + (mode == AnalysisMode::Auto ? " auto x" : " spatial x") +
                     std::to_string(factor));
        request.scale = factor;
        const GeneratorResult<MechanismDescription> description = generateMechanism(request);
        ASSERT_TRUE(std::holds_alternative<MechanismDescription>(description));
        // A model that cannot be analysed in a mode says so in every unit alike.
        const std::string text =
            reportOrRefusal(mechanismOf(std::get<MechanismDescription>(description)), mode);
        if (factor == 1.0)
          first = text;
        else
          EXPECT_EQ(first, text);
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 150);  // about thirty families, two modes, three scales
}

// Turned in space (every world frame, point and axis of the description), a model keeps what does not depend
// on its axes: the counts, the redundant joints and links with their numbers of redundant equations, the
// element classes, the number of states and whether the cables can be prestressed. Which component of a
// vector equation is the redundant one (a pin's x or y) and the listed basis may change (README, Tolerances).
TEST(MobilityReport, TurnedInSpaceKeepsTheCountsAndTheRedundantJoints) {
  const Eigen::Matrix3d turn =
      (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  auto turned = [&](MechanismDescription m) {
    const Eigen::Isometry3d pose(turn);
    for (LinkDescription& link : m.links) {
      for (Eigen::Vector3d& point : link.visualPath)
        point = turn * point;
      if (link.floatingFrame)
        link.floatingFrame = pose * *link.floatingFrame;
    }
    for (Connection& c : m.connections) {
      c.frame = pose * c.frame;
      c.axis = turn * c.axis;
      c.axis2 = turn * c.axis2;
      c.point2 = turn * c.point2;
    }
    for (CableDescription& cable : m.cables) {
      cable.point1 = turn * cable.point1;
      cable.point2 = turn * cable.point2;
    }
    return m;
  };
  auto report = [](const MechanismDescription& m, AnalysisMode mode) {
    return analyzeOrFail(mechanismOf(m), mode).report;
  };
  const std::vector<std::pair<std::string, MechanismDescription>> families{
      {"grid", makeParallelogramGrid(3, 4)}, {"truss", makeTrussMast(3)},
      {"hoberman", makeHobermanRing(6)},     {"braced", makeBarLattice(3, 3, true)},
      {"sle", makeSleSpatialMast(3)},        {"door", makeDoor(4)}};
  for (const auto& [name, family] : families) {
    for (const AnalysisMode mode : {AnalysisMode::Auto, AnalysisMode::Spatial}) {
      SCOPED_TRACE(name + (mode == AnalysisMode::Auto ? " auto" : " spatial"));
      const MobilityReport a = report(family, mode), b = report(turned(family), mode);
      EXPECT_EQ(a.mode, b.mode);
      expectSameCounts(a, b);
      ASSERT_EQ(a.redundantJoints.size(), b.redundantJoints.size());
      for (size_t j = 0; j < a.redundantJoints.size(); ++j) {
        EXPECT_EQ(a.redundantJoints[j].name, b.redundantJoints[j].name);
        EXPECT_EQ(a.redundantJoints[j].redundantEquations, b.redundantJoints[j].redundantEquations);
      }
      EXPECT_EQ(a.redundantLinks, b.redundantLinks);
      ASSERT_EQ(a.joints.size(), b.joints.size());
      for (size_t j = 0; j < a.joints.size(); ++j)
        EXPECT_EQ(a.joints[j].elementClass, b.joints[j].elementClass) << a.joints[j].name;
      EXPECT_EQ(a.selfStress.count, b.selfStress.count);
      EXPECT_EQ(a.selfStress.prestressable, b.selfStress.prestressable);
    }
  }
}

TEST(MobilityReport, ElementClassesMarkTheLoopJointRedAndTheLoopOrange) {
  const MobilityReport report =
      analyzeOrFail(fixturePath("four_bar_closed.urdf"), AnalysisMode::Spatial).report;
  for (const ElementStatus& s : report.joints) {
    EXPECT_EQ(s.elementClass, s.name == "j4" ? ElementClass::Redundant : ElementClass::OverConstrainedLoop)
        << s.name;
  }
  for (const ElementStatus& s : report.links)
    EXPECT_EQ(s.elementClass, ElementClass::OverConstrainedLoop) << s.name;
  const MobilityReport planar =
      analyzeOrFail(fixturePath("four_bar_closed.urdf"), AnalysisMode::Planar).report;
  for (const ElementStatus& s : planar.joints)
    EXPECT_EQ(s.elementClass, ElementClass::Neutral) << s.name;
}

namespace {

/// A report whose one list @p which holds @p n items and whose others are short (or empty).
MobilityReport reportWithLong(const std::string& which, size_t n) {
  MobilityReport r = analyzeOrFail(urdfPath("ring_pantograph_deployed.urdf"), AnalysisMode::Planar).report;
  for (size_t i = 0; i < n; ++i) {
    const std::string name = "e\"" + std::to_string(i);  // escaped, of growing length
    if (which == "nullity_trace")
      r.nullityTrace.push_back(static_cast<int>(i));
    if (which == "redundant_constraints")
      r.redundantConstraints.push_back(
          RedundantConstraint{static_cast<int>(i), "joint", name, "x", "x_a = x_b"});
    if (which == "links")
      r.links.push_back(ElementStatus{name, "link", "link", ElementClass::Neutral});
    if (which == "joints")
      r.joints.push_back(ElementStatus{name, "joint", "revolute", ElementClass::Redundant});
    if (which == "positions")
      r.positions.push_back(JointValue{name, 0.1 * static_cast<double>(i)});
    if (which == "states")
      r.selfStress.states.push_back(
          SelfStressState{{ElementForce{name, "link", 1.0}, ElementForce{name, "cable", -0.5}}});
    if (which == "prestress")
      r.selfStress.prestress.push_back(ElementForce{name, "cable", 1.0 / static_cast<double>(i + 1)});
  }
  return r;
}

}  // namespace

TEST(MobilityReport, JsonInTwoHalvesIsTheSameText) {
  // A large report is written in two halves on two threads (core_detail::toJson), cut at about half its
  // estimated bytes: inside whichever list holds them, or between parts. Every place the cut can fall must
  // give the one-thread text: each list made long in turn, at sizes that move the cut along it, and the
  // bundled models as they are (their cut falls between small parts).
  for (const char* which : {"nullity_trace", "redundant_constraints", "links", "joints", "positions",
                            "states", "prestress", "none"}) {
    for (size_t n : {0, 1, 2, 7, 100, 5000}) {
      SCOPED_TRACE(std::string(which) + " " + std::to_string(n));
      const MobilityReport r = reportWithLong(which, n);
      const std::string one = core_detail::toJson(r, std::numeric_limits<size_t>::max());
      EXPECT_EQ(core_detail::toJson(r, 0), one);
      EXPECT_EQ(toJson(r), one);
    }
  }
  for (const char* file : {"bennett.urdf", "sle_deployable_deployed.urdf", "door.urdf"}) {
    const MobilityReport r = analyzeOrFail(urdfPath(file), AnalysisMode::Auto).report;
    EXPECT_EQ(core_detail::toJson(r, 0), core_detail::toJson(r, std::numeric_limits<size_t>::max())) << file;
  }
}

TEST(MobilityReport, JsonWrittenToAStreamIsTheSameText) {
  // writeJson to a stream passes the text on a chunk (1 MB) at a time as it is written, on one thread or
  // with the second half made on another: the stream must receive toJson's text whatever the size, and
  // wherever a chunk ends (the 60 000 links and states here are several chunks).
  for (const char* which : {"links", "states", "positions", "none"}) {
    for (size_t n : {0, 5, 60000}) {
      SCOPED_TRACE(std::string(which) + " " + std::to_string(n));
      const MobilityReport r = reportWithLong(which, n);
      const std::string expected = core_detail::toJson(r, std::numeric_limits<size_t>::max());
      for (size_t secondThreadFrom : {size_t{0}, std::numeric_limits<size_t>::max()}) {
        std::ostringstream out;
        core_detail::writeJson(r, out, secondThreadFrom);
        EXPECT_EQ(out.str(), expected);
      }
      std::ostringstream out;
      EXPECT_FALSE(writeJson(r, out).has_value());
      EXPECT_EQ(out.str(), expected);
    }
  }
  // A report writeJson refuses: its Diagnostic, and not a byte written.
  MobilityReport bad = reportWithLong("links", 100);
  bad.characteristicLength = std::numeric_limits<double>::quiet_NaN();
  std::ostringstream out;
  const std::optional<Diagnostic> refused = writeJson(bad, out);
  ASSERT_TRUE(refused.has_value());
  EXPECT_NE(refused->what.find("characteristic_length"), std::string::npos) << refused->toString();
  EXPECT_TRUE(out.str().empty());
}
