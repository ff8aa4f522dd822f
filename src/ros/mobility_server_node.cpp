/// mobility_server: serves the DOF and redundancy of the mechanism in `robot_description` (see
/// MobilityServer).

#include <cstdlib>

#include <ros/ros.h>

#include "mobility_analysis/ros/MobilityServer.hpp"

namespace {
/// Service threads: a long ~load_robot or ~move occupies one, the others keep answering get_dof & co.
constexpr int kServiceThreads = 4;
}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "mobility_server");
  ros::NodeHandle nodeHandle;
  ros::NodeHandle privateNodeHandle("~");
  mobility_analysis::MobilityServer server(nodeHandle, privateNodeHandle);
  if (!server.isConfigured())
    return EXIT_FAILURE;  // ROS_FATAL already said which parameter.
  ros::AsyncSpinner spinner(kServiceThreads);
  spinner.start();
  ros::waitForShutdown();
  return EXIT_SUCCESS;
}
