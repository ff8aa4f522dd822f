/// Integration test of ~deploy (test_mobility_deploy.launch): the node deploys the four-unit SLE mast of
/// urdf/sle_deployable_folded.urdf by its base cable, shows every step, and keeps the deployed structure.
///
/// Expectations come from the mast's geometry (the file's header), never from the core: bars 1 m long at
/// elevation beta (written 10 deg), unit height sin(beta); passive_k joins a unit's left foot to its left
/// top, so its ends are sin(beta) apart, and it is sin(45 deg) long: it goes taut at beta = 45 deg, where the
/// base cable, from the ground pin (0, 0) to the slider pin (cos beta, 0), is cos(45 deg) long. Every tree
/// joint turns with beta: base_pin by beta - 10 deg, slider_pin by the opposite, the pins between units by
/// twice that (alternating signs); base_slide slides by cos(beta) - cos(10 deg).

#include <algorithm>
#include <cmath>
#include <future>
#include <iostream>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "mobility_analysis/Deploy.h"
#include "mobility_analysis/GetDof.h"
#include "mobility_analysis/GetRedundancy.h"
#include "mobility_analysis/mobility_analysis.hpp"
#include "mobility_analysis/ros/RosConversions.hpp"

using namespace mobility_analysis;

namespace {

constexpr double kWait = 30.0;  ///< Bound of every wait [s].
const double kDeg = M_PI / 180.0;
const double kBeta0 = 10.0 * kDeg;     ///< Written elevation.
const double kDeployed = 45.0 * kDeg;  ///< Where the passive cables go taut.
const std::vector<std::string> kPassive = {"passive_1", "passive_2", "passive_3", "passive_4"};

/// Collects NS/joint_states and NS/mobility_server/markers.
class Recorder {
 public:
  Recorder(ros::NodeHandle& nh, const std::string& ns) {
    states_ = nh.subscribe<sensor_msgs::JointState>(ns + "/joint_states", 1000,
                                                    [this](const sensor_msgs::JointStateConstPtr& m) {
                                                      std::lock_guard<std::mutex> lock(mutex_);
                                                      joints_.push_back(*m);
                                                    });
    // Both servers of the launch file publish /tf_static (the frames of their own mast): count this one's by
    // its deployment's stamps, later than the subscription.
    tf_ = nh.subscribe<tf2_msgs::TFMessage>("/tf_static", 1000, [this](const tf2_msgs::TFMessageConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const auto& t : m->transforms) {
        if (t.child_frame_id == "bar_4_b")
          topFrames_.push_back(t);
      }
    });
    markers_ = nh.subscribe<visualization_msgs::MarkerArray>(
        ns + "/mobility_server/markers", 1000, [this](const visualization_msgs::MarkerArrayConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          arrays_.push_back(*m);
        });
  }
  bool connected() {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(kWait);
    while ((states_.getNumPublishers() == 0 || markers_.getNumPublishers() == 0 || arrays().empty()) &&
           ros::WallTime::now() < end) {
      ros::WallDuration(0.02).sleep();
    }
    return states_.getNumPublishers() > 0 && !arrays().empty();
  }
  std::vector<sensor_msgs::JointState> joints() {
    std::lock_guard<std::mutex> lock(mutex_);
    return joints_;
  }
  std::vector<geometry_msgs::TransformStamped> topFrames() {
    std::lock_guard<std::mutex> lock(mutex_);
    return topFrames_;
  }
  std::vector<visualization_msgs::MarkerArray> arrays() {
    std::lock_guard<std::mutex> lock(mutex_);
    return arrays_;
  }
  /// Waits for a marker array whose `forces` legend contains @p text; returns it (empty array on timeout).
  visualization_msgs::MarkerArray waitForLegend(const std::string& text) {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(kWait);
    while (ros::WallTime::now() < end) {
      for (const auto& array : arrays()) {
        for (const auto& m : array.markers) {
          if (m.ns == kForcesNamespace && m.id == 0 && m.text.find(text) != std::string::npos)
            return array;
        }
      }
      ros::WallDuration(0.05).sleep();
    }
    return {};
  }

 private:
  std::mutex mutex_;
  std::vector<sensor_msgs::JointState> joints_;
  std::vector<visualization_msgs::MarkerArray> arrays_;
  std::vector<geometry_msgs::TransformStamped> topFrames_;
  ros::Subscriber states_;
  ros::Subscriber tf_;
  ros::Subscriber markers_;
};

const visualization_msgs::Marker* find(const visualization_msgs::MarkerArray& array, const std::string& ns,
                                       int id) {
  for (const auto& m : array.markers) {
    if (m.ns == ns && m.id == id && m.action == visualization_msgs::Marker::ADD)
      return &m;
  }
  return nullptr;
}

