#include "mobility_analysis/UrdfLoader.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "../../src/core/io/NameIndex.hpp"
#include "../../src/core/io/XmlValues.hpp"
#include "core/TestModels.hpp"
#include "mobility_analysis/io/ReadMechanism.hpp"
#include "mobility_analysis/io/SdfReader.hpp"

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
  for (const Joint& j : m.joints)
    names.push_back(j.name);
  // Tree joints in document order, then distance constraints, cables, loop joints (DESIGN.md §3).
  EXPECT_EQ(names, (std::vector<std::string>{"r", "p", "fx", "pl", "fl", "cont", "fl2", "dist", "cab", "lr",
                                             "lp", "lc", "ls", "lu", "lf"}));
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
  EXPECT_TRUE(
      lr.frame2.linear().isApprox(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()).toRotationMatrix()));
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

// --- The reader's number triples and its index of names (io/UrdfReader.cpp, io/NameIndex.hpp) -------------

namespace {

/// A one-joint robot whose joint origin is xyz="@p xyz".
std::string originUrdf(const std::string& xyz) {
  return "<robot name=\"o\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"fixed\"><parent "
         "link=\"a\"/><child link=\"b\"/><origin xyz=\"" +
         xyz + "\"/></joint></robot>";
}

}  // namespace

TEST(UrdfLoader, aNumberTripleIsThreeBlankSeparatedFiniteNumbersAndNothingElse) {
  struct Case {
    std::string xyz;
    Eigen::Vector3d value;  // when fragment is empty
    std::string fragment;   // of the diagnostic, else
  };
  const std::vector<Case> cases = {
      // Three single digits: the reader's short cut; next to it, the general loop.
      {"1 2 3", {1, 2, 3}, ""},
      {"1 2 34", {1, 2, 34}, ""},
      {"7 8 9 ", {7, 8, 9}, ""},
      {"1 2 ", {}, "needs 3 numbers, got 2: '1 2 '"},
      {"1 2 3 x", {}, "has more than 3 numbers: '1 2 3 x'"},
      {"\t-1.5\n2e-3   +3 ", {-1.5, 2e-3, 3}, ""},  // every blank separates, leading and trailing ones too
      {"\r\n 0x10 0 .5\f", {16, 0, 0.5}, ""},       // strtod's forms, as before
      {"1 2", {}, "needs 3 numbers, got 2: '1 2'"},
      {"", {}, "needs 3 numbers, got 0"},
      {" \t ", {}, "needs 3 numbers, got 0"},
      {"1 2 3 4", {}, "has more than 3 numbers: '1 2 3 4'"},
      {"1 2 x", {}, "is not a number triple ('x')"},
      {"1 2 3x", {}, "is not a number triple ('3x')"},
      {"1,2,3", {}, "is not a number triple ('1,2,3')"},
      {"1 2 inf", {}, "is not finite"},
      {"1e400 0 0", {}, "is not finite"},
      {"0 2e12 0", {}, "outside the accepted range"},
  };
  for (const Case& c : cases) {
    const Result<Mechanism> result = loadMechanismFromString(originUrdf(c.xyz), "o.urdf");
    if (c.fragment.empty()) {
      ASSERT_TRUE(isOk(result)) << "'" << c.xyz << "': " << diagnosticOf(result).toString();
      EXPECT_EQ(valueOf(result).joints[0].frame1.translation(), c.value) << "'" << c.xyz << "'";
    } else {
      ASSERT_FALSE(isOk(result)) << "'" << c.xyz << "' was read";
      const Diagnostic& d = diagnosticOf(result);
      EXPECT_EQ(d.elementName, "j");
      EXPECT_NE(d.what.find("origin xyz"), std::string::npos) << d.toString();
      EXPECT_NE(d.what.find(c.fragment), std::string::npos) << "'" << c.xyz << "': " << d.toString();
    }
  }
}

