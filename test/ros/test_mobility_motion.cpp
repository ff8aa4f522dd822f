/// Integration test of the node following a mechanism as it moves (test_mobility_motion.launch): joint states
/// in and out against closed-form position analyses, ~move, and the node under load.
///
/// The launch file starts two servers: /crank (urdf/four_bar.urdf, a Grashof crank-rocker) and /bennett
/// (urdf/bennett.urdf). Expectations come from the geometry written in those files' headers, never from the
/// core.

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <future>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include "mobility_analysis/Move.h"
#include "mobility_analysis/mobility_analysis.hpp"
#include "mobility_analysis/ros/RosConversions.hpp"
#include "../TextFile.hpp"

using namespace mobility_analysis;

namespace {

constexpr double kWait = 30.0;      ///< Bound of every wait [s].
constexpr double kAngleTol = 1e-6;  ///< Closed form vs node [rad] (the issue's bound).

/// a - b wrapped into (-pi, pi].
double angleDiff(double a, double b) {
  return std::remainder(a - b, 2.0 * M_PI);
}

/// Publishes on NS/input_joint_states and collects NS/joint_states by stamp.
class StateClient {
 public:
  StateClient(ros::NodeHandle& nh, const std::string& ns) {
    publisher_ = nh.advertise<sensor_msgs::JointState>(ns + "/input_joint_states", 10);
    subscriber_ = nh.subscribe<sensor_msgs::JointState>(ns + "/joint_states", 100,
                                                        [this](const sensor_msgs::JointStateConstPtr& m) {
                                                          std::lock_guard<std::mutex> lock(mutex_);
                                                          states_.push_back(*m);
                                                        });
  }
  /// Waits until the server listens.
  bool connected() {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(kWait);
    while ((publisher_.getNumSubscribers() == 0 || subscriber_.getNumPublishers() == 0) &&
           ros::WallTime::now() < end) {
      ros::WallDuration(0.02).sleep();
    }
    return publisher_.getNumSubscribers() > 0 && subscriber_.getNumPublishers() > 0;
  }
  /// Sends one input stamped @p stamp and returns the joint values answered with that stamp (empty on
  /// timeout).
  std::map<std::string, double> drive(const std::map<std::string, double>& input, const ros::Time& stamp) {
    sensor_msgs::JointState message;
    message.header.stamp = stamp;
    for (const auto& [name, value] : input) {
      message.name.push_back(name);
      message.position.push_back(value);
    }
    publisher_.publish(message);
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(kWait);
    while (ros::WallTime::now() < end) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        for (const auto& s : states_) {
          if (s.header.stamp == stamp) {
            std::map<std::string, double> out;
            for (size_t i = 0; i < s.name.size(); ++i)
              out[s.name[i]] = s.position[i];
            return out;
          }
        }
      }
      ros::WallDuration(0.005).sleep();
    }
    return {};
  }
  std::vector<sensor_msgs::JointState> received() {
    std::lock_guard<std::mutex> lock(mutex_);
    return states_;
  }
  void clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    states_.clear();
  }

 private:
  ros::Publisher publisher_;
  std::mutex mutex_;
  std::vector<sensor_msgs::JointState> states_;
  ros::Subscriber subscriber_;
};

/// Crank-rocker of urdf/four_bar.urdf: ground A(0,0)-D(1,0), crank AB 0.35, coupler BC 1.1, rocker CD 0.8,
/// crank written at 60 deg, C on the side of B->D where it is written. Closed-form position analysis.
struct CrankRocker {
  const Eigen::Vector2d A{0.0, 0.0}, D{1.0, 0.0};
  const double crank = 0.35, coupler = 1.1, rocker = 0.8, phi0 = M_PI / 3.0;

