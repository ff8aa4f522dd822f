/// Deployment by an active cable: the SLE mast and the ring pantograph stop exactly where their passive
/// cables go taut, checked against the closed forms of their geometry.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <sys/wait.h>

#include "core/CliRun.hpp"
#include "core/TestModels.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/ParametricFamilies.hpp"
#include "mobility_analysis/motion/Deployment.hpp"

using namespace mobility_analysis;

namespace {

MobilityAnalysis deployOrFail(const Mechanism& mechanism, const std::string& cable, int steps,
                              std::optional<double> target = std::nullopt) {
  DeploymentOptions options;
  options.cable = cable;
  options.steps = steps;
  options.targetLength = target;
  Result<MobilityAnalysis> analysis = deployMechanism(mechanism, options);
  if (!isOk(analysis)) {
    ADD_FAILURE() << diagnosticOf(analysis).toString();
    return MobilityAnalysis{};
  }
  return valueOf(std::move(analysis));
}

Mechanism generated(const MechanismDescription& description) {
  const GeneratorResult<std::string> text = toClosedLoopUrdf(description, UrdfWriterOptions{});
  EXPECT_TRUE(std::holds_alternative<std::string>(text));
  Result<Mechanism> mechanism =
      loadMechanismFromString(std::get<std::string>(text), description.name + ".urdf");
  EXPECT_TRUE(isOk(mechanism)) << diagnosticOf(mechanism).toString();
  return valueOf(std::move(mechanism));
}

const double kCos45 = std::cos(M_PI / 4);

}  // namespace

TEST(Deployment, MastDeployedByItsBaseCableStopsExactlyAt45Degrees) {
  const Mechanism mast = loadOrFail(urdfPath("sle_deployable_folded.urdf"));
  const MobilityAnalysis analysis = deployOrFail(mast, "active_base", 40);
  ASSERT_TRUE(analysis.report.deployment.has_value());
  const DeploymentInfo& d = *analysis.report.deployment;
  EXPECT_NEAR(d.initialLength, std::cos(10 * M_PI / 180), 1e-12);
  // Bars of 1 m: base width cos beta is the active length, the passive (left-side) cables are sin beta long,
  // and they reach their length sin 45 exactly when the base is cos 45.
  EXPECT_NEAR(d.finalLength, kCos45, 1e-8);
  EXPECT_EQ(d.stoppedBy, (std::vector<std::string>{"passive_1", "passive_2", "passive_3", "passive_4"}));
  EXPECT_EQ(d.finalDof, 0);
  EXPECT_EQ(analysis.report.dof, 0);
  EXPECT_EQ(analysis.report.selfStress.count, 3);
  EXPECT_FALSE(analysis.report.selfStress.prestressable);
  ASSERT_GE(d.steps.size(), 3u);
  for (size_t k = 0; k < d.steps.size(); ++k) {
    const DeploymentStep& step = d.steps[k];
    const bool last = k + 1 == d.steps.size();
    EXPECT_EQ(step.dof, 1) << "step " << k;  // one freedom all along (the active cable is the driver)
    for (const CableState& c : step.cables) {
      if (c.type != "passive")
        continue;
      EXPECT_NEAR(c.distance, std::sqrt(1.0 - step.activeLength * step.activeLength), 1e-8) << "step " << k;
      EXPECT_EQ(c.state, last ? "taut" : "slack") << c.name << " step " << k;
    }
    if (k > 0)
      EXPECT_LT(step.activeLength, d.steps[k - 1].activeLength);
    EXPECT_FALSE(step.joints.empty());
  }
  for (const CableState& c : analysis.report.cables)
    EXPECT_EQ(c.state, c.type == "passive" ? "taut" : "driving") << c.name;
}

TEST(Deployment, CoarseStepsStillStopWhereTheCablesGoTaut) {
  const Mechanism mast = loadOrFail(urdfPath("sle_deployable_partly.urdf"));
  const DeploymentInfo d = *deployOrFail(mast, "active_base", 2, 0.2).report.deployment;
  EXPECT_NEAR(d.finalLength, kCos45, 1e-8);
  EXPECT_EQ(d.stoppedBy.size(), 4u);
  EXPECT_LE(d.steps.size(), 3u);
}

TEST(Deployment, StopsAtTheTargetWhenNoCableGoesTaut) {
  const Mechanism mast = loadOrFail(urdfPath("sle_deployable_folded.urdf"));
  const MobilityAnalysis analysis = deployOrFail(mast, "active_base", 5, 0.9);
  const DeploymentInfo& d = *analysis.report.deployment;
  EXPECT_TRUE(d.stoppedBy.empty());
  EXPECT_DOUBLE_EQ(d.finalLength, 0.9);
  EXPECT_EQ(d.finalDof, 1);
  EXPECT_EQ(d.steps.size(), 6u);
  // The slider sits at the active length: base_slide's value moved by 0.9 - cos 10.
  bool found = false;
  for (const JointValue& j : analysis.report.positions) {
    if (j.name != "base_slide")
      continue;
    found = true;
    EXPECT_NEAR(j.value, 0.9 - std::cos(10 * M_PI / 180), 1e-8);
  }
  EXPECT_TRUE(found);
}