/// Distance between the first and the last point of a line marker (a cable's two ends).
double span(const visualization_msgs::Marker& m) {
  const auto& a = m.points.front();
  const auto& b = m.points.back();
  return std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z));
}

Mechanism loadMast() {
  const Result<Mechanism> mechanism =
      loadMechanismFromFile(std::string(MA_URDF_DIR) + "/sle_deployable_folded.urdf");
  EXPECT_TRUE(isOk(mechanism));
  return valueOf(mechanism);
}

}  // namespace

TEST(MobilityDeploy, badRequestsAreRefusedAndNothingMoves) {
  const std::string server = "/mast/mobility_server";
  ASSERT_TRUE(ros::service::waitForService(server + "/deploy", ros::Duration(kWait)));
  auto refused = [&](const std::string& cable, int steps, double target, const std::string& says) {
    Deploy deploy;
    deploy.request.cable = cable;
    deploy.request.steps = steps;
    deploy.request.target_length = target;
    ASSERT_TRUE(ros::service::call(server + "/deploy", deploy));
    EXPECT_FALSE(deploy.response.success) << cable;
    EXPECT_NE(deploy.response.message.find(says), std::string::npos) << deploy.response.message;
  };
  refused("passive_1", 10, 0.0, "passive");
  refused("nope", 10, 0.0, "nope");
  refused("active_base", -3, 0.0, "steps");
  refused("active_base", 10, -1.0, "target_length");
  GetDof dof;
  ASSERT_TRUE(ros::service::call(server + "/get_dof", dof));
  EXPECT_EQ(dof.response.dof, 1) << "still the folded mast";
}