  Eigen::Vector2d B(double phi) const { return A + crank * Eigen::Vector2d(std::cos(phi), std::sin(phi)); }
  /// Intersection of circles (B, coupler) and (D, rocker) on the side @p side of B->D.
  Eigen::Vector2d C(double phi, double side) const {
    const Eigen::Vector2d b = B(phi);
    const double d = (D - b).norm();
    const Eigen::Vector2d u = (D - b) / d;
    const double a = (coupler * coupler - rocker * rocker + d * d) / (2.0 * d);
    const double h = std::sqrt(coupler * coupler - a * a);
    return b + a * u + side * h * Eigen::Vector2d(-u.y(), u.x());
  }
  static double angle(const Eigen::Vector2d& v) { return std::atan2(v.y(), v.x()); }
  /// (crank_coupler, coupler_rocker) tree values for crank value @p q1, relative to the written pose.
  std::pair<double, double> joints(double q1) const {
    const double side = +1.0;  // written: cross(D - B, C - B) > 0 (checked in the test)
    const Eigen::Vector2d b0 = B(phi0), c0 = C(phi0, side), b = B(phi0 + q1), c = C(phi0 + q1, side);
    const double q2 = angle(c - b) - angle(c0 - b0) - q1;
    const double q3 = angle(D - c) - angle(D - c0) - q1 - q2;
    return {q2, q3};
  }
};

/// Bennett of urdf/bennett.urdf: alpha 40 deg, beta 70 deg, written at theta1 = 100 deg; DESIGN.md §5
/// closure.
struct Bennett {
  const double alpha = 40.0 * M_PI / 180.0, beta = 70.0 * M_PI / 180.0, theta10 = 100.0 * M_PI / 180.0;
  double theta2(double theta1) const {
    const double k = std::sin((beta + alpha) / 2.0) / std::sin((beta - alpha) / 2.0);
    return 2.0 * std::atan2(k, std::tan(theta1 / 2.0));  // tan(t1/2) tan(t2/2) = k
  }
  /// (j2, j3) tree values for j1 value @p q1, relative to the written pose.
  std::pair<double, double> joints(double q1) const {
    return {theta2(theta10 + q1) - theta2(theta10), -q1};  // theta3 = -theta1
  }
};

/// Loop residual of the published tree values: forward kinematics, then every loop joint's residual [m].
double loopResidual(const Mechanism& mechanism, const sensor_msgs::JointState& state, double length) {
  JointPositions positions;
  for (size_t i = 0; i < state.name.size(); ++i)
    positions[state.name[i]] = state.position[i];
  const LinkPoses poses = computeTreePoses(mechanism, positions);
  double worst = 0.0;
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    if (mechanism.joints[j].kind == ConnectionKind::LoopJoint) {
      worst = std::max(worst, computeJointResidual(mechanism, poses, static_cast<int>(j), length));
    }
  }
  return worst;
}

}  // namespace

TEST(MobilityMotion, crankRockerFollowsTheClosedFormOverAFullTurn) {
  const CrankRocker closedForm;
  {  // The branch the closed form assumes is the written one.
    const Eigen::Vector2d b = closedForm.B(closedForm.phi0), c = closedForm.C(closedForm.phi0, 1.0);
    const Eigen::Vector2d db = closedForm.D - b, cb = c - b;
    ASSERT_GT(db.x() * cb.y() - db.y() * cb.x(), 0.0);
    ASSERT_NEAR(
        (c - Eigen::Vector2d(0.175 + 0.9898857843480466, 0.3031088913245535 + 0.47971463803562736)).norm(),
        0.0, 1e-9)
        << "the written coupler-rocker pin";
  }
  ros::NodeHandle nh;
  StateClient client(nh, "/crank");
  ASSERT_TRUE(client.connected());
  const int steps = 72;
  for (int k = 0; k <= steps; ++k) {
    const double q1 = 2.0 * M_PI * k / steps;
    SCOPED_TRACE("crank value " + std::to_string(q1));
    const auto answer = client.drive({{"ground_crank", q1}}, ros::Time(1000 + k));
    ASSERT_FALSE(answer.empty()) << "no joint_states for this input";
    ASSERT_EQ(answer.size(), 3u) << "every 1-DOF tree joint";
    const auto [q2, q3] = closedForm.joints(q1);
    EXPECT_NEAR(angleDiff(answer.at("ground_crank"), q1), 0.0, kAngleTol) << "the driven value is held";
    EXPECT_NEAR(angleDiff(answer.at("crank_coupler"), q2), 0.0, kAngleTol);
    EXPECT_NEAR(angleDiff(answer.at("coupler_rocker"), q3), 0.0, kAngleTol);
  }
}