TEST(Deployment, RingPantographStopsWhenItsHoopsGoTaut) {
  const Mechanism ring = loadOrFail(urdfPath("ring_pantograph_folded.urdf"));
  const MobilityAnalysis analysis = deployOrFail(ring, "active_unit0", 30);
  const DeploymentInfo& d = *analysis.report.deployment;
  // Unit 0's first arms (0.5 m each) close from 150 to the deployed 60 deg: 2 * 0.5 * sin(30 deg) = 0.5.
  EXPECT_NEAR(d.initialLength, std::sin(75 * M_PI / 180), 1e-12);
  EXPECT_NEAR(d.finalLength, 0.5, 1e-8);
  EXPECT_EQ(d.stoppedBy, (std::vector<std::string>{"hoop_0", "hoop_1", "hoop_2", "hoop_3"}));
  EXPECT_EQ(d.finalDof, 0);
  EXPECT_EQ(analysis.report.selfStress.count, 7);
  for (const DeploymentStep& step : d.steps)
    EXPECT_EQ(step.dof, 1);
}

TEST(Deployment, LargerGeneratedMastsStopAtTheSameAngle) {
  const Mechanism mast = generated(makeSleDeployableMast(12, 20.0));
  const DeploymentInfo d = *deployOrFail(mast, "active_base", 20).report.deployment;
  EXPECT_NEAR(d.finalLength, kCos45, 1e-8);
  EXPECT_EQ(d.stoppedBy.size(), 12u);
  EXPECT_EQ(d.finalDof, 0);
}

TEST(Deployment, RejectsCablesThatCannotDrive) {
  const Mechanism mast = loadOrFail(urdfPath("sle_deployable_folded.urdf"));
  DeploymentOptions options;
  options.cable = "passive_1";
  Result<MobilityAnalysis> passive = deployMechanism(mast, options);
  ASSERT_FALSE(isOk(passive));
  EXPECT_NE(diagnosticOf(passive).toString().find("passive_1"), std::string::npos);
  options.cable = "no_such_cable";
  Result<MobilityAnalysis> unknown = deployMechanism(mast, options);
  ASSERT_FALSE(isOk(unknown));
  EXPECT_NE(diagnosticOf(unknown).toString().find("no_such_cable"), std::string::npos);
}

TEST(Deployment, JsonReportsTheSteps) {
  const Mechanism mast = loadOrFail(urdfPath("sle_deployable_folded.urdf"));
  const std::string json = toJson(deployOrFail(mast, "active_base", 10).report);
  EXPECT_NE(json.find("\"deployment\": {\"cable\": \"active_base\""), std::string::npos);
  EXPECT_NE(json.find("\"stopped_by\": [\"passive_1\", \"passive_2\", \"passive_3\", \"passive_4\"]"),
            std::string::npos);
  EXPECT_NE(json.find("\"final_length\": 0.707106781"), std::string::npos);
  EXPECT_EQ(json.find("nan"), std::string::npos);
}

TEST(DeploymentCli, DeployAndLockFlags) {
  const CliRun deploy =
      runReport(urdfPath("sle_deployable_folded.urdf") + " --deploy active_base --steps 20 --json");
  EXPECT_EQ(deploy.status, 0) << deploy.err;
  EXPECT_NE(deploy.out.find("\"final_dof\": 0"), std::string::npos);
  EXPECT_NE(deploy.out.find("\"stopped_by\": [\"passive_1\""), std::string::npos);
  const CliRun lock = runReport(urdfPath("sle_deployable_deployed.urdf") + " --lock-active-cables --json");
  EXPECT_EQ(lock.status, 0) << lock.err;
  EXPECT_NE(lock.out.find("\"self_stress\": {\"count\": 4"), std::string::npos);
  EXPECT_NE(lock.out.find("\"prestressable\": true"), std::string::npos);
  EXPECT_NE(lock.out.find("\"state\": \"locked\""), std::string::npos);
  // Deployed, then the actuator locked: the final report is the prestressable structure.
  const CliRun both = runReport(urdfPath("sle_deployable_folded.urdf") +
                                " --deploy active_base --steps 20 --lock-active-cables --json");
  EXPECT_EQ(both.status, 0) << both.err;
  EXPECT_NE(both.out.find("\"self_stress\": {\"count\": 4"), std::string::npos);
  EXPECT_NE(both.out.find("\"prestressable\": true"), std::string::npos);
  EXPECT_NE(both.out.find("\"final_dof\": 0"), std::string::npos);
}

TEST(DeploymentCli, BadDeploymentArgumentsExitTwoWithOneLine) {
  const std::string mast = urdfPath("sle_deployable_folded.urdf");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {mast + " --deploy passive_1", "passive_1"},
      {mast + " --deploy nope", "nope"},
      {mast + " --deploy active_base --steps 0", "--steps"},
      {mast + " --deploy active_base --deploy-to -1", "--deploy-to"},
      {mast + " --deploy", "--deploy"},
  };
  for (const auto& [arguments, name] : cases) {
    const CliRun run = runReport(arguments);
    EXPECT_EQ(run.status, 2) << arguments;
    EXPECT_TRUE(run.out.empty()) << arguments;
    EXPECT_NE(run.err.find(name), std::string::npos) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  }
}
