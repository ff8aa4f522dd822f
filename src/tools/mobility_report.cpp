/// mobility_report FILE [--closures FILE.yaml] [--strict] [--mode auto|planar|spatial] [--positions
/// j1=0.3,j2=-1]
/// [--rank-tolerance T] [--lock-active-cables] [--deploy CABLE [--steps N] [--deploy-to LENGTH]] [--json]
/// Prints the mobility report of a closed-loop URDF or an MJCF model, with the --positions joints held at
/// their values; warnings go to stderr as "warning: ..." lines; on bad input one line on stderr and exit
/// code 2.

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <optional>
#include <string>

#include "mobility_analysis/mobility_analysis.hpp"
#include "mobility_analysis/motion/Deployment.hpp"

namespace {

constexpr int kBadInput = 2;

int fail(const std::string& line) {
  std::cerr << line << std::endl;
  return kBadInput;
}

const char* kUsage =
    "usage: mobility_report FILE.urdf|FILE.xml|FILE.sdf [--closures FILE.yaml] [--strict] [--mode "
    "auto|planar|spatial] "
    "[--positions j1=0.3,j2=-1] [--rank-tolerance T] [--lock-active-cables] "
    "[--deploy CABLE [--steps N] [--deploy-to LENGTH]] [--one-thread] [--json]";

/// --help: the usage line and what --positions does (errors print the usage line alone: one line).
const char* kPositionsHelp =
    "  --positions  hold these tree joints exactly at these values [rad or m]; the other joints\n"
    "               follow by continuation from the written pose, in its assembly mode\n"
    "               (exit 2 if a value is beyond reach)";

/// What the command line asks for.
struct Arguments {
  std::string file;
  mobility_analysis::AnalysisMode mode = mobility_analysis::AnalysisMode::Auto;
  std::string positionsText;
  double rankTolerance = -1.0;
  bool json = false;
  mobility_analysis::ReadOptions readOptions;
  bool lockActiveCables = false;
  std::string deployCable;
  int deploySteps = 100;
  std::optional<double> deployTo;
  bool oneThread = false;  ///< no second thread for a large model (the answer is the same)
};

/// The arguments, or how main must end without a model: --help printed (exit 0) or one error line (exit 2).
struct ParsedArguments {
  std::optional<Arguments> arguments;
  int exitCode = 0;
};

ParsedArguments parseArguments(int argc, char** argv) {
  using namespace mobility_analysis;
  auto stop = [](int code) { return ParsedArguments{std::nullopt, code}; };
  Arguments a;
  std::string modeText = "auto";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto next = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
    if (arg == "--json") {
      a.json = true;
    } else if (arg == "--strict") {
      a.readOptions.strict = true;
    } else if (arg == "--one-thread") {
      a.oneThread = true;
      a.readOptions.sideThread = false;
    } else if (arg == "--lock-active-cables") {
      a.lockActiveCables = true;
    } else if (arg == "--deploy" || arg == "--steps" || arg == "--deploy-to") {
      const char* value = next();
      if (value == nullptr)
        return stop(fail(std::string("mobility_report: ") + arg + " needs a value; " + kUsage));
      char* end = nullptr;
      if (arg == "--deploy") {
        a.deployCable = value;
      } else if (arg == "--steps") {
        const long steps = std::strtol(value, &end, 10);
        if (*end != '\0' || steps < 1 || steps > 10000000)
          return stop(
              fail(std::string("mobility_report: --steps '") + value + "' is not a whole number >= 1"));
        a.deploySteps = static_cast<int>(steps);
      } else {
        const double length = std::strtod(value, &end);
        if (*end != '\0' || !(length >= 0.0 && std::isfinite(length)))
          return stop(fail(std::string("mobility_report: --deploy-to '") + value + "' is not a length >= 0"));
        a.deployTo = length;
      }
    } else if (arg == "--mode" || arg == "--positions" || arg == "--rank-tolerance" || arg == "--closures") {
      const char* value = next();
      if (value == nullptr)
        return stop(fail(std::string("mobility_report: ") + arg + " needs a value; " + kUsage));
      if (arg == "--mode")
        modeText = value;
      if (arg == "--closures")
        a.readOptions.closuresFile = value;
      if (arg == "--positions")
        a.positionsText = value;
      if (arg == "--rank-tolerance") {
        char* end = nullptr;
        a.rankTolerance = std::strtod(value, &end);
        if (*end != '\0' || !(a.rankTolerance > 0.0 && a.rankTolerance < 1.0)) {
          return stop(fail(std::string("mobility_report: --rank-tolerance '") + value +
                           "' is not a number in (0, 1)"));
        }
      }
    } else if (arg == "-h" || arg == "--help") {
      std::cout << kUsage << "\n" << kPositionsHelp << std::endl;
      return stop(0);
    } else if (!arg.empty() && arg[0] == '-') {
      return stop(fail("mobility_report: unknown option '" + arg + "'; " + kUsage));
    } else if (a.file.empty()) {
      a.file = arg;
    } else {
      return stop(
          fail("mobility_report: more than one file given ('" + a.file + "', '" + arg + "'); " + kUsage));
    }
  }
  if (a.file.empty())
    return stop(fail(std::string("mobility_report: no model file given; ") + kUsage));
  const Result<AnalysisMode> mode = parseAnalysisMode(modeText);
  if (!isOk(mode))
    return stop(fail("mobility_report: --mode '" + modeText + "' is not one of auto, planar, spatial"));
  a.mode = valueOf(mode);
  return {a, 0};
}

}  // namespace