TEST(UrdfLoader, namesResolveAmongThousandsWrittenInAnyOrder) {
  // A random tree of 3000 links, links and joints each written in a shuffled order, closed by loop joints and
  // tied by a mimic: every end must be the link of that name, every connection in equation order.
  std::mt19937 random(13);
  const int n = 3000;
  std::vector<int> parent(n, -1);
  for (int l = 1; l < n; ++l)
    parent[l] = std::uniform_int_distribution<int>(0, l - 1)(random);
  auto linkName = [](int l) {
    return l == 0 ? std::string("ground") : "l" + std::to_string(l * 7919 % 100003);
  };
  std::vector<int> linkOrder(n), jointOrder(n - 1);
  std::iota(linkOrder.begin(), linkOrder.end(), 0);
  std::iota(jointOrder.begin(), jointOrder.end(), 1);
  std::shuffle(linkOrder.begin(), linkOrder.end(), random);
  std::shuffle(jointOrder.begin(), jointOrder.end(), random);
  std::string text = "<robot name=\"many\">\n";
  for (int l : linkOrder)
    text += "<link name=\"" + linkName(l) + "\"/>\n";
  std::vector<std::pair<int, int>> loops;
  for (int k = 0; k < 50; ++k) {
    const int a = std::uniform_int_distribution<int>(0, n - 1)(random);
    const int b = std::uniform_int_distribution<int>(0, n - 1)(random);
    if (a != b)
      loops.emplace_back(a, b);
  }
  for (size_t k = 0; k < loops.size();
       ++k) {  // loops before the tree joints in the document: order is by kind
    text += "<loop_joint name=\"loop" + std::to_string(k) + "\" type=\"spherical\"><link1 link=\"" +
            linkName(loops[k].first) + "\"/><link2 link=\"" + linkName(loops[k].second) +
            "\"/></loop_joint>\n";
  }
  for (int l : jointOrder) {
    text += "<joint name=\"j" + std::to_string(l) + "\" type=\"revolute\"><parent link=\"" +
            linkName(parent[l]) + "\"/><child link=\"" + linkName(l) + "\"/><axis xyz=\"0 0 1\"/>" +
            (l == jointOrder[0] ? "<mimic joint=\"j" + std::to_string(jointOrder[1]) + "\"/>" : "") +
            "</joint>\n";
  }
  text += "</robot>\n";
  const Result<Mechanism> result = loadMechanismFromString(text, "many.urdf");
  ASSERT_TRUE(isOk(result)) << diagnosticOf(result).toString();
  const Mechanism& m = valueOf(result);
  ASSERT_EQ(m.links.size(), static_cast<size_t>(n));
  ASSERT_EQ(m.joints.size(), static_cast<size_t>(n - 1) + loops.size() + 1);
  for (int i = 0; i < n; ++i)
    EXPECT_EQ(m.links[i].name, linkName(linkOrder[i]));
  EXPECT_EQ(m.links[m.rootLink].name, "ground");
  for (int k = 0; k < n - 1; ++k) {
    const Joint& joint = m.joints[k];
    const int l = jointOrder[k];
    EXPECT_EQ(joint.name, "j" + std::to_string(l));
    EXPECT_EQ(m.links[joint.link1].name, linkName(parent[l]));
    EXPECT_EQ(m.links[joint.link2].name, linkName(l));
  }
  for (size_t k = 0; k < loops.size(); ++k) {
    const Joint& joint = m.joints[n - 1 + k];
    EXPECT_EQ(joint.kind, ConnectionKind::LoopJoint);
    EXPECT_EQ(m.links[joint.link1].name, linkName(loops[k].first));
    EXPECT_EQ(m.links[joint.link2].name, linkName(loops[k].second));
  }
  const Joint& mimic = m.joints.back();
  EXPECT_EQ(mimic.kind, ConnectionKind::Coupling);
  EXPECT_EQ(m.joints[mimic.follower].name, "j" + std::to_string(jointOrder[0]));
  EXPECT_EQ(m.joints[mimic.leader].name, "j" + std::to_string(jointOrder[1]));
  for (const std::string& name : {std::string("ground"), linkName(n - 1), linkName(n / 2)})
    EXPECT_EQ(m.links[*m.findLink(name)].name, name);
}

