/// 1 000 structure-aware mutations of the bundled models (urdf/*.urdf and every URDF and MJCF file under
/// test/fixtures/), deterministic (fixed seed): each mutant must give either a report whose JSON is valid
/// (and free of inf/nan) or one diagnostic line, never a crash, an exception or a multi-line message (issue
/// 14).
///
/// Every mutant goes through the core in-process (the reader, analyzeMechanism and writeJson: the CLI's own
/// path); one in ten also goes through the CLI, whose stdout must then parse as JSON and whose stderr must
/// end in exactly one error line (warnings before it are "warning: " lines, each one line).

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include "TextFile.hpp"
#include "core/CliRun.hpp"
#include "core/JsonCheck.hpp"
#include "core/TestModels.hpp"

namespace mobility_analysis {
namespace {

/// The seed models: every .urdf of urdf/ and every .urdf and .xml under test/fixtures/, sorted by path.
std::vector<std::string> seedFiles() {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(MA_URDF_DIR))
    if (entry.path().extension() == ".urdf")
      files.push_back(entry.path().string());
  for (const auto& entry : std::filesystem::recursive_directory_iterator(MA_FIXTURE_DIR)) {
    const std::string extension = entry.path().extension().string();
    if (extension == ".urdf" || extension == ".xml")
      files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// Numbers that have broken or could break a reader or the analysis.
const std::vector<std::string> kExtremeNumbers = {"1e308",
                                                  "-1e308",
                                                  "-0",
                                                  "nan",
                                                  "NaN",
                                                  "inf",
                                                  "-inf",
                                                  "Infinity",
                                                  "1e-320",
                                                  "4.9e-324",
                                                  "1e155",
                                                  "123456789012345678901234567890",
                                                  "-99999999999999999999",
                                                  "1e12",
                                                  "1.0000001e12",
                                                  "-1e13",
                                                  "1e9",
                                                  "1e-9",
                                                  "0x1p1023",
                                                  "0",
                                                  "1e",
                                                  ".",
                                                  "+",
                                                  "1,5",
                                                  "",
                                                  " ",
                                                  "2.2250738585072014e-308",
                                                  "3.4e38",
                                                  "-1e-300",
                                                  "1e11"};

/// Names with newlines, control characters, quotes, markup and sheer length.
const std::vector<std::string> kHostileNames = {"gro\nund",
                                                "a\rb",
                                                "tab\there",
                                                std::string("nul\x01x"),
                                                "bell\x07",
                                                "del\x7f",
                                                "esc\x1b[31mred",
                                                "\"quoted\"",
                                                "back\\slash",
                                                "<tag>",
                                                "a&b",
                                                "",
                                                " ",
                                                "\xc3\xa9l\xc3\xa9ment",
                                                "\xff\xfe",
                                                std::string(5000, 'n'),
                                                "l0",
                                                "ground",
                                                "world",
                                                "..",
                                                "a b"};

/// Joint type spellings, known and unknown.
const std::vector<std::string> kTypes = {
    "revolute", "continuous", "prismatic", "fixed",       "floating",
    "planar",   "spherical",  "universal", "cylindrical", "revolut",
    "REVOLUTE", "",           "ball",      "screw",       "revolute revolute",
    "hinge",    "slide",      "free",      "weld",        "passive",
    "active",   "\n"};

/// Element names the readers know (and a few they do not).
const std::vector<std::string> kTags = {"link",      "joint",    "loop_joint", "distance_constraint",
                                        "cable",     "coupling", "loop",       "parent",
                                        "child",     "origin",   "axis",       "axis2",
                                        "limit",     "link1",    "link2",      "mimic",
                                        "robot",     "mujoco",   "body",       "geom",
                                        "loopjoint", "gazebo",   "frame",      "x"};

/// Deterministic structure-aware mutator over a tinyxml2 document.
class Mutator {
 public:
  explicit Mutator(uint32_t seed) : rng_(seed) {}

  size_t pick(size_t n) { return n == 0 ? 0 : rng_() % n; }
  template <class T>
  const T& pickFrom(const std::vector<T>& v) {
    return v[pick(v.size())];
  }

  /// @return @p text after 1 to 3 mutations, and what was done.
  std::string mutate(const std::string& text, std::string& log) {
    tinyxml2::XMLDocument doc;
    if (doc.Parse(text.c_str(), text.size()) != tinyxml2::XML_SUCCESS)
      return text;
    const int count = 1 + static_cast<int>(pick(3));
    for (int i = 0; i < count; ++i)
      log += mutateOnce(doc) + "; ";
    tinyxml2::XMLPrinter printer;
    doc.Print(&printer);
    std::string out = printer.CStr();
    // Now and then a byte-level change as well: truncation, a stray byte, a broken declaration.
    switch (pick(12)) {
      case 0:
        out = out.substr(0, pick(out.size()));
        log += "truncated; ";
        break;
      case 1:
        out.insert(pick(out.size()), 1, static_cast<char>(pick(256)));
        log += "stray byte; ";
        break;
      case 2:
        out = "<?xml version=\"1.0\n\x02?>" + out;
        log += "broken declaration; ";
        break;
      default:
        break;
    }
    return out;
  }

 private:
  static void collect(tinyxml2::XMLElement* e, std::vector<tinyxml2::XMLElement*>& out) {
    for (; e != nullptr; e = e->NextSiblingElement()) {
      out.push_back(e);
      collect(e->FirstChildElement(), out);
    }
  }
  static bool isAncestor(const tinyxml2::XMLNode* a, const tinyxml2::XMLNode* b) {
    for (const tinyxml2::XMLNode* n = b; n != nullptr; n = n->Parent())
      if (n == a)
        return true;
    return false;
  }
  static std::vector<const tinyxml2::XMLAttribute*> attributes(const tinyxml2::XMLElement* e) {
    std::vector<const tinyxml2::XMLAttribute*> out;
    for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a != nullptr; a = a->Next())
      out.push_back(a);
    return out;
  }
  /// Every value of attribute @p name in the document (link names, joint names, ...).
  static std::vector<std::string> valuesOf(const std::vector<tinyxml2::XMLElement*>& all, const char* name) {
    std::vector<std::string> out;
    for (const tinyxml2::XMLElement* e : all)
      if (const char* v = e->Attribute(name))
        out.push_back(v);
    return out;
  }

  std::string mutateOnce(tinyxml2::XMLDocument& doc) {
    std::vector<tinyxml2::XMLElement*> all;
    collect(doc.RootElement(), all);
    if (all.size() < 2)
      return "nothing to mutate";
    tinyxml2::XMLElement* root = all.front();
    tinyxml2::XMLElement* e = all[1 + pick(all.size() - 1)];  // never the root
    tinyxml2::XMLElement* any = all[pick(all.size())];
    const std::vector<const tinyxml2::XMLAttribute*> attrs = attributes(any);
    switch (pick(14)) {
      case 0:
        e->Parent()->DeleteChild(e);
        return "dropped an element";
      case 1:
        e->Parent()->InsertAfterChild(e, e->DeepClone(&doc));
        return "duplicated <" + std::string(e->Name()) + ">";
      case 2: {  // swap two elements that do not contain each other
        tinyxml2::XMLElement* f = all[1 + pick(all.size() - 1)];
        if (f == e || isAncestor(e, f) || isAncestor(f, e))
          return "no swap";
        tinyxml2::XMLNode* ce = e->DeepClone(&doc);
        tinyxml2::XMLNode* cf = f->DeepClone(&doc);
        f->Parent()->InsertAfterChild(f, ce);
        e->Parent()->InsertAfterChild(e, cf);
        e->Parent()->DeleteChild(e);
        f->Parent()->DeleteChild(f);
        return "swapped two elements";
      }
      case 3: {  // move an element inside another one
        tinyxml2::XMLElement* into = all[pick(all.size())];
        if (isAncestor(e, into))
          return "no move";
        into->InsertEndChild(e);
        return "moved <" + std::string(e->Name()) + "> into <" + into->Name() + ">";
      }
      case 4:
        e->SetName(pickFrom(kTags).c_str());
        return "renamed an element";
      case 5:
        if (attrs.empty())
          return "no attribute";
        any->DeleteAttribute(pickFrom(attrs)->Name());
        return "dropped an attribute";
      case 6: {  // copy an attribute onto another element
        if (attrs.empty())
          return "no attribute";
        const tinyxml2::XMLAttribute* a = pickFrom(attrs);
        const std::string name = a->Name(), value = a->Value();
        all[pick(all.size())]->SetAttribute(name.c_str(), value.c_str());
        return "copied attribute " + name;
      }
      case 7:
      case 8: {  // an extreme number in place of one number of a numeric attribute
        std::vector<std::pair<tinyxml2::XMLElement*, std::string>> numeric;
        for (tinyxml2::XMLElement* x : all)
          for (const tinyxml2::XMLAttribute* a : attributes(x)) {
            const std::string v = a->Value();
            if (!v.empty() && v.find_first_not_of("0123456789.eE+- ") == std::string::npos)
              numeric.emplace_back(x, a->Name());
          }
        if (numeric.empty())
          return "no number";
        const auto& [x, name] = numeric[pick(numeric.size())];
        std::istringstream in(x->Attribute(name.c_str()));
        std::vector<std::string> tokens;
        for (std::string t; in >> t;)
          tokens.push_back(t);
        if (tokens.empty())
          tokens.push_back("0");
        tokens[pick(tokens.size())] = pickFrom(kExtremeNumbers);
        std::string joined;
        for (size_t k = 0; k < tokens.size(); ++k)
          joined += (k ? " " : "") + tokens[k];
        x->SetAttribute(name.c_str(), joined.c_str());
        return name + "=\"" + joined + "\"";
      }
      case 9: {  // a hostile name: on one reference, or renamed consistently (the model stays valid)
        const std::vector<std::string> names = valuesOf(all, "name");
        if (names.empty())
          return "no name";
        const std::string old = pickFrom(names), hostile = pickFrom(kHostileNames);
        const bool everywhere = pick(2) == 0;
        bool first = true;
        for (tinyxml2::XMLElement* x : all)
          for (const tinyxml2::XMLAttribute* a : attributes(x))
            if (a->Value() == old && (everywhere || first)) {
              x->SetAttribute(a->Name(), hostile.c_str());
              first = false;
            }
        return everywhere ? "renamed everywhere" : "hostile name";
      }
      case 10: {
        std::vector<tinyxml2::XMLElement*> typed;
        for (tinyxml2::XMLElement* x : all)
          if (x->Attribute("type"))
            typed.push_back(x);
        if (typed.empty())
          return "no type";
        const std::string type = pickFrom(kTypes);
        typed[pick(typed.size())]->SetAttribute("type", type.c_str());
        return "type=\"" + type + "\"";
      }
      case 11: {  // a self-parent or a cycle: a joint's parent becomes its child or another link
        std::vector<tinyxml2::XMLElement*> parents;
        for (tinyxml2::XMLElement* x : all)
          if (std::string(x->Name()) == "parent" || std::string(x->Name()) == "link1")
            parents.push_back(x);
        const std::vector<std::string> links = valuesOf(all, "link");
        if (parents.empty() || links.empty())
          return "no parent";
        tinyxml2::XMLElement* p = parents[pick(parents.size())];
        const tinyxml2::XMLElement* sibling =
            p->Parent()->FirstChildElement(std::string(p->Name()) == "parent" ? "child" : "link2");
        const std::string to = sibling != nullptr && sibling->Attribute("link") && pick(2) == 0
                                   ? sibling->Attribute("link")
                                   : pickFrom(links);
        p->SetAttribute("link", to.c_str());
        return "parent -> " + to;
      }
      case 12: {  // any attribute takes any other attribute's value (cross-wired references)
        if (attrs.empty())
          return "no attribute";
        std::vector<std::string> values;
        for (tinyxml2::XMLElement* x : all)
          for (const tinyxml2::XMLAttribute* a : attributes(x))
            values.push_back(a->Value());
        any->SetAttribute(pickFrom(attrs)->Name(), pickFrom(values).c_str());
        return "cross-wired an attribute";
      }
      default: {  // a new element the readers know, empty or half-filled, at a random place
        tinyxml2::XMLElement* fresh = doc.NewElement(pickFrom(kTags).c_str());
        if (pick(2) == 0)
          fresh->SetAttribute("name", pickFrom(kHostileNames).c_str());
        if (pick(2) == 0)
          fresh->SetAttribute("type", pickFrom(kTypes).c_str());
        (pick(2) == 0 ? root : e)->InsertEndChild(fresh);
        return "inserted <" + std::string(fresh->Name()) + ">";
      }
    }
  }

  std::mt19937 rng_;
};

/// @return Empty when @p message is one printable line, else why not.
std::string oneLine(const std::string& message) {
  if (message.empty())
    return "empty message";
  for (const char c : message) {
    if (static_cast<unsigned char>(c) < 0x20 || c == '\x7f')
      return "control character " + std::to_string(static_cast<int>(static_cast<unsigned char>(c)));
  }
  // Valid UTF-8 as well (ROS strings and terminals): checked as a JSON string's content.
  std::string asJson = "\"";
  for (const char c : message)
    asJson += c == '"' || c == '\\' ? ' ' : c;
  const std::string why = JsonCheck::check(asJson + "\"");
  return why.empty() ? "" : "not one line of text: " + why;
}

/// What the CLI path gives for one model text, in-process: "" when it holds the rule, else why not.
/// @p ok is set to whether a report was written.
std::string checkInProcess(const std::string& text, const std::string& name, bool& ok) {
  ok = false;
  try {
    const Result<Mechanism> mechanism = readMechanismFromString(text, name);
    if (!isOk(mechanism))
      return oneLine(diagnosticOf(mechanism).toString());
    for (const Diagnostic& warning : valueOf(mechanism).warnings)
      if (const std::string why = oneLine(warning.toString()); !why.empty())
        return "warning: " + why;
    const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), AnalysisOptions{});
    if (!isOk(analysis))
      return oneLine(diagnosticOf(analysis).toString());
    const Result<std::string> json = writeJson(valueOf(analysis).report);
    if (!isOk(json))  // the analysis gave a report that breaks its own invariants: a bug, not bad input
      return "writeJson refused the analysis' report: " + diagnosticOf(json).toString();
    ok = true;
    const std::string why = JsonCheck::check(valueOf(json));
    return why.empty() ? "" : "invalid JSON: " + why;
  } catch (const std::exception& e) {
    return std::string("exception across the API: ") + e.what();
  }
}