TEST(MobilityMotion, bennettFollowsItsClosureOverAFullTurn) {
  const Bennett closedForm;
  ros::NodeHandle nh;
  StateClient client(nh, "/bennett");
  ASSERT_TRUE(client.connected());
  const int steps = 72;
  for (int k = 0; k <= steps; ++k) {
    const double q1 = 2.0 * M_PI * k / steps;
    SCOPED_TRACE("j1 value " + std::to_string(q1));
    const auto answer = client.drive({{"j1", q1}}, ros::Time(2000 + k));
    ASSERT_FALSE(answer.empty()) << "no joint_states for this input";
    const auto [q2, q3] = closedForm.joints(q1);
    EXPECT_NEAR(angleDiff(answer.at("j1"), q1), 0.0, kAngleTol);
    EXPECT_NEAR(angleDiff(answer.at("j2"), q2), 0.0, kAngleTol);
    EXPECT_NEAR(angleDiff(answer.at("j3"), q3), 0.0, kAngleTol);
  }
}

TEST(MobilityMotion, unreachableInputKeepsTheLastGoodState) {
  // The rocker of the crank-rocker swings between two dead points: it cannot be driven a full turn.
  ros::NodeHandle nh;
  StateClient client(nh, "/crank");
  ASSERT_TRUE(client.connected());
  const auto good = client.drive({{"ground_crank", 0.0}}, ros::Time(3000));
  ASSERT_FALSE(good.empty());
  const auto stuck = client.drive({{"coupler_rocker", good.at("coupler_rocker") + 3.0}}, ros::Time(3001));
  ASSERT_FALSE(stuck.empty()) << "an unreachable input is still answered (with the last good state)";
  for (const auto& [name, value] : good)
    EXPECT_NEAR(stuck.at(name), value, 1e-12) << name;
}

TEST(MobilityMotion, moveSweepsTheBennettWithItsLoopClosed) {
  const Mechanism mechanism = valueOf(loadMechanismFromFile(std::string(MA_URDF_DIR) + "/bennett.urdf"));
  ros::NodeHandle nh;
  StateClient client(nh, "/bennett");
  ASSERT_TRUE(client.connected());
  ASSERT_TRUE(ros::service::waitForService("/bennett/mobility_server/move", ros::Duration(kWait)));
  client.clear();
  Move move;
  move.request.free_direction = 0;
  move.request.start = 0.0;
  move.request.end = 2.0 * M_PI;
  move.request.steps = 61;
  move.request.duration = 3.0;  // 20 states a second: none dropped on the way
  ASSERT_TRUE(ros::service::call("/bennett/mobility_server/move", move));
  ASSERT_TRUE(move.response.success) << move.response.message;
  EXPECT_EQ(move.response.driveable_joints, std::vector<std::string>{"j1"}) << "DOF 1, the first tree joint";
  EXPECT_EQ(move.response.joint, "j1");
  EXPECT_EQ(move.response.states, 61);
  const double length = move.response.characteristic_length;
  EXPECT_LT(move.response.max_residual, 1e-9 * length);
  // Independently: the published tree values close the loop (forward kinematics of the file).
  ros::WallDuration(0.5).sleep();
  const std::vector<sensor_msgs::JointState> states = client.received();
  EXPECT_GE(states.size(), 61u);
  double worst = 0.0;
  for (const auto& s : states)
    worst = std::max(worst, loopResidual(mechanism, s, length));
  EXPECT_LT(worst, 1e-9 * length) << "largest loop residual of the published states";

  Move bad;
  bad.request.joint = "j4";  // the loop joint has no value of its own
  bad.request.steps = 3;
  ASSERT_TRUE(ros::service::call("/bennett/mobility_server/move", bad));
  EXPECT_FALSE(bad.response.success);
  EXPECT_NE(bad.response.message.find("j4"), std::string::npos) << bad.response.message;
}

