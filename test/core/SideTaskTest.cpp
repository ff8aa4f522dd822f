/// The analysis runs two phases on a second thread on large models (core_detail::SideTask): the answer must
/// be the same to the bit as on one thread, a cancelling progress callback must still cancel, and a task kept
/// for the caller's thread must run there, only when asked.
#include <atomic>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

#include "../../src/core/SideTask.hpp"
#include "mobility_analysis/MobilityAnalysis.hpp"
#include "mobility_analysis/UrdfLoader.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/ScalingFamilies.hpp"

using namespace mobility_analysis;

namespace {

Mechanism load(const MechanismDescription& description, const std::string& name) {
  const GeneratorResult<std::string> urdf = toClosedLoopUrdf(description);
  EXPECT_TRUE(std::holds_alternative<std::string>(urdf)) << name;
  const Result<Mechanism> mechanism = loadMechanismFromString(std::get<std::string>(urdf), name + ".urdf");
  EXPECT_TRUE(isOk(mechanism)) << diagnosticOf(mechanism).toString();
  return valueOf(mechanism);
}

constexpr long kThreshold = core_detail::kSecondThreadEquations;

std::string reportOf(const Mechanism& mechanism, AnalysisMode mode, bool sideThreads) {
  AnalysisOptions options;
  options.mode = mode;
  options.sideThreads = sideThreads;
  const Result<MobilityAnalysis> analysis = analyzeMechanism(mechanism, options);
  EXPECT_TRUE(isOk(analysis)) << diagnosticOf(analysis).toString();
  if (!isOk(analysis))
    return {};
  EXPECT_GE(valueOf(analysis).report.numConstraints, kThreshold) << "below the threshold: one thread only";
  return toJson(valueOf(analysis).report);
}

}  // namespace

TEST(SideTask, KeptForTheCallerRunsThereWhenAsked) {
  std::atomic<bool> ran{false};
  std::thread::id where;
  core_detail::SideTask task(false, [&] {
    ran = true;
    where = std::this_thread::get_id();
    return 7;
  });
  EXPECT_FALSE(ran);
  EXPECT_EQ(task.get(), 7);
  EXPECT_TRUE(ran);
  EXPECT_EQ(where, std::this_thread::get_id());
}

TEST(SideTask, WorthAThreadRunsOnAnother) {
  std::thread::id where;
  core_detail::SideTask task(true, [&] {
    where = std::this_thread::get_id();
    return std::string("done");
  });
  EXPECT_EQ(task.get(), "done");
  EXPECT_NE(where, std::this_thread::get_id());
}

TEST(SideTask, ExceptionsReachTheCaller) {
  for (bool thread : {false, true}) {
    core_detail::SideTask task(thread, []() -> int { throw std::runtime_error("inside"); });
    EXPECT_THROW(task.get(), std::runtime_error) << thread;
  }
}

// Above the threshold (2 10^4 equations) with and without the second thread: the same report to the byte. A
// braced lattice (the report's prestress and listed states beside the redundant links) and a chain (the
// passive-freedom search beside the self-stresses), in both modes.
TEST(SideTask, LargeReportsAreTheSameOnOneThreadOrTwo) {
  const Mechanism braced = load(makeBarLattice(32, 32, true), "braced_32");
  const Mechanism chain = load(makeChain(5000), "chain_5000");
  for (const Mechanism* mechanism : {&braced, &chain}) {
    for (AnalysisMode mode : {AnalysisMode::Auto, AnalysisMode::Spatial}) {
      const std::string one = reportOf(*mechanism, mode, false);
      const std::string two = reportOf(*mechanism, mode, true);
      ASSERT_FALSE(one.empty());
      EXPECT_TRUE(one == two) << mechanism->name << " differs with the second thread";
    }
  }
}

// The node cancels a long analysis by throwing from the progress callback: with a side task running, or the
// sweep's finds being made ahead (mid-sweep), the exception still leaves analyzeMechanism (after the other
// thread has stopped), and the next analysis is whole.
TEST(SideTask, ACancellingProgressCallbackStillCancels) {
  const Mechanism braced = load(makeBarLattice(32, 32, true), "braced_32");
  for (const auto& [phase, after] : {std::pair<std::string, double>{"self-stresses", 0.6},
                                     std::pair<std::string, double>{"ordered redundancy", 0.0}}) {
    AnalysisOptions options;
    options.progress = [phase = phase, after = after](const std::string& now, double fraction) {
      if (now == phase && fraction >= after)
        throw std::runtime_error("cancelled in " + now);
    };
    EXPECT_THROW(analyzeMechanism(braced, options), std::runtime_error) << phase;
  }
  EXPECT_EQ(reportOf(braced, AnalysisMode::Auto, true), reportOf(braced, AnalysisMode::Auto, false));
}