TEST(StructuredMutations, everyMutantGivesAValidReportOrOneDiagnosticLine) {
  const std::vector<std::string> seeds = seedFiles();
  ASSERT_GE(seeds.size(), 40u) << "the bundled models are missing";
  std::vector<std::string> texts;
  for (const std::string& file : seeds)
    texts.push_back(readTextFile(file));

  // 1 000 mutants of seed 14 in CI; MA_MUTANTS and MA_MUTATION_SEED run a longer campaign by hand.
  const int kMutants = std::getenv("MA_MUTANTS") ? std::atoi(std::getenv("MA_MUTANTS")) : 1000;
  const uint32_t seed = std::getenv("MA_MUTATION_SEED")
                            ? static_cast<uint32_t>(std::atol(std::getenv("MA_MUTATION_SEED")))
                            : 14u;
  constexpr int kThroughCli = 10;  // every tenth mutant also through the CLI
  Mutator mutator(seed);
  int reports = 0, refusals = 0, cliRuns = 0;
  double slowest = 0.0;
  std::string slowestLog;
  for (int m = 0; m < kMutants; ++m) {
    const size_t s = static_cast<size_t>(m) % seeds.size();
    std::string log;
    const std::string mutant = mutator.mutate(texts[s], log);
    const std::string name =
        "mutant" + std::to_string(m) + std::filesystem::path(seeds[s]).extension().string();
    SCOPED_TRACE(name + " of " + seeds[s] + ": " + log);
    // MA_MUTANT_DIR keeps every mutant, to compare two builds' answers on them (a reader port, say).
    if (const char* keep = std::getenv("MA_MUTANT_DIR"))
      std::ofstream(std::string(keep) + "/" + name, std::ios::binary) << mutant;

    const auto start = std::chrono::steady_clock::now();
    bool ok = false;
    const std::string why = checkInProcess(mutant, name, ok);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (seconds > slowest)
      slowest = seconds, slowestLog = name + " of " + seeds[s] + ": " + log;
    EXPECT_EQ(why, "") << mutant.substr(0, 2000);
    (ok ? reports : refusals)++;

    if (m % kThroughCli == 0) {
      ++cliRuns;
      const std::string path = ::testing::TempDir() + name;
      std::ofstream(path, std::ios::binary) << mutant;
      const CliRun run = runReport("'" + path + "' --json");
      EXPECT_TRUE(run.status == 0 || run.status == 2) << run.status << ": " << run.err;
      EXPECT_EQ(run.status == 0, ok) << "the CLI and the core disagree: " << run.err;
      if (run.status == 0) {
        EXPECT_EQ(JsonCheck::check(run.out), "");
      } else {
        EXPECT_TRUE(run.out.empty());
        // Warnings (one line each, "warning: ...") may come first; the error is the one last line.
        std::istringstream lines(run.err);
        std::vector<std::string> errors;
        for (std::string line; std::getline(lines, line);)
          if (line.rfind("warning: ", 0) != 0)
            errors.push_back(line);
        EXPECT_EQ(errors.size(), 1u) << run.err;
        EXPECT_TRUE(!run.err.empty() && run.err.back() == '\n') << run.err;
        for (const std::string& line : errors)
          EXPECT_EQ(oneLine(line), "") << line;
      }
      std::remove(path.c_str());
    }
  }
  // The mutations are neither all harmless nor all fatal: both paths are exercised.
  EXPECT_GT(reports, kMutants / 10);
  EXPECT_GT(refusals, kMutants / 10);
  std::printf("%d mutants: %d reports, %d refusals, %d through the CLI; slowest %.3f s (%s)\n", kMutants,
              reports, refusals, cliRuns, slowest, slowestLog.c_str());
}

