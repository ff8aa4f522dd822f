/// A large URDF is parsed in two halves on two threads, cut before a top-level element near its middle
/// (io/XmlHalves.hpp). Wherever the cut falls, the mechanism read, or the error, must be the file's read
/// whole: here every byte of small files is tried as the place the cut is looked for from.
#include <cctype>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/TestModels.hpp"
#include "TextFile.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/ScalingFamilies.hpp"
#include "mobility_analysis/io/UrdfReader.hpp"

#include "../../src/core/io/UrdfHalves.hpp"

using namespace mobility_analysis;

namespace {

/// Every number to the bit (hexadecimal floating point).
void put(std::ostringstream& out, double value) {
  char text[40];
  std::snprintf(text, sizeof text, " %a", value);
  out << text;
}

void put(std::ostringstream& out, const Eigen::Isometry3d& frame) {
  for (int i = 0; i < 12; ++i)
    put(out, frame.matrix()(i % 3, i / 3));
}

/// All a read gives: the mechanism, field by field and in order, with its warnings; or the error.
std::string describe(const Result<Mechanism>& read) {
  if (!isOk(read))
    return "error: " + diagnosticOf(read).toString();
  const Mechanism& m = valueOf(read);
  std::ostringstream out;
  out << m.name << " " << m.file << " root " << m.rootLink << "\n";
  for (const Link& link : m.links)
    out << "link " << link.name << "\n";
  for (const Joint& j : m.joints) {
    out << "joint " << j.name << " " << static_cast<int>(j.kind) << " " << static_cast<int>(j.type) << " "
        << j.link1 << " " << j.link2 << " " << static_cast<int>(j.cableType) << " " << j.leader << " "
        << j.follower;
    put(out, j.frame1);
    put(out, j.frame2);
    for (const Eigen::Vector3d& v : {j.axis, j.axis2})
      for (int i = 0; i < 3; ++i)
        put(out, v(i));
    for (double value : {j.length, j.multiplier, j.offset})
      put(out, value);
    out << "\n";
  }
  for (const Diagnostic& warning : m.warnings)
    out << "warning " << warning.toString() << "\n";
  return out.str();
}

/// A closed-loop URDF with what a cut may fall into: comments and CDATA holding lines like top-level
/// elements, a <transmission> whose <joint> starts a line at the top-level indentation, an unknown element
/// (a warning), attributes with '>' in them, a loop joint, a cable and a coupling.
std::string trickyUrdf() {
  return R"(<?xml version="1.0"?>
<!-- a comment before the root
  <link name="not_a_link"/>
-->
<robot name="tricky" note="a > b">
  <link name="ground"/>
  <link name="crank"/>
  <!--
  <joint name="commented" type="fixed"><parent link="ground"/><child link="crank"/></joint>
  -->
  <link name="coupler"/>
  <link name="rocker"/>
  <joint name="j1" type="revolute">
    <origin xyz="0 0 0" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
    <parent link="ground"/>
    <child link="crank"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <gazebo><![CDATA[
  <joint name="in_cdata" type="fixed">
  ]]></gazebo>
  <joint name="j2" type="revolute">
    <origin xyz="0.1 0 0"/>
<axis xyz="0 0 1"/>
    <parent link="crank"/>
    <child link="coupler"/>
  </joint>
  <transmission name="t">
  <joint name="j2"/>
  </transmission>
  <whatever/>
  <joint name="j3" type="revolute">
    <origin xyz="0.3 0.2 0"/>
    <axis xyz="0 0 1"/>
    <parent link="ground"/>
    <child link="rocker"/>
  </joint>
  <loop_joint name="j4" type="revolute">
    <link1 link="coupler" xyz="0.3 0 0"/>
    <link2 link="rocker" xyz="-0.1 0.2 0"/>
    <axis xyz="0 0 1"/>
  </loop_joint>
  <link name="tip"/>
  <joint name="j5" type="revolute"><origin xyz="0 0.1 0"/><axis xyz="0 0 1"/><parent link="rocker"/><child link="tip"/></joint>
  <coupling name="c"><predecessor joint="j1"/><successor joint="j5"/><ratio value="0.5"/></coupling>
</robot>
<!-- after the root -->
)";
}

/// The URDF the generator writes for a family's model (a line per top-level element).
std::string generatedUrdf(const MechanismDescription& model) {
  const GeneratorResult<std::string> urdf = toClosedLoopUrdf(model);
  EXPECT_TRUE(std::holds_alternative<std::string>(urdf));
  return std::holds_alternative<std::string>(urdf) ? std::get<std::string>(urdf) : std::string();
}

/// For every @p stride-th byte of @p text as the place the cut is looked for from: the read in halves
/// against the read whole. @return the places the file was cut at.
std::set<size_t> expectSameWhereverCut(const std::string& text, const std::string& name, size_t stride = 1) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path, std::ios::binary) << text;
  const std::string whole = describe(readUrdfFile(path, false));
  if (name.find("bad") == std::string::npos)
    EXPECT_EQ(whole.find("error: "), std::string::npos) << whole;
  std::set<size_t> cuts;
  for (size_t from = 0; from <= text.size(); from += stride) {
    size_t cut = 0;
    const std::string halves = describe(core_detail::readUrdfFileCutFrom(path, from, &cut));
    EXPECT_EQ(halves, whole) << name << " cut from byte " << from << " at " << cut;
    if (halves != whole)
      break;  // one place is enough to see
    if (cut > 0)
      cuts.insert(cut);
  }
  return cuts;
}

}  // namespace