TEST(MobilityMotion, getDofAnswersFromTheModelInForceWhileALargeMastLoads) {
  // A 3 10^4-unit spatial scissor mast takes about a second to analyse; get_dof must keep answering within
  // 100 ms. (10^4 units had come down to 0.45 s, six get_dof calls at 50 ms: the load was too quick to test.)
  const std::string mast = "/tmp/mobility_motion_test_mast_" + std::to_string(getpid()) + ".urdf";
  ASSERT_EQ(std::system((std::string(MA_GENERATE_EXE) + " sle_spatial 30000 > " + mast).c_str()), 0);
  const std::string server = "/crank/mobility_server";
  ASSERT_TRUE(ros::service::waitForService(server + "/get_dof", ros::Duration(kWait)));
  ros::NodeHandle nh;
  ros::ServiceClient getDof = nh.serviceClient<GetDof>(server + "/get_dof", true);

  LoadRobot load;
  load.request.urdf = readTextFile(mast);
  load.request.mode = "spatial";
  std::remove(mast.c_str());
  std::atomic<bool> loading{true};
  auto loaded = std::async(std::launch::async, [&] {
    const bool ok = ros::service::call(server + "/load_robot", load);
    loading = false;
    return ok;
  });
  ros::WallDuration(0.2).sleep();  // the request is on its way and being analysed
  int answered = 0;
  double slowest = 0.0;
  while (loading) {
    GetDof dof;
    const auto start = std::chrono::steady_clock::now();
    ASSERT_TRUE(getDof.call(dof));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_TRUE(dof.response.success) << dof.response.message;
    // Once swapped in, the new model answers (its 10^5-entry response is no longer a call during the load).
    if (!loading || dof.response.robot != "four_bar")
      break;
    ++answered;
    slowest = std::max(slowest, seconds);
    ros::WallDuration(0.05).sleep();
  }
  ASSERT_TRUE(loaded.get());
  ASSERT_TRUE(load.response.success) << load.response.message;
  EXPECT_EQ(load.response.robot, "sle_spatial_30000");
  EXPECT_EQ(load.response.dof, 1);
  EXPECT_GT(answered, 5) << "the load was too quick to test anything";
  EXPECT_LT(slowest, 0.1) << "slowest get_dof during the load [s]";
  std::cout << answered << " get_dof calls during the load, slowest " << slowest << " s" << std::endl;

  GetDof after;
  ASSERT_TRUE(getDof.call(after));
  EXPECT_EQ(after.response.robot, "sle_spatial_30000");

  // Restore the crank-rocker for the tests that may follow.
  LoadRobot restore;
  restore.request.urdf = readTextFile(std::string(MA_URDF_DIR) + "/four_bar.urdf");
  ASSERT_TRUE(ros::service::call(server + "/load_robot", restore));
  EXPECT_TRUE(restore.response.success) << restore.response.message;
  std::string description;
  EXPECT_TRUE(ros::param::get("/crank/robot_description", description));
  EXPECT_EQ(description, restore.request.urdf) << "~load_robot sets robot_description";
}

TEST(MobilityMotion, aLoadLongerThanTheTimeoutIsRefusedAndTheModelStays) {
  // /timeout runs with ~load_timeout 0.2 s: reading and analysing a 10^4-unit mast in space takes longer (about
  // 1 s in the CLI on a 2-core machine), so it is refused.
  const std::string mast = "/tmp/mobility_motion_test_timeout_" + std::to_string(getpid()) + ".urdf";
  ASSERT_EQ(std::system((std::string(MA_GENERATE_EXE) + " sle_spatial 10000 > " + mast).c_str()), 0);
  LoadRobot load;
  load.request.urdf = readTextFile(mast);
  load.request.mode = "spatial";
  std::remove(mast.c_str());
  ASSERT_TRUE(ros::service::waitForService("/timeout/mobility_server/load_robot", ros::Duration(kWait)));
  ASSERT_TRUE(ros::service::call("/timeout/mobility_server/load_robot", load));
  EXPECT_FALSE(load.response.success);
  EXPECT_NE(load.response.message.find("load_timeout"), std::string::npos) << load.response.message;
  EXPECT_EQ(load.response.robot, "bennett") << "the full report of the model still served";
  EXPECT_EQ(load.response.dof, 1);
  GetDof dof;
  ASSERT_TRUE(ros::service::call("/timeout/mobility_server/get_dof", dof));
  EXPECT_TRUE(dof.response.success);
  EXPECT_EQ(dof.response.robot, "bennett");
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_mobility_motion");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