/// @p text with the children of its root element in an order drawn by @p seed; @p text if it does not parse.
std::string withShuffledElements(const std::string& text, uint32_t seed) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.c_str(), text.size()) != tinyxml2::XML_SUCCESS || doc.RootElement() == nullptr)
    return text;
  tinyxml2::XMLElement* root = doc.RootElement();
  std::vector<tinyxml2::XMLNode*> children;
  for (tinyxml2::XMLNode* c = root->FirstChild(); c != nullptr; c = c->NextSibling())
    children.push_back(c);
  std::shuffle(children.begin(), children.end(), std::mt19937(seed));
  for (tinyxml2::XMLNode* c : children)
    root->InsertEndChild(c);  // moves it to the end, in the drawn order
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  return printer.CStr();
}

// The order elements are written in is the order of the equations, so it may change which equation of a
// redundant set is named, never the counts: DOF, finite and passive DOF, Grübler, redundant equations,
// singular, and whether the cables can be prestressed. (Shuffling every bundled and generated model this way
// found a triangular scissor mast whose finite DOF read 0 in one order: FiniteMobilityTest.)
TEST(StructuredMutations, theOrderOfTheElementsDoesNotChangeTheCounts) {
  int compared = 0;
  for (const auto& entry : std::filesystem::directory_iterator(MA_URDF_DIR)) {
    if (entry.path().extension() != ".urdf")
      continue;
    const std::string text = readTextFile(entry.path().string());
    for (const AnalysisMode mode : {AnalysisMode::Auto, AnalysisMode::Spatial}) {
      const Result<Mechanism> written = loadMechanismFromString(text, "written.urdf");
      ASSERT_TRUE(isOk(written)) << diagnosticOf(written).toString();
      const MobilityReport expected = analyzeOrFail(valueOf(written), mode).report;
      for (uint32_t seed = 1; seed <= 3; ++seed) {
        SCOPED_TRACE(entry.path().filename().string() + (mode == AnalysisMode::Auto ? " auto" : " spatial") +
                     ", order " + std::to_string(seed));
        const std::string shuffled = withShuffledElements(text, seed);
        ASSERT_NE(shuffled, text);
        const Result<Mechanism> reordered = loadMechanismFromString(shuffled, "shuffled.urdf");
        ASSERT_TRUE(isOk(reordered)) << diagnosticOf(reordered).toString();
        const MobilityReport actual = analyzeOrFail(valueOf(reordered), mode).report;
        expectSameCounts(expected, actual);
        EXPECT_EQ(actual.selfStress.count, expected.selfStress.count);
        EXPECT_EQ(actual.selfStress.prestressable, expected.selfStress.prestressable);
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 100);  // every bundled model, both modes, three orders
}

}  // namespace
}  // namespace mobility_analysis