TEST(UrdfLoader, aNameIsRefusedWhereverItWasUsedBefore) {
  const std::string head = "<robot name=\"d\"><link name=\"a\"/><link name=\"b\"/><link name=\"c\"/>";
  const std::string j1 =
      "<joint name=\"j1\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/>"
      "<axis xyz=\"0 0 1\"/></joint>";
  const std::string j2 =
      "<joint name=\"j2\" type=\"revolute\"><parent link=\"b\"/><child link=\"c\"/>"
      "<axis xyz=\"0 0 1\"/></joint>";
  auto loop = [](const std::string& name) {
    return "<loop_joint name=\"" + name +
           "\" type=\"spherical\"><link1 link=\"a\"/><link2 link=\"c\"/></loop_joint>";
  };
  struct Case {
    std::string body, kind, name, fragment;
  };
  const std::vector<Case> cases = {
      {"<link name=\"b\"/>" + j1 + j2, "link", "b", "is defined twice"},
      {j1 + j2 + "<joint name=\"j1\" type=\"fixed\"><parent link=\"a\"/><child link=\"c\"/></joint>", "joint",
       "j1", "is defined twice"},
      {j1 + j2 + loop("j2"), "loop_joint", "j2", "has the name of another joint or constraint"},
      {j1 + j2 + loop("x") + loop("x"), "loop_joint", "x", "has the name of another joint or constraint"},
      {j1 + j2 +
           "<distance_constraint name=\"x\"><link1 link=\"a\"/><link2 link=\"c\"/></distance_constraint>" +
           loop("x"),
       "loop_joint", "x", "has the name of another joint or constraint"},
      {j1 + j2 + loop("x") +
           "<coupling name=\"x\"><leader joint=\"j1\"/><follower joint=\"j2\"/><ratio "
           "value=\"1\"/></coupling>",
       "coupling", "x", "has the name of another joint or constraint"},
      {j1 + j2 + loop("x") +
           "<coupling name=\"c\"><leader joint=\"x\"/><follower joint=\"j2\"/><ratio "
           "value=\"1\"/></coupling>",
       "coupling", "c", "predecessor 'x' is not a tree joint"},
      {j1 + j2 +
           "<coupling name=\"c\"><leader joint=\"j9\"/><follower joint=\"j2\"/><ratio "
           "value=\"1\"/></coupling>",
       "coupling", "c", "predecessor 'j9' is not a tree joint"},
      {j1 + "<joint name=\"j2\" type=\"revolute\"><parent link=\"b\"/><child link=\"cc\"/></joint>", "joint",
       "j2", "child 'cc' is not a link"},
  };
  for (const Case& c : cases) {
    const Result<Mechanism> result = loadMechanismFromString(head + c.body + "</robot>", "d.urdf");
    ASSERT_FALSE(isOk(result)) << c.body;
    const Diagnostic& d = diagnosticOf(result);
    EXPECT_EQ(d.elementKind, c.kind) << d.toString();
    EXPECT_EQ(d.elementName, c.name) << d.toString();
    EXPECT_NE(d.what.find(c.fragment), std::string::npos) << d.toString();
  }
}

TEST(NameIndex, findsEveryNameGivenThroughGrowthAndNoOther) {
  struct Named {
    std::string name;
  };
  std::vector<Named> items;
  io_detail::NameIndex index;  // no reserve: it grows from empty
  EXPECT_EQ(index.find("x", items), -1);
  for (int i = 0; i < 5000; ++i) {
    items.push_back(Named{"n" + std::to_string(i * 31 % 5003)});
    ASSERT_EQ(index.find(items.back().name, items), -1);
    index.insert(items.back().name, i);
  }
  for (int i = 0; i < 5000; ++i)
    EXPECT_EQ(index.find(items[i].name, items), i);
  EXPECT_EQ(index.find("n", items), -1);
  EXPECT_EQ(index.find("", items), -1);
  EXPECT_EQ(index.find("n5002x", items), -1);
}

TEST(NameIndex, findOrInsertGivesTheIndexOfANameGivenAndClaimsANewOne) {
  struct Named {
    std::string name;
  };
  std::vector<Named> items;
  io_detail::NameIndex index;  // no reserve: it grows from empty, between a claim and its append too
  for (int i = 0; i < 5000; ++i) {
    const std::string name = "n" + std::to_string(i * 31 % 5003);
    ASSERT_EQ(index.findOrInsert(name, i, items), -1);  // claimed for the item appended next
    items.push_back(Named{name});
    ASSERT_EQ(index.findOrInsert(name, -7, items), i);  // given: found, nothing inserted
  }
  for (int i = 0; i < 5000; ++i)
    EXPECT_EQ(index.find(items[i].name, items), i);
  EXPECT_EQ(index.find("n5002x", items), -1);
}

