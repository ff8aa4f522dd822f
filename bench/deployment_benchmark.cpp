/// deployment_benchmark [--units N] [--steps S] [--deployed-units M] [--svg FILE]
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
/// Peak memory is the process's maximum resident set. --svg FILE draws six snapshots of the deployment side
/// by side (bars black, taut cables solid red, slack cables dashed grey, the active cable blue) for the
/// README.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
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

/// Every link as its description's visual path carried by the link's motion since the first snapshot; cables
/// as lines between their ends.
std::string drawSnapshot(const Mechanism& mechanism, const MechanismDescription& description,
                         const LinkPoses& written, const LinkPoses& poses, const DeploymentStep& step,
                         double dx, double scale) {
  std::string out;
  auto xy = [&](const Eigen::Vector3d& p) {
    char text[64];
    std::snprintf(text, sizeof(text), "%.2f,%.2f", dx + scale * p.x(), 40.0 + scale * (4.0 - p.y()));
    return std::string(text);
  };
  for (const LinkDescription& link : description.links) {
    const std::optional<int> index = mechanism.findLink(link.name);
    if (!index || link.visualPath.size() < 2)
      continue;
    const Eigen::Isometry3d motion = poses[*index] * written[*index].inverse();
    std::string line;
    for (const Eigen::Vector3d& p : link.visualPath)
      line += xy(motion * p) + " ";
    out += "<polyline points=\"" + line + "\" style=\"fill:none;stroke:#222;stroke-width:2.5\"/>\n";
  }
  for (const Joint& joint : mechanism.joints) {
    if (joint.kind != ConnectionKind::Cable)
      continue;
    std::string style = "stroke:#1f5fd6;stroke-width:2";
    for (const CableState& c : step.cables) {
      if (c.name == joint.name && c.type == "passive")
        style = c.state == "taut" ? "stroke:#d62728;stroke-width:2"
                                  : "stroke:#999;stroke-width:1.5;stroke-dasharray:4,3";
    }
    out += "<polyline points=\"" + xy(poses[joint.link1] * joint.frame1.translation()) + " " +
           xy(poses[joint.link2] * joint.frame2.translation()) + "\" style=\"fill:none;" + style + "\"/>\n";
  }
  char label[160];
  std::snprintf(label, sizeof(label), "<text x=\"%.1f\" y=\"30\" font-size=\"13\">L = %.3f m</text>\n", dx,
                step.activeLength);
  return out + label;
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
  std::string svgFile;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--svg") == 0) {
      svgFile = argv[i + 1];
      continue;
    }
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
  std::vector<std::pair<DeploymentStep, LinkPoses>> snapshots;
  if (!svgFile.empty())
    options.onStep = [&](const DeploymentStep& step, const LinkPoses& poses) {
      snapshots.emplace_back(step, poses);
    };
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
  if (!svgFile.empty() && !snapshots.empty()) {
    std::ofstream svg(svgFile);
    const double scale = 120.0, width = 1.3 * scale;
    const int shots = 6;
    const MechanismDescription description = makeSleDeployableMast(units, 10.0);
    svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << shots * width + 40 << "\" height=\""
        << 4.2 * scale + 60 << "\" style=\"background:white\">\n";
    for (int k = 0; k < shots; ++k) {
      const size_t index = k * (snapshots.size() - 1) / (shots - 1);
      svg << drawSnapshot(valueOf(folded), description, snapshots.front().second, snapshots[index].second,
                          snapshots[index].first, 20 + k * width, scale);
    }
    svg << "</svg>\n";
  }

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