int main(int argc, char** argv) {
  using namespace mobility_analysis;
  try {
    const ParsedArguments parsed = parseArguments(argc, argv);
    if (!parsed.arguments)
      return parsed.exitCode;
    const Arguments& a = *parsed.arguments;
    // Long runs say where they are on stderr (stdout stays the report alone), the loading included.
    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [start] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    const Result<Mechanism> mechanism = readMechanism(a.file, a.readOptions);
    if (!isOk(mechanism))
      return fail(diagnosticOf(mechanism).toString());
    for (const Diagnostic& warning : valueOf(mechanism).warnings)
      std::cerr << "warning: " << warning.toString() << std::endl;
    if (elapsed() > 1.0) {
      std::cerr << "mobility_report: loaded " << valueOf(mechanism).links.size() << " links and "
                << valueOf(mechanism).joints.size() << " connections (" << elapsed() << " s)" << std::endl;
    }
    AnalysisOptions options;
    options.mode = a.mode;
    options.rankTolerance = a.rankTolerance;
    if (!a.positionsText.empty()) {
      const Result<JointPositions> positions = parseJointPositions(a.positionsText, valueOf(mechanism));
      if (!isOk(positions))
        return fail(diagnosticOf(positions).toString());
      options.positions = valueOf(positions);
    }
    options.progress = [elapsed, last = -1.0](const std::string& phase, double fraction) mutable {
      if (elapsed() > 1.0 && fraction - last >= 0.1) {
        std::cerr << "mobility_report: " << phase << " " << static_cast<int>(100 * fraction) << "% ("
                  << elapsed() << " s)" << std::endl;
        last = fraction;
      }
    };
    options.lockActiveCables = a.lockActiveCables;
    options.sideThreads = !a.oneThread;
    DeploymentOptions deployment;
    deployment.cable = a.deployCable;
    deployment.steps = a.deploySteps;
    deployment.targetLength = a.deployTo;
    deployment.analysis = options;
    const Result<MobilityAnalysis> analysis = a.deployCable.empty()
                                                  ? analyzeMechanism(valueOf(mechanism), options)
                                                  : deployMechanism(valueOf(mechanism), deployment);
    if (!isOk(analysis))
      return fail(diagnosticOf(analysis).toString());
    // The report is written only once its own invariants hold (finite numbers, consistent counts); the JSON
    // goes out as it is written (a large report's text never exists whole).
    if (a.json) {
      if (const std::optional<Diagnostic> refused =
              writeJson(valueOf(analysis).report, std::cout, !a.oneThread))
        return fail(refused->toString());
    } else {
      const Result<std::string> out = writeText(valueOf(analysis).report);
      if (!isOk(out))
        return fail(diagnosticOf(out).toString());
      std::cout << valueOf(out);
    }
    if (!std::cout.flush())
      return fail("mobility_report: could not write the report to standard output");
    return 0;
  } catch (const std::exception& e) {
    return fail(std::string("mobility_report: internal error: ") + e.what());
  }
}
