/// deployment_benchmark [--units N] [--steps S] [--deployed-units M]
///
/// Prints two figures of issue 12 (one line each, key=value):
///   deploy:  the SLE mast of N units (default 1000) generated folded at 10 deg, deployed by its base cable
///   in S
///            equal steps (default 1000) from cos 10 towards 0.7 m; the continuation stops where the passive
///            cables go taut (cos 45 = 0.70710678 m): generate+load seconds, deployment seconds, steps taken,
///            final length and its error, cables that stopped it, final DOF;
///   prestress: the mast of M units (default 10000) written deployed at 45 deg, analysed with passive cables
///            only and with the active cable locked: analysis seconds, of which the self-stress report
///            (element forces, Clp prestress LP, stress-matrix test), states, prestressable, stability.
/// Peak memory is the process's maximum resident set.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>

#include <sys/resource.h>

#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/ParametricFamilies.hpp"
#include "mobility_analysis/mobility_analysis.hpp"
#include "mobility_analysis/motion/Deployment.hpp"

using namespace mobility_analysis;

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double peakMegabytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

Result<Mechanism> generate(int units, double elevationDeg) {
  UrdfWriterOptions writer;
  writer.visuals = false;
  const GeneratorResult<std::string> text =
      toClosedLoopUrdf(makeSleDeployableMast(units, elevationDeg), writer);
  if (const auto* error = std::get_if<GeneratorError>(&text))
    return makeDiagnostic("generated", "robot", "sle_deployable", error->what);
  return loadMechanismFromString(std::get<std::string>(text),
                                 "sle_deployable_" + std::to_string(units) + ".urdf");
}

int prestressLine(const Mechanism& mast, bool lock) {
  AnalysisOptions options;
  options.lockActiveCables = lock;
  Clock::time_point selfStressStart{};
  double selfStressSeconds = 0.0;
  options.progress = [&](const std::string& phase, double) {
    if (phase == "self-stress report")
      selfStressStart = Clock::now();
    if (phase == "done" && selfStressStart != Clock::time_point{})
      selfStressSeconds = since(selfStressStart);
  };
  const Clock::time_point start = Clock::now();
  const Result<MobilityAnalysis> analysis = analyzeMechanism(mast, options);
  const double seconds = since(start);
  if (!isOk(analysis)) {
    std::cerr << diagnosticOf(analysis).toString() << std::endl;
    return 2;
  }
  const MobilityReport& r = valueOf(analysis).report;
  std::printf(
      "prestress units=%zu lock_active=%d coordinates=%d equations=%d dof=%d states=%d taut_cables=%d "
      "prestressable=%d prestress_stable=%d analysis_seconds=%.2f self_stress_report_seconds=%.2f "
      "peak_mb=%.0f\n",
      (mast.links.size() - 2) / 2, lock ? 1 : 0, r.numCoordinates, r.numConstraints, r.dof,
      r.selfStress.count, r.selfStress.tautCables, r.selfStress.prestressable ? 1 : 0,
      r.selfStress.prestressStable ? 1 : 0, seconds, selfStressSeconds, peakMegabytes());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int units = 1000, steps = 1000, deployedUnits = 10000;
  for (int i = 1; i + 1 < argc; i += 2) {
    const int value = std::atoi(argv[i + 1]);
    if (value < 1) {
      std::cerr << "deployment_benchmark: " << argv[i] << " needs a positive whole number" << std::endl;
      return 2;
    }
    if (std::strcmp(argv[i], "--units") == 0)
      units = value;
    else if (std::strcmp(argv[i], "--steps") == 0)
      steps = value;
    else if (std::strcmp(argv[i], "--deployed-units") == 0)
      deployedUnits = value;
    else {
      std::cerr << "deployment_benchmark: unknown option " << argv[i] << std::endl;
      return 2;
    }
  }

  Clock::time_point start = Clock::now();
  const Result<Mechanism> folded = generate(units, 10.0);
  if (!isOk(folded))
    return std::cerr << diagnosticOf(folded).toString() << std::endl, 2;
  const double loadSeconds = since(start);
  DeploymentOptions options;
  options.cable = "active_base";
  options.steps = steps;
  options.targetLength = 0.7;
  start = Clock::now();
  const Result<MobilityAnalysis> deployed = deployMechanism(valueOf(folded), options);
  const double deploySeconds = since(start);
  if (!isOk(deployed))
    return std::cerr << diagnosticOf(deployed).toString() << std::endl, 2;
  const DeploymentInfo& d = *valueOf(deployed).report.deployment;
  std::printf(
      "deploy units=%d steps_requested=%d steps_taken=%zu load_seconds=%.2f deploy_seconds=%.2f "
      "final_length=%.9f error_vs_cos45=%.2e stopped_by=%zu final_dof=%d peak_mb=%.0f\n",
      units, steps, d.steps.size() - 1, loadSeconds, deploySeconds, d.finalLength,
      d.finalLength - std::cos(M_PI / 4), d.stoppedBy.size(), d.finalDof, peakMegabytes());
  std::fflush(stdout);

  start = Clock::now();
  const Result<Mechanism> mast = generate(deployedUnits, 45.0);
  if (!isOk(mast))
    return std::cerr << diagnosticOf(mast).toString() << std::endl, 2;
  std::printf("prestress units=%d generate_load_seconds=%.2f\n", deployedUnits, since(start));
  std::fflush(stdout);
  if (int code = prestressLine(valueOf(mast), false))
    return code;
  std::fflush(stdout);
  return prestressLine(valueOf(mast), true);
}