TEST(MobilityDeploy, theMastDeploysUntilItsPassiveCablesGoTautAndStaysDeployed) {
  const Mechanism mast = loadMast();
  const std::string server = "/mast/mobility_server";
  ros::NodeHandle nh;
  Recorder recorder(nh, "/mast");
  ASSERT_TRUE(recorder.connected());
  ASSERT_TRUE(ros::service::waitForService(server + "/deploy", ros::Duration(kWait)));

  GetRedundancy before;
  ASSERT_TRUE(ros::service::call(server + "/get_redundancy", before));
  ASSERT_TRUE(before.response.success) << before.response.message;
  EXPECT_EQ(before.response.dof, 1) << "folded: one freedom";
  for (const auto& c : before.response.cables) {
    if (c.type == "passive")
      EXPECT_EQ(c.state, "slack") << c.name;
  }

  const ros::Time deployStart = ros::Time::now();
  Deploy deploy;
  deploy.request.cable = "active_base";
  deploy.request.steps = 100;     // 0.00985 m each: the cables go taut in the 29th
  deploy.request.duration = 3.0;  // 33 states a second: rviz (and this test) sees every one
  auto running =
      std::async(std::launch::async, [&] { return ros::service::call(server + "/deploy", deploy); });
  ros::WallDuration(0.5).sleep();  // the first one is on its way (3 s)
  Deploy second = deploy;
  ASSERT_TRUE(ros::service::call(server + "/deploy", second));
  EXPECT_FALSE(second.response.success) << "one deployment at a time";
  EXPECT_NE(second.response.message.find("another deployment"), std::string::npos) << second.response.message;
  ASSERT_TRUE(running.get());
  const auto& r = deploy.response;
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_EQ(r.cable, "active_base");
  EXPECT_NEAR(r.initial_length, std::cos(kBeta0), 1e-12);
  EXPECT_NEAR(r.final_length, std::cos(kDeployed), 1e-7) << "the base cable when the passive ones go taut";
  std::vector<std::string> stopped = r.stopped_by;
  std::sort(stopped.begin(), stopped.end());
  EXPECT_EQ(stopped, kPassive) << "every unit's cable goes taut at once";
  EXPECT_EQ(r.final_dof, 0);
  EXPECT_GE(r.steps, 3);
  EXPECT_LE(r.steps, 102) << "the start, at most 100 steps, the located stop";
  ASSERT_EQ(r.active_lengths.size(), static_cast<size_t>(r.steps));
  for (size_t i = 1; i < r.active_lengths.size(); ++i)
    EXPECT_LT(r.active_lengths[i], r.active_lengths[i - 1]) << "the cable only shortens";
  EXPECT_EQ(r.self_stress.count, 3) << "four taut cables, one of them needed: N - 1 states";
  EXPECT_FALSE(r.self_stress.prestressable) << "all passive cables resist the same motion";

  // The deployed structure stays in force.
  GetRedundancy after;
  ASSERT_TRUE(ros::service::call(server + "/get_redundancy", after));
  ASSERT_TRUE(after.response.success) << after.response.message;
  EXPECT_EQ(after.response.dof, 0) << "deployed: a structure";
  EXPECT_EQ(after.response.num_redundant, 3);
  for (const auto& c : after.response.cables) {
    if (c.type == "passive") {
      EXPECT_EQ(c.state, "taut") << c.name;
      EXPECT_NEAR(c.distance, std::sin(kDeployed), 1e-7) << c.name;
    }
  }
  bool warned = false;
  for (const auto& w : after.response.warnings)
    warned = warned || w.find("deploying") != std::string::npos;
  EXPECT_FALSE(warned) << "the final state carries its own full analysis";

  // joint_states along the way: loops closed at every state (the slide follows the pin), each joint monotone,
  // and the final values are the closed form at 45 deg.
  ros::WallDuration(0.3).sleep();
  const std::vector<sensor_msgs::JointState> states = recorder.joints();
  ASSERT_GE(states.size(), 10u);
  std::map<std::string, std::vector<double>> series;
  for (const auto& s : states) {
    std::map<std::string, double> v;
    for (size_t i = 0; i < s.name.size(); ++i)
      v[s.name[i]] = s.position[i];
    ASSERT_EQ(v.count("base_pin"), 1u);
    const double beta = kBeta0 + std::abs(v.at("base_pin"));
    EXPECT_NEAR(std::abs(v.at("base_slide")), std::cos(kBeta0) - std::cos(beta), 1e-6)
        << "the slider sits at cos(beta)";
    EXPECT_NEAR(std::abs(v.at("slider_pin")), beta - kBeta0, 1e-6);
    for (const std::string& pin : {"left_pin_2", "right_pin_2", "left_pin_3", "right_pin_4"})
      EXPECT_NEAR(std::abs(v.at(pin)), 2.0 * (beta - kBeta0), 1e-6) << pin;
    for (const auto& [name, value] : v)
      series[name].push_back(value);
  }
  int moved = 0;
  for (const auto& [name, values] : series) {
    SCOPED_TRACE(name);
    const double sign = values.back() >= values.front() ? 1.0 : -1.0;
    for (size_t i = 1; i < values.size(); ++i)
      EXPECT_GE(sign * (values[i] - values[i - 1]), -1e-9) << "state " << i << " goes back";
    moved += std::abs(values.back() - values.front()) > 1e-3;
  }
  EXPECT_EQ(moved, 9) << "every tree joint moves";
  EXPECT_NEAR(std::abs(series.at("base_pin").back()), kDeployed - kBeta0, 1e-7);
  EXPECT_NEAR(std::abs(series.at("base_slide").back()), std::cos(kBeta0) - std::cos(kDeployed), 1e-7);
  EXPECT_NEAR(std::abs(series.at("left_pin_4").back()), 2.0 * (kDeployed - kBeta0), 1e-7);
  EXPECT_NEAR(series.at("base_pin").front(), 0.0, 1e-9) << "it started folded";

  // tf per step: the top unit's frame, once per published state, rising with the mast.
  std::vector<double> rise;
  for (const auto& t : recorder.topFrames()) {
    if (t.header.stamp >= deployStart)
      rise.push_back(t.transform.translation.y);
  }
  EXPECT_GE(rise.size(), static_cast<size_t>(r.steps)) << "tf of every state";
  for (size_t i = 1; i < rise.size(); ++i)
    EXPECT_GE(rise[i], rise[i - 1] - 1e-9) << "the top unit only rises";
  ASSERT_FALSE(rise.empty());
  EXPECT_GT(rise.back(), rise.front() + 0.1);

  // Markers: every array is one pose, slack cables dashed and taut ones solid at that pose, the base cable as
  // long as that pose's closed form; the first slack, the last taut.
  const std::vector<visualization_msgs::MarkerArray> arrays = recorder.arrays();
  ASSERT_GE(arrays.size(), 10u) << "markers per step";
  const int passive1 = *mast.findJoint("passive_1");
  const int active = *mast.findJoint("active_base");
  int slack = 0, taut = 0;
  for (size_t i = 0; i < arrays.size(); ++i) {
    SCOPED_TRACE("marker array " + std::to_string(i));
    const auto* cable = find(arrays[i], kJointsNamespace, passive1);
    const auto* driver = find(arrays[i], kJointsNamespace, active);
    ASSERT_TRUE(cable && driver);
    const double unitHeight = span(*cable);  // sin(beta)
    const bool isTaut = unitHeight >= std::sin(kDeployed) * (1.0 - 1e-6);
    EXPECT_EQ(cable->points.size() == 2u, isTaut) << "height " << unitHeight;
    EXPECT_NEAR(span(*driver), std::sqrt(1.0 - unitHeight * unitHeight), 1e-6) << "one pose per array";
    (isTaut ? taut : slack) += 1;
  }
  const auto* first = find(arrays.front(), kJointsNamespace, passive1);
  const auto* last = find(arrays.back(), kJointsNamespace, passive1);
  EXPECT_GT(first->points.size(), 2u) << "folded: dashed";
  EXPECT_EQ(last->points.size(), 2u) << "deployed: solid";
  EXPECT_GT(slack, 5);
  EXPECT_GE(taut, 1);
  std::cout << states.size() << " joint_states and " << arrays.size() << " marker arrays (" << slack
            << " slack, " << taut << " taut) during the deployment" << std::endl;

  // The forces namespace shows state 0 of the deployed mast (not prestressable): some elements coloured.
  int coloured = 0;
  for (const auto& m : arrays.back().markers) {
    if (m.ns == kForcesNamespace && m.id > 0 &&
        std::max({m.color.r, m.color.g, m.color.b}) - std::min({m.color.r, m.color.g, m.color.b}) > 0.3f)
      ++coloured;
  }
  EXPECT_GE(coloured, 1);
  const auto* legend = find(arrays.back(), kForcesNamespace, 0);
  ASSERT_NE(legend, nullptr);
  EXPECT_NE(legend->text.find("state of self-stress 0 of 3"), std::string::npos) << legend->text;

  // ~forces_state chooses: the prestress (none here), then state 2.
  ros::param::set(server + "/forces_state", -1);
  const auto none = recorder.waitForLegend("no prestress");
  EXPECT_FALSE(none.markers.empty()) << "redrawn for ~forces_state -1";
  for (const auto& m : none.markers)
    EXPECT_FALSE(m.ns == kForcesNamespace && m.id > 0) << "no element without a prestress";
  ros::param::set(server + "/forces_state", 2);
  const auto two = recorder.waitForLegend("state of self-stress 2 of 3");
  int elements = 0;
  for (const auto& m : two.markers)
    elements += m.ns == kForcesNamespace && m.id > 0;
  EXPECT_GE(elements, 2) << "state 2 drawn";
  ros::param::del(server + "/forces_state");

  GetDof dof;
  ASSERT_TRUE(ros::service::call(server + "/get_dof", dof));
  EXPECT_EQ(dof.response.dof, 0) << "still deployed";
}

