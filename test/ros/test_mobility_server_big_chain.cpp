/// Integration test: the node survives `~load_robot` of a 140 000-link chain (launched by
/// test_mobility_server_big_chain.launch).
///
/// urdfdom walked the tree recursively, about two stack frames per link: a chain of more than about 130 000
/// links crashed the CLI and, sent to ~load_robot, killed the node (issue 14). The chain is generated here, a
/// planar revolute chain (every joint about z, 0.1 m apart): 140 000 independent pins, DOF 140 000 in the
/// plane and in space by Grübler–Kutzbach, with nothing redundant. While it loads the node keeps serving the
/// model in force.

#include <atomic>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include "../core/TestModels.hpp"
#include "mobility_analysis/ros/RosConversions.hpp"
#include "../TextFile.hpp"

using namespace mobility_analysis;

namespace {

constexpr double kWait = 60.0;  ///< Bound of the wait for the node's services [s].
const std::string kServer = "/big/mobility_server";

template <class Service>
bool call(const std::string& name, Service& srv) {
  // One retry on a transport failure (roscpp can lose a non-persistent call's response, ros/ros_comm#1976).
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (ros::service::call(kServer + "/" + name, srv))
      return true;
  }
  return false;
}

}  // namespace

TEST(MobilityServerBigChain, loadRobotOfA140000LinkChainReportsItsDofAndTheNodeKeepsServing) {
  ASSERT_TRUE(ros::service::waitForService(kServer + "/load_robot", ros::Duration(kWait)));
  GetDof before;
  ASSERT_TRUE(call("get_dof", before));
  ASSERT_TRUE(before.response.success) << before.response.message;
  const std::string launched = before.response.robot;  // four_bar: DOF 1

  constexpr int kLinks = 140000;
  LoadRobot load;
  load.request.urdf = straightChainUrdf(kLinks);
  std::atomic<bool> loaded{false};
  bool answered = false;
  std::thread loader([&] {
    answered = call("load_robot", load);
    loaded = true;
  });
  // While the chain is read and analysed, the model in force is still served.
  int servedMeanwhile = 0;
  while (!loaded) {
    GetDof dof;
    if (call("get_dof", dof) && dof.response.success && !loaded) {
      EXPECT_TRUE(dof.response.robot == launched || dof.response.robot == "chain") << dof.response.robot;
      ++servedMeanwhile;
    }
    ros::WallDuration(0.2).sleep();
  }
  loader.join();
  ASSERT_TRUE(answered) << "load_robot got no answer: the node died";
  ASSERT_TRUE(load.response.success) << load.response.message;
  EXPECT_EQ(load.response.robot, "chain");
  EXPECT_EQ(load.response.dof, kLinks);
  EXPECT_EQ(load.response.grubler_kutzbach_dof, kLinks);
  EXPECT_EQ(load.response.num_redundant, 0);
  EXPECT_EQ(static_cast<int>(load.response.links.size()), kLinks + 1);
  EXPECT_EQ(static_cast<int>(load.response.joints.size()), kLinks);
  EXPECT_GT(servedMeanwhile, 0) << "get_dof did not answer while the chain loaded";

  // The node is alive and serves the chain.
  GetDof after;
  ASSERT_TRUE(call("get_dof", after)) << "the node died after the load";
  ASSERT_TRUE(after.response.success) << after.response.message;
  EXPECT_EQ(after.response.robot, "chain");
  EXPECT_EQ(after.response.dof, kLinks);
  EXPECT_EQ(after.response.finite_dof, kLinks);

  // And it still loads a small model afterwards (the four-bar from the bundled files: DOF 1).
  LoadRobot back;
  back.request.urdf = readTextFile(urdfPath("four_bar.urdf"));
  ASSERT_TRUE(call("load_robot", back));
  ASSERT_TRUE(back.response.success) << back.response.message;
  EXPECT_EQ(back.response.dof, 1);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_mobility_server_big_chain");
  return RUN_ALL_TESTS();
}