TEST(ReadMechanism, theFormatIsToldByTheRootHoweverLongTheProlog) {
  // The root element is looked for in the file's head (64 KiB) and in the whole file when the head ends
  // before it, or inside its name: a URDF and an SDF behind a long comment, with the name cut at every spot
  // around the boundary, are each read by their own reader.
  const std::string urdf =
      "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" "
      "type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/><axis xyz=\"0 0 1\"/>"
      "</joint></robot>\n";
  const std::string sdf = "<sdf version=\"1.9\"><model name=\"s\"><link name=\"a\"/></model></sdf>\n";
  for (const size_t prolog :
       {size_t(0), size_t(100), size_t(65536 - 20), size_t(65536 - 7), size_t(65536 - 5), size_t(65536 - 3),
        size_t(65536 - 1), size_t(65536), size_t(200000)}) {
    for (const bool isSdf : {false, true}) {
      // "<?xml?>\n<!--" + padding + "-->\n" is exactly `prolog` characters (at least the markup's own).
      const std::string start = "<?xml version=\"1.0\"?>\n<!--", end = "-->\n";
      const size_t pad = prolog > start.size() + end.size() ? prolog - start.size() - end.size() : 0;
      const std::string text =
          (prolog == 0 ? "" : start + std::string(pad, 'x') + end) + (isSdf ? sdf : urdf);
      const std::string path = ::testing::TempDir() + "prolog_" + std::to_string(prolog) + ".urdf";
      {
        std::ofstream out(path);
        out << text;
      }
      const Result<Mechanism> read = readMechanism(path, ReadOptions{});
      if (isSdf) {
        // Not <robot>: the SDF reader answers, and this .urdf has no SDF model it can read as a URDF.
        const Result<Mechanism> bySdf = readSdf(text, path);
        ASSERT_EQ(isOk(read), isOk(bySdf)) << prolog;
        if (!isOk(read))
          EXPECT_EQ(diagnosticOf(read).toString(), diagnosticOf(bySdf).toString()) << prolog;
        else
          EXPECT_EQ(valueOf(read).name, valueOf(bySdf).name) << prolog;
      } else {
        ASSERT_TRUE(isOk(read)) << prolog << ": " << diagnosticOf(read).toString();
        EXPECT_EQ(valueOf(read).name, "r");
        EXPECT_EQ(valueOf(read).joints.size(), 1u);
        EXPECT_EQ(valueOf(read).file, "prolog_" + std::to_string(prolog) + ".urdf");
      }
      std::remove(path.c_str());
    }
  }
}

TEST(ReadMechanism, aDirectoryOrAMissingFileCannotBeOpened) {
  for (const std::string& path : {::testing::TempDir(), std::string("/nonexistent/x.urdf")}) {
    for (const Result<Mechanism>& read : {readMechanism(path, ReadOptions{}), loadMechanismFromFile(path)}) {
      ASSERT_FALSE(isOk(read)) << path;
      EXPECT_NE(diagnosticOf(read).what.find("cannot open the file"), std::string::npos)
          << diagnosticOf(read).toString();
    }
  }
}

TEST(XmlValues, everyNumberIsTheDoubleStrtodReads) {
  // The fast path (std::from_chars) must give strtod's double bit for bit wherever it answers: random doubles
  // of every magnitude (subnormals too) in the forms files use, and strtod's own forms behind it.
  std::mt19937_64 random(13);
  std::vector<std::string> texts = {"0",     "-0",      "1e-320", "4.9e-324", "2.2250738585072014e-308",
                                    "1e308", ".5",      "5.",     "+1",       "0x1p3",
                                    "1e400", "-1e-400", "nan",    "inf",      "-Infinity"};
  for (int i = 0; i < 20000; ++i) {
    double value = 0.0;
    const uint64_t bits = random();
    std::memcpy(&value, &bits, sizeof(value));
    if (!std::isfinite(value))
      continue;
    char text[64];
    std::snprintf(text, sizeof(text), i % 3 == 0 ? "%.17g" : i % 3 == 1 ? "%.6e" : "%.3f", value);
    texts.push_back(text);
    std::snprintf(text, sizeof(text), "%.15g", static_cast<double>(random() % 100000) / 1000.0);
    texts.push_back(text);
  }
  for (const std::string& text : texts) {
    char* end = nullptr;
    const double expected = std::strtod(text.c_str(), &end);
    const std::optional<double> got = io_detail::parseNumber(text.data(), text.data() + text.size());
    ASSERT_EQ(got.has_value(), *end == '\0') << text;
    if (got && !std::isnan(expected))
      EXPECT_EQ(std::memcmp(&*got, &expected, sizeof(double)), 0)
          << text << ": " << *got << " vs " << expected;
  }
  for (const char* digit : {"0", "1", "7", "9"})
    EXPECT_EQ(io_detail::parseNumber(digit, digit + 1), std::strtod(digit, nullptr));
  EXPECT_FALSE(io_detail::parseNumber("1e", std::strchr("1e", '\0')));
  EXPECT_FALSE(io_detail::parseDouble(" 1 2"));
  EXPECT_EQ(io_detail::parseDouble("\v 2.5\r\n"), 2.5);
}