TEST(MobilityDeploy, withTheActiveCableLockedTheDeployedMastIsPrestressedInTension) {
  const Mechanism mast = loadMast();
  const std::string server = "/locked/mobility_server";
  ros::NodeHandle nh;
  Recorder recorder(nh, "/locked");
  ASSERT_TRUE(recorder.connected());
  ASSERT_TRUE(ros::service::waitForService(server + "/deploy", ros::Duration(kWait)));
  Deploy deploy;
  deploy.request.cable = "active_base";
  deploy.request.steps = 25;
  deploy.request.lock_active_cables = true;
  ASSERT_TRUE(ros::service::call(server + "/deploy", deploy));
  ASSERT_TRUE(deploy.response.success) << deploy.response.message;
  EXPECT_NEAR(deploy.response.final_length, std::cos(kDeployed), 1e-7);
  EXPECT_EQ(deploy.response.final_dof, 0);
  EXPECT_EQ(deploy.response.self_stress.count, 4) << "the locked base cable adds one";
  EXPECT_TRUE(deploy.response.self_stress.prestressable);

  // Automatic choice: the prestress, every cable in tension (blue).
  const auto array = recorder.waitForLegend("prestress");
  ASSERT_FALSE(array.markers.empty());
  const int numLinks = static_cast<int>(mast.links.size());
  std::set<std::string> inTension;
  for (const auto& m : array.markers) {
    if (m.ns != kForcesNamespace || m.id <= numLinks ||
        m.id > numLinks + static_cast<int>(mast.joints.size()))
      continue;
    const Joint& joint = mast.joints[m.id - 1 - numLinks];
    if (joint.kind == ConnectionKind::Cable && m.color.b > m.color.r + 0.3f)
      inTension.insert(joint.name);
  }
  EXPECT_EQ(inTension,
            (std::set<std::string>{"active_base", "passive_1", "passive_2", "passive_3", "passive_4"}));
  GetDof dof;
  ASSERT_TRUE(ros::service::call(server + "/get_dof", dof));
  EXPECT_EQ(dof.response.dof, 0);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_mobility_deploy");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