TEST(UrdfHalves, aSoundFileReadsTheSameWhereverItIsCut) {
  // The tricky file, two bundled mechanisms and a chain: every cut taken gives the mechanism read whole,
  // and the file is cut (not only read whole) at most of its top-level links and joints.
  const std::set<size_t> cuts = expectSameWhereverCut(trickyUrdf(), "halves_tricky.urdf");
  EXPECT_GE(cuts.size(), 8u);  // the links and joints written at the top-level indentation
  for (size_t cut : cuts)
    EXPECT_TRUE(trickyUrdf()[cut] == '<' && std::isalpha(trickyUrdf()[cut + 1])) << cut;
  // A second <robot> after the first (the whole read takes the first): a cut in the second must not join
  // its links to the first's. Either half then holds two elements at its top, and the file is read whole.
  EXPECT_TRUE(expectSameWhereverCut(trickyUrdf() + "<robot name=\"second\">\n  <link name=\"s1\"/>\n" +
                                         "  <link name=\"s2\"/>\n</robot>\n",
                                     "halves_two_robots.urdf")
                   .empty());
  // Latin-1, declared: pugixml converts the whole text; a second half read as UTF-8 would keep the bytes.
  std::string latin1 = trickyUrdf();
  latin1.replace(0, latin1.find('\n'), "<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>");
  latin1.replace(latin1.find("name=\"tip\""), 10, "name=\"t\xe9p\"");
  latin1.replace(latin1.find("<child link=\"tip\""), 17, "<child link=\"t\xe9p\"");
  EXPECT_TRUE(expectSameWhereverCut(latin1, "halves_latin1.urdf").empty());
  for (const char* file : {"bennett.urdf", "sle_deployable_deployed.urdf"}) {
    EXPECT_GE(expectSameWhereverCut(readTextFile(urdfPath(file)), std::string("halves_") + file, 3).size(), 4u)
        << file;
  }
  EXPECT_GE(expectSameWhereverCut(generatedUrdf(makeChain(20)), "halves_chain.urdf", 5).size(), 30u);
  EXPECT_GE(expectSameWhereverCut(generatedUrdf(makeBarLattice(2, 2, true)), "halves_braced.urdf", 5).size(),
            10u);
}

TEST(UrdfHalves, aFaultyFileGivesTheSameErrorWhereverItIsCut) {
  // The reader's errors (a joint to an unknown link in the second half, a root that is not <robot>) and the
  // XML faults (an attribute given twice, text after the root, the root not closed, a bad tag) come out as
  // from the file read whole, with the same line.
  const std::string good = trickyUrdf();
  const size_t tail = good.find("  <link name=\"tip\"/>");
  ASSERT_NE(tail, std::string::npos);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {good.substr(0, tail) + "  <link name=\"a\" name=\"b\"/>\n" + good.substr(tail), "twice"},
      {good + "text after", "text outside"},
      {good.substr(0, good.find("</robot>")), "mismatch"},
      {good.substr(0, good.find("<!-- after")) + "  <link name=\"late\"/>\n</robot>\n", "mismatch"},
      {good.substr(0, tail) + "  <link name=\"x\"><bad</link>\n" + good.substr(tail), "xml"},
      {good.substr(0, tail) +
           "  <joint name=\"lost\" type=\"fixed\"><parent link=\"nowhere\"/><child link=\"tip\"/></joint>\n" +
           good.substr(tail),
       "nowhere"},
      {"<?xml version=\"1.0\"?>\n<robotx name=\"r\">\n  <link name=\"a\"/>\n  <link name=\"b\"/>\n</robotx>\n",
       "not <robot>"}};
  int index = 0;
  for (const auto& [text, fragment] : cases) {
    const std::string name = "halves_bad_" + std::to_string(index++) + ".urdf";
    const std::string path = ::testing::TempDir() + name;
    std::ofstream(path, std::ios::binary) << text;
    const std::string whole = describe(readUrdfFile(path, false));
    EXPECT_NE(whole.find("error: "), std::string::npos) << whole;
    EXPECT_NE(whole.find(fragment), std::string::npos) << whole;
    expectSameWhereverCut(text, name);
  }
}

TEST(UrdfHalves, aLargeFileIsReadInHalvesAndAsWhole) {
  // readUrdfFile itself, on two threads, from 4 MB: a 3 10^4-link chain gives the mechanism it gives on
  // one thread (read whole), and a file not cut cleanly (minified: one line) is read whole.
  const std::string chain = generatedUrdf(makeChain(30000));
  ASSERT_GT(chain.size(), size_t{4} << 20);
  const std::string path = ::testing::TempDir() + "halves_large_chain.urdf";
  std::ofstream(path, std::ios::binary) << chain;
  EXPECT_EQ(describe(readUrdfFile(path, true)), describe(readUrdfFile(path, false)));
  size_t cut = 0;
  EXPECT_EQ(describe(core_detail::readUrdfFileCutFrom(path, chain.size() / 2, &cut)),
            describe(readUrdfFile(path, false)));
  EXPECT_GT(cut, chain.size() / 2);
  EXPECT_LT(cut, chain.size() / 2 + 1000);
  std::string oneLine = chain;
  for (char& c : oneLine)
    c = c == '\n' ? ' ' : c;
  std::ofstream(path, std::ios::binary | std::ios::trunc) << oneLine;
  EXPECT_EQ(describe(core_detail::readUrdfFileCutFrom(path, oneLine.size() / 2, &cut)),
            describe(readUrdfFile(path, false)));
  EXPECT_EQ(cut, 0u);
}