TEST(UrdfLoader, aLargeFileChecksItsXmlOnASecondThreadWithTheSameAnswer) {
  // From 1 MB the well-formedness walk runs beside the reader (ReadOptions::sideThread): its fault must still
  // come first, whatever the reader finds, and a sound file must read the same. A 10^4-link chain (about 2
  // MB) with, at its end, a repeated attribute; text outside the root; a repeated attribute and a joint to an
  // unknown link (the reader's error, which the XML fault outranks); the unknown link alone; nothing wrong.
  const std::string chain = straightChainUrdf(10000);
  ASSERT_GT(chain.size(), size_t{1} << 20);
  const std::string body = chain.substr(0, chain.rfind("</robot>"));
  const std::string unknown =
      R"(<joint name="bad" type="fixed"><parent link="nowhere"/><child link="l1"/></joint>)";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {body + R"(<link name="x" name="y"/></robot>)", "attribute 'name' given twice in <link>"},
      {chain + "trailing", "text outside the root element"},
      {body + unknown + R"(<link name="x" name="y"/></robot>)", "attribute 'name' given twice in <link>"},
      {body + unknown + "</robot>", "nowhere"},
      {chain, ""}};
  for (const auto& [text, fragment] : cases) {
    const std::string path = ::testing::TempDir() + "large_xml_check.urdf";
    std::ofstream(path) << text;
    ReadOptions one, two;
    one.sideThread = false;
    two.sideThread = true;
    const std::pair<Result<Mechanism>, Result<Mechanism>> reads[] = {
        {readMechanism(path, two), readMechanism(path, one)},
        {readMechanismFromString(text, "x.urdf", two), readMechanismFromString(text, "x.urdf", one)}};
    for (const auto& [read, reference] : reads) {
      if (fragment.empty()) {
        ASSERT_TRUE(isOk(read)) << diagnosticOf(read).toString();
        ASSERT_TRUE(isOk(reference));
        EXPECT_EQ(valueOf(read).links.size(), valueOf(reference).links.size());
        EXPECT_EQ(valueOf(read).joints.size(), 10000u);
      } else {
        ASSERT_FALSE(isOk(read)) << fragment;
        EXPECT_NE(diagnosticOf(read).toString().find(fragment), std::string::npos)
            << diagnosticOf(read).toString();
        ASSERT_FALSE(isOk(reference));
        EXPECT_EQ(diagnosticOf(read).what, diagnosticOf(reference).what);
      }
    }
  }
}

TEST(UrdfLoader, whatIsNotWellFormedXmlIsRefusedAndTextIsReadAsWritten) {
  const std::string tree =
      R"(<link name="a"/><link name="b"/><joint name="j" type="revolute"><parent link="a"/>)"
      R"(<child link="b"/><axis xyz="0 0 1"/></joint>)";
  // XML 1.0 §2.1, §3.1: one root, no text outside it, each attribute once, a blank between attributes.
  const std::vector<std::pair<std::string, std::string>> refused = {
      {"<robot name=\"r\">" + tree + "</robot>trailing", "text outside the root element at line 1"},
      {"before<robot name=\"r\">" + tree + "</robot>", "text outside the root element"},
      {"<robot name=\"r\" name=\"s\">" + tree + "</robot>", "attribute 'name' given twice in <robot>"},
      {"<robot name=\"r\">\n" + tree +
           "\n<link name=\"c\"><visual><box size=\"1\" size=\"2\"/></visual></link></robot>",
       "attribute 'size' given twice in <box> at line 3"},
      {"<robot name=\"r\">" + tree + "<link name=\"c\"><box a=\"1\" b=\"2\" a=\"3\"/></link></robot>",
       "attribute 'a' given twice in <box>"},
      // Past the eight names gathered: the ninth and later are compared through pugixml.
      {"<robot name=\"r\">" + tree +
           "<link name=\"c\"><box a1=\"\" a2=\"\" a3=\"\" a4=\"\" a5=\"\" a6=\"\" a7=\"\" a8=\"\" a9=\"\" "
           "a10=\"\" a9=\"\"/></link></robot>",
       "attribute 'a9' given twice in <box>"},
      {"<robot name=\"r\">" + tree +
           "<link name=\"c\"><box a1=\"\" a2=\"\" a3=\"\" a4=\"\" a5=\"\" a6=\"\" a7=\"\" a8=\"\" a9=\"\" "
           "a2=\"\"/></link></robot>",
       "attribute 'a2' given twice in <box>"},
      {"<robot name=\"r\" x=\"1\"y=\"2\">" + tree + "</robot>", "not well-formed XML"},
      {"<robot name=\"r\">" + tree + "</robot></robot>", "not well-formed XML"},
      {"<robot name=\"r\">\n" + tree + "\n", "not well-formed XML"},
      {"<!-- nothing else -->", "No document element found"},
      {"", "No document element found"},
  };
  for (const auto& [text, fragment] : refused) {
    const Result<Mechanism> read = loadMechanismFromString(text, "x.urdf");
    ASSERT_FALSE(isOk(read)) << text;
    EXPECT_EQ(diagnosticOf(read).elementKind, "xml") << text;
    EXPECT_NE(diagnosticOf(read).what.find(fragment), std::string::npos) << diagnosticOf(read).toString();
  }
  // Entities decoded, CDATA and a processing instruction after the root allowed, blanks inside an attribute
  // kept as written but for line ends (\r\n and \r become \n), as tinyxml2 read them.
  const std::string text =
      "<?xml version=\"1.0\"?>\n<!DOCTYPE robot>\n<robot name=\"a&amp;b&#65;\">"
      "<link name=\"t\tab\"/><link name=\"l\r\nf\"/>"
      "<joint name=\"j\" type=\"revolute\"><parent link=\"t\tab\"/><child link=\"l\nf\"/>"
      "<axis xyz=\"0 0 1\"/><![CDATA[ignored]]></joint></robot>\n<?pi after?>\n";
  const Result<Mechanism> read = loadMechanismFromString(text, "x.urdf");
  ASSERT_TRUE(isOk(read)) << diagnosticOf(read).toString();
  EXPECT_EQ(valueOf(read).name, "a&bA");
  EXPECT_EQ(valueOf(read).links[0].name, "t\tab");
  EXPECT_EQ(valueOf(read).links[1].name, "l\nf");
}

TEST(XmlValues, aZeroRollPitchYawGivesTheGeneralFormulasIdentityBitForBit) {
  const Eigen::Vector3d xyz(0.1, -2, 3e-5);
  const auto sameBits = [](const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
    return std::memcmp(a.matrix().data(), b.matrix().data(), 16 * sizeof(double)) == 0;
  };
  for (const Eigen::Vector3d& rpy : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(-0.0, 0, 0),
                                     Eigen::Vector3d(0, 0, -0.0), Eigen::Vector3d(0.3, -1.2, 2.5)}) {
    Eigen::Isometry3d expected = Eigen::Isometry3d::Identity();
    expected.linear() = io_detail::originRotation(rpy);  // the general formula, always
    expected.translation() = xyz;
    EXPECT_TRUE(sameBits(io_detail::makeOriginFrame(xyz, rpy), expected)) << rpy.transpose();
    expected.linear() = io_detail::rollPitchYaw(rpy);  // and the loop elements' angle-axis product
    EXPECT_TRUE(sameBits(io_detail::makeFrame(xyz, rpy), expected)) << rpy.transpose();
  }
}
