/// Integration test of the running `mobility_server` node (launched by test_mobility_server*.launch).
///
/// Private parameters: ~urdf_file (the model the launch file put in robot_description), ~mode, ~expect_redundant
/// (whether the model is over-constrained), ~server (the node's name, default /mobility_server).

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <mutex>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpcClient.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/MarkerArray.h>

#include "mobility_analysis/mobility_analysis.hpp"
#include "mobility_analysis/ros/RosConversions.hpp"
#include "../TextFile.hpp"

extern char** environ;

using namespace mobility_analysis;

namespace {

constexpr double kWait = 30.0;  ///< Bound of every wait loop [s].

struct Config {
  std::string urdfFile, modeText = "auto", server = "/mobility_server";
  std::string closuresFile;  ///< ~closures of the launched node (a Gepetto closure file), empty: none.
  bool expectRedundant = false;
};
Config config;

/// How the launched node reads its model: with its closure file, if any.
ReadOptions readOptions() {
  ReadOptions options;
  options.closuresFile = config.closuresFile;
  return options;
}

/// The report the core computes in-process for the launched model, as the node read it.
MobilityReport expectedReport() {
  const Result<Mechanism> mechanism =
      readMechanismFromString(readTextFile(config.urdfFile), "robot_description", readOptions());
  EXPECT_TRUE(isOk(mechanism));
  AnalysisOptions options;
  options.mode = valueOf(parseAnalysisMode(config.modeText));
  const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), options);
  EXPECT_TRUE(isOk(analysis));
  return valueOf(analysis).report;
}

Mechanism launchedMechanism() { return valueOf(readMechanism(config.urdfFile, readOptions())); }

int transportRetries = 0;  ///< Non-persistent calls that had to be repeated (see call()).

/**
 * A non-persistent call of the server's service @p name. roscpp's client can lose the response of a
 * non-persistent call when the server's close (POLLRDHUP) is seen first (ros/ros_comm#1976, a client-side race
 * of roscpp itself); such a transport failure is retried, at most twice, and counted. Answers are never retried.
 */
template <class Service>
bool call(const std::string& name, Service& srv) {
  for (int attempt = 0; attempt < 3; ++attempt) {
    if (ros::service::call(config.server + "/" + name, srv)) return true;
    ++transportRetries;
  }
  return false;
}

/// Runs @p command and returns its stdout and exit status.
std::pair<std::string, int> run(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return {"", -1};
  std::array<char, 4096> buffer;
  size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) out.append(buffer.data(), n);
  const int status = pclose(pipe);
  return {out, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

/// Latest marker array on the server's ~markers, waiting (bounded) for the first one.
class MarkerCatcher {
 public:
  explicit MarkerCatcher(ros::NodeHandle& nh) {
    subscriber_ = nh.subscribe<visualization_msgs::MarkerArray>(
        config.server + "/markers", 10, [this](const visualization_msgs::MarkerArrayConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          last_ = *m;
          ++count_;
        });
  }
  ~MarkerCatcher() { subscriber_.shutdown(); }
  /// Waits until more than @p seen arrays arrived; false after kWait.
  bool waitBeyond(int seen) {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(kWait);
    while (count_ <= seen && ros::WallTime::now() < end && ros::ok()) {
      ros::WallDuration(0.01).sleep();
    }
    return count_ > seen;
  }
  int count() const { return count_; }
  visualization_msgs::MarkerArray last() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_;
  }

 private:
  mutable std::mutex mutex_;
  visualization_msgs::MarkerArray last_;
  std::atomic<int> count_{0};
  ros::Subscriber subscriber_;  ///< Last member: unsubscribed (waiting for a running callback) before the rest goes.
};

std::string titleOf(const visualization_msgs::MarkerArray& array) {
  for (const auto& m : array.markers) {
    if (m.ns == kTitleNamespace) return m.text;
  }
  return "";
}

/// Resident set size of process @p pid [kB], from /proc.
long residentKb(int pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

/// Process id of the node @p name, asked from the node itself over its XML-RPC API.
int nodePid(const std::string& name) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  args[1] = name;
  if (!ros::master::execute("lookupNode", args, result, payload, true)) return -1;
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(static_cast<std::string>(payload), host, port)) return -1;
  XmlRpc::XmlRpcClient client(host.c_str(), port, "/");
  XmlRpc::XmlRpcValue pidArgs, pidResult;
  pidArgs[0] = ros::this_node::getName();
  if (!client.execute("getPid", pidArgs, pidResult) || pidResult.size() < 3) return -1;
  return static_cast<int>(pidResult[2]);
}

/// A server we start ourselves (for start-up failures); killed by its pid when it goes out of scope.
class OwnServer {
 public:
  explicit OwnServer(const std::vector<std::string>& arguments) {
    std::vector<std::string> argv = {MA_SERVER_EXE};
    argv.insert(argv.end(), arguments.begin(), arguments.end());
    std::vector<char*> raw;
    for (std::string& a : argv) raw.push_back(a.data());
    raw.push_back(nullptr);
    if (posix_spawn(&pid_, MA_SERVER_EXE, nullptr, nullptr, raw.data(), environ) != 0) pid_ = -1;
  }
  ~OwnServer() {
    if (pid_ > 0 && !exited_) {
      kill(pid_, SIGINT);
      waitForExit(10.0);
      if (!exited_) kill(pid_, SIGKILL), waitpid(pid_, nullptr, 0);
    }
  }
  /// Waits (bounded) for the process to end; its exit status, or -1 if still running.
  int waitForExit(double seconds) {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
    while (ros::WallTime::now() < end) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
      }
      ros::WallDuration(0.05).sleep();
    }
    return -1;
  }
  int pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
  bool exited_ = false;
};

}  // namespace

TEST(MobilityServer, servicesAnswerLikeTheCoreAndTheCli) {
  ASSERT_TRUE(ros::service::waitForService(config.server + "/get_redundancy", ros::Duration(kWait)));
  ASSERT_TRUE(ros::service::waitForService(config.server + "/get_dof", ros::Duration(kWait)));
  const MobilityReport expected = expectedReport();

  GetRedundancy redundancy;
  ASSERT_TRUE(call("get_redundancy", redundancy));
  ASSERT_TRUE(redundancy.response.success) << redundancy.response.message;
  EXPECT_TRUE(redundancy.response.message.empty());
  MobilityReport served = fromResponse(redundancy.response);
  served.file = expected.file;  // "robot_description", or "load_robot" when a test before restored the model
  EXPECT_EQ(toJson(served), toJson(expected));
  EXPECT_EQ(redundancy.response.num_redundant > 0, config.expectRedundant);
  EXPECT_EQ(redundancy.response.num_redundant, redundancy.response.dof - redundancy.response.grubler_kutzbach_dof);

  GetDof dof;
  ASSERT_TRUE(call("get_dof", dof));
  ASSERT_TRUE(dof.response.success) << dof.response.message;
  EXPECT_EQ(dof.response.robot, expected.robot);
  EXPECT_EQ(dof.response.mode, expected.mode);
  EXPECT_EQ(dof.response.lambda, expected.lambda);
  EXPECT_EQ(dof.response.dof, expected.dof);
  EXPECT_EQ(dof.response.grubler_kutzbach_dof, expected.grublerKutzbachDof);
  EXPECT_EQ(dof.response.num_coordinates, expected.numCoordinates);
  EXPECT_EQ(dof.response.num_constraints, expected.numConstraints);
  EXPECT_EQ(dof.response.rank, expected.rank);
  EXPECT_EQ(dof.response.num_redundant, expected.numRedundant);
  EXPECT_EQ(std::vector<int>(dof.response.nullity_trace.begin(), dof.response.nullity_trace.end()),
            expected.nullityTrace);

  // The CLI on the same file: its JSON must equal the response's, the file field aside (the node read a parameter).
  if (access(MA_REPORT_EXE, X_OK) != 0) {
    ADD_FAILURE() << "CLI " << MA_REPORT_EXE << " not built";
    return;
  }
  const std::string closures = config.closuresFile.empty() ? "" : " --closures '" + config.closuresFile + "'";
  const auto [json, status] = run(std::string(MA_REPORT_EXE) + " '" + config.urdfFile + "' --mode " +
                                  config.modeText + closures + " --json");
  ASSERT_EQ(status, 0) << json;
  MobilityReport fromService = fromResponse(redundancy.response);
  fromService.file = launchedMechanism().file;
  EXPECT_EQ(toJson(fromService), json);
}

TEST(MobilityServer, posesFromTheRequestAreAnalysedWithoutChangingTheModel) {
  const Mechanism mechanism = launchedMechanism();
  std::string treeJoint;
  for (const Joint& j : mechanism.joints) {
    if (j.kind == ConnectionKind::TreeJoint && j.type != JointType::Fixed && j.type != JointType::Floating) {
      treeJoint = j.name;
      break;
    }
  }
  ASSERT_FALSE(treeJoint.empty());
  GetDof dof;
  dof.request.joint_names = {treeJoint};
  dof.request.positions = {0.05};
  ASSERT_TRUE(call("get_dof", dof));
  ASSERT_TRUE(dof.response.success) << dof.response.message;
  EXPECT_EQ(dof.response.dof, expectedReport().dof);
}

TEST(MobilityServer, badRequestsOfEachClassAreAnsweredAndTheModelStays) {
  const Mechanism mechanism = launchedMechanism();
  const std::string treeJoint = mechanism.joints.front().name;
  struct BadCase {
    std::vector<std::string> names;
    std::vector<double> values;
    std::string mustMention;
  };
  std::vector<BadCase> cases = {
      {{treeJoint, treeJoint + "_x"}, {0.1}, "1 values for 2"},                           // sizes differ
      {{"no_such_joint"}, {0.1}, "no_such_joint"},                                       // unknown joint
      {{treeJoint}, {std::numeric_limits<double>::quiet_NaN()}, treeJoint},              // not finite
      {{treeJoint}, {std::numeric_limits<double>::infinity()}, treeJoint},               // not finite
  };
  for (const Joint& j : mechanism.joints) {
    if (j.kind == ConnectionKind::LoopJoint) {
      cases.push_back({{j.name}, {0.1}, j.name});  // a loop joint has no value of its own
      break;
    }
  }
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.mustMention);
    GetDof dof;
    dof.request.joint_names = c.names;
    dof.request.positions = c.values;
    ASSERT_TRUE(call("get_dof", dof));
    EXPECT_FALSE(dof.response.success);
    EXPECT_NE(dof.response.message.find(c.mustMention), std::string::npos) << dof.response.message;
    GetRedundancy redundancy;
    redundancy.request.joint_names = c.names;
    redundancy.request.positions = c.values;
    ASSERT_TRUE(call("get_redundancy", redundancy));
    EXPECT_FALSE(redundancy.response.success);
    EXPECT_NE(redundancy.response.message.find(c.mustMention), std::string::npos) << redundancy.response.message;
  }
  GetDof after;
  ASSERT_TRUE(call("get_dof", after));
  EXPECT_TRUE(after.response.success);
  EXPECT_EQ(after.response.dof, expectedReport().dof);
}

TEST(MobilityServer, markersAreLatchedColouredAndLabelled) {
  ros::NodeHandle nh;
  MarkerCatcher markers(nh);
  ASSERT_TRUE(markers.waitBeyond(0)) << "no latched MarkerArray on " << config.server << "/markers";
  const visualization_msgs::MarkerArray array = markers.last();
  const Mechanism mechanism = launchedMechanism();
  const MobilityReport expected = expectedReport();
  ASSERT_FALSE(array.markers.empty());
  EXPECT_EQ(array.markers.front().action, visualization_msgs::Marker::DELETEALL);
  int links = 0, joints = 0, labels = 0, red = 0;
  const int numLinks = static_cast<int>(mechanism.links.size());
  for (size_t i = 1; i < array.markers.size(); ++i) {
    const auto& m = array.markers[i];
    SCOPED_TRACE(m.ns + "/" + std::to_string(m.id));
    EXPECT_EQ(m.header.frame_id, mechanism.links[mechanism.rootLink].name);
    EXPECT_GT(m.scale.x, 0.0);
    EXPECT_GT(m.scale.y, 0.0);
    EXPECT_GT(m.scale.z, 0.0);
    EXPECT_GT(m.color.a, 0.0f);
    const auto& q = m.pose.orientation;
    EXPECT_NEAR(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w, 1.0, 1e-6);
    if (m.color.r == 1.0f && m.color.g == 0.0f && m.color.b == 0.0f) ++red;
    if (m.ns == kLinksNamespace) {
      ++links;
      const auto c = toColor(expected.links.at(m.id).elementClass, true);
      EXPECT_TRUE(m.color.r == c.r && m.color.g == c.g && m.color.b == c.b);
    } else if (m.ns == kJointsNamespace) {
      ++joints;
      const auto c = toColor(expected.joints.at(m.id).elementClass, false);
      EXPECT_TRUE(m.color.r == c.r && m.color.g == c.g && m.color.b == c.b);
    } else if (m.ns == kLabelsNamespace) {
      ++labels;
      const bool isLink = m.id < numLinks;
      const ElementStatus& s = isLink ? expected.links.at(m.id) : expected.joints.at(m.id - numLinks);
      EXPECT_EQ(m.type, visualization_msgs::Marker::TEXT_VIEW_FACING);
      EXPECT_EQ(m.text, s.name);
      const auto c = toColor(s.elementClass, isLink);
      EXPECT_TRUE(m.color.r == c.r && m.color.g == c.g && m.color.b == c.b);
    }
  }
  EXPECT_EQ(links, numLinks);
  EXPECT_EQ(joints, static_cast<int>(mechanism.joints.size()));
  EXPECT_EQ(labels, numLinks + static_cast<int>(mechanism.joints.size()));
  EXPECT_EQ(red > 0, config.expectRedundant) << red << " red markers";
  EXPECT_NE(titleOf(array).find("DOF " + std::to_string(expected.dof)), std::string::npos) << titleOf(array);
}

TEST(MobilityServer, tfHasEveryLinkAtTheAssembledPose) {
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  const Mechanism mechanism = launchedMechanism();
  AnalysisOptions options;
  options.mode = valueOf(parseAnalysisMode(config.modeText));
  const LinkPoses poses = valueOf(analyzeMechanism(mechanism, options)).assembled.poses;
  const std::string& root = mechanism.links[mechanism.rootLink].name;
  for (size_t l = 0; l < mechanism.links.size(); ++l) {
    const std::string& link = mechanism.links[l].name;
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(kWait);
    while (!buffer.canTransform(root, link, ros::Time(0)) && ros::WallTime::now() < end) {
      ros::WallDuration(0.02).sleep();
    }
    ASSERT_TRUE(buffer.canTransform(root, link, ros::Time(0))) << root << " -> " << link;
    const auto t = buffer.lookupTransform(root, link, ros::Time(0));
    EXPECT_TRUE(fromTransform(t.transform).isApprox(poses[l], 1e-6)) << link;
  }
  EXPECT_TRUE(buffer.canTransform("mobility_world", root, ros::Time(0))) << "the rviz fixed frame";
}

TEST(MobilityServer, loadRobotSwapsOnlyOnSuccessAndRepublishes) {
  ros::NodeHandle nh;
  MarkerCatcher markers(nh);
  ASSERT_TRUE(markers.waitBeyond(0));
  const int before = markers.count();
  const std::string original = readTextFile(config.urdfFile);
  const MobilityReport expected = expectedReport();

  struct BadLoad {
    std::string urdf, mode, mustMention;
  };
  const std::vector<BadLoad> bad = {
      {readTextFile(std::string(MA_FIXTURE_DIR) + "/ros_bad_unknown_link.urdf"), "auto", "rockr"},
      {"this is not XML", "auto", "load_robot"},
      {original, "sideways", "sideways"},
      {"", "", "load_robot"},
  };
  for (const BadLoad& b : bad) {
    SCOPED_TRACE(b.mustMention);
    LoadRobot load;
    load.request.urdf = b.urdf;
    load.request.mode = b.mode;
    ASSERT_TRUE(call("load_robot", load));
    EXPECT_FALSE(load.response.success);
    EXPECT_NE(load.response.message.find(b.mustMention), std::string::npos) << load.response.message;
    EXPECT_EQ(load.response.robot, expected.robot) << "still serving the previous model";
  }
  const std::string unclosable = std::string(MA_FIXTURE_DIR) + "/bad_unclosable.urdf";
  if (access(unclosable.c_str(), R_OK) == 0) {
    LoadRobot load;
    load.request.urdf = readTextFile(unclosable);
    ASSERT_TRUE(call("load_robot", load));
    EXPECT_FALSE(load.response.success);
    EXPECT_NE(load.response.message.find("j4"), std::string::npos) << load.response.message;
  }
  GetDof dof;
  ASSERT_TRUE(call("get_dof", dof));
  EXPECT_TRUE(dof.response.success);
  EXPECT_EQ(dof.response.robot, expected.robot);
  EXPECT_EQ(dof.response.num_redundant, expected.numRedundant);
  ros::WallDuration(0.3).sleep();
  EXPECT_EQ(markers.count(), before) << "a failed load must not republish";

  // A good one: the fixture 4-bar analysed in the other mode, so the answer and the markers change.
  LoadRobot good;
  good.request.urdf = readTextFile(std::string(MA_FIXTURE_DIR) + "/ros_four_bar.urdf");
  good.request.mode = config.expectRedundant ? "planar" : "spatial";
  ASSERT_TRUE(call("load_robot", good));
  ASSERT_TRUE(good.response.success) << good.response.message;
  EXPECT_EQ(good.response.robot, "ros_four_bar");
  EXPECT_EQ(good.response.num_redundant, config.expectRedundant ? 0 : 3);
  ASSERT_TRUE(markers.waitBeyond(before));
  EXPECT_EQ(markers.last().markers.front().action, visualization_msgs::Marker::DELETEALL);
  EXPECT_NE(titleOf(markers.last()).find("ros_four_bar"), std::string::npos);
  {
    tf2_ros::Buffer buffer;
    tf2_ros::TransformListener listener(buffer);
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(kWait);
    while (!buffer.canTransform("ground", "coupler", ros::Time(0)) && ros::WallTime::now() < end) {
      ros::WallDuration(0.02).sleep();
    }
    EXPECT_TRUE(buffer.canTransform("ground", "coupler", ros::Time(0))) << "tf re-sent after load_robot";
  }
  GetDof now;
  ASSERT_TRUE(call("get_dof", now));
  EXPECT_EQ(now.response.robot, "ros_four_bar");

  // Restore the launched model for the other tests.
  LoadRobot restore;
  restore.request.urdf = original;
  restore.request.mode = config.modeText;
  ASSERT_TRUE(call("load_robot", restore));
  ASSERT_TRUE(restore.response.success) << restore.response.message;
  EXPECT_EQ(restore.response.num_redundant, expected.numRedundant);
}

TEST(MobilityServer, theLoadRobotToolLoadsEveryBundledModel) {
  // The README's load_robot example: nodes/load_robot sends the file as it is (apostrophes and all, which broke
  // the YAML one-liner on 5 of the bundled files) and prints what the node now serves.
  const std::string tool = std::string(MA_SOURCE_DIR) + "/nodes/load_robot";
  ASSERT_EQ(access(tool.c_str(), X_OK), 0) << tool;
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(MA_URDF_DIR)) {
    if (entry.path().extension() != ".urdf") continue;
    ++files;
    SCOPED_TRACE(entry.path().string());
    const Mechanism mechanism = valueOf(loadMechanismFromFile(entry.path().string()));
    const auto [out, status] =
        run("/usr/bin/python3 " + tool + " '" + entry.path().string() + "' --server " + config.server + " 2>&1");
    EXPECT_EQ(status, 0) << out;
    EXPECT_EQ(out.rfind(mechanism.name + ": DOF ", 0), 0u) << out;
  }
  EXPECT_GE(files, 10);
  const auto [bad, status] = run("/usr/bin/python3 " + tool + " '" + std::string(MA_FIXTURE_DIR) +
                                 "/ros_bad_unknown_link.urdf' --server " + config.server + " 2>&1");
  EXPECT_EQ(status, 2) << bad;
  EXPECT_NE(bad.find("rockr"), std::string::npos) << bad;
  // Restore the launched model for the other tests.
  LoadRobot restore;
  restore.request.urdf = readTextFile(config.urdfFile);
  restore.request.mode = config.modeText;
  ASSERT_TRUE(call("load_robot", restore));
  ASSERT_TRUE(restore.response.success) << restore.response.message;
}

TEST(MobilityServer, thousandRapidCallsKeepTheNodeAliveAndItsMemoryFlat) {
  const int pid = nodePid(config.server);
  ASSERT_GT(pid, 0) << "cannot ask " << config.server << " for its pid";
  const Mechanism mechanism = launchedMechanism();
  ros::NodeHandle nh;
  ros::ServiceClient persistent = nh.serviceClient<GetRedundancy>(config.server + "/get_redundancy", true);
  // Each failure is recorded with its case so that a flaky transport and a wrong answer can be told apart.
  std::vector<std::string> failures;
  auto burst = [&](int n) {
    failures.clear();
    for (int i = 0; i < n; ++i) {
      switch (i % 4) {
        case 0: {
          GetRedundancy srv;
          if (!persistent.call(srv)) failures.push_back("persistent get_redundancy: transport");
          else if (!srv.response.success) failures.push_back("get_redundancy: " + srv.response.message);
          break;
        }
        case 1: {
          GetDof srv;
          if (!call("get_dof", srv)) failures.push_back("get_dof: transport");
          else if (!srv.response.success) failures.push_back("get_dof: " + srv.response.message);
          break;
        }
        case 2: {  // a bad request costs nothing lasting either
          GetDof srv;
          srv.request.joint_names = {"no_such_joint"};
          srv.request.positions = {1.0};
          if (!call("get_dof", srv)) failures.push_back("bad get_dof: transport");
          else if (srv.response.success) failures.push_back("bad get_dof: succeeded");
          break;
        }
        default: {
          GetRedundancy srv;
          srv.request.joint_names = {mechanism.joints.front().name, "x"};
          if (!persistent.call(srv)) failures.push_back("persistent bad get_redundancy: transport");
          else if (srv.response.success) failures.push_back("bad get_redundancy: succeeded");
          break;
        }
      }
    }
    std::string all;
    for (const std::string& f : failures) all += f + "\n";
    return all;
  };
  ASSERT_EQ(burst(200), "");  // warm-up: connection pools, allocator arenas
  const long rssBefore = residentKb(pid);
  ASSERT_GT(rssBefore, 0);
  EXPECT_EQ(burst(1000), "");
  const long rssAfter = residentKb(pid);
  EXPECT_GT(rssAfter, 0) << "node " << pid << " is gone";
  if (transportRetries > 0) std::cout << "non-persistent calls retried after a transport failure: " << transportRetries << std::endl;
  EXPECT_LT(transportRetries, 20);
  EXPECT_LT(rssAfter - rssBefore, 4096) << "VmRSS grew from " << rssBefore << " kB to " << rssAfter << " kB";
  GetDof alive;
  EXPECT_TRUE(call("get_dof", alive) && alive.response.success);
}

TEST(MobilityServer, invalidParametersAreFatalAtStartUp) {
  {
    OwnServer server({"__name:=bad_mode_server", "_mode:=sideways"});
    ASSERT_GT(server.pid(), 0);
    const int status = server.waitForExit(kWait);
    EXPECT_NE(status, 0) << "an invalid ~mode must stop the node";
    EXPECT_NE(status, -1) << "still running";
  }
  {
    OwnServer server({"__name:=bad_tolerance_server", "_rank_tolerance:=-3.0"});
    const int status = server.waitForExit(kWait);
    EXPECT_NE(status, 0);
    EXPECT_NE(status, -1);
  }
}

TEST(MobilityServer, badDescriptionAtStartUpKeepsServingUntilLoadRobot) {
  ros::param::set("/broken_ns/robot_description", std::string("<robot name='x'><link name='a'/>"));
  OwnServer server({"__ns:=/broken_ns", "__name:=broken_server"});
  const std::string base = "/broken_ns/broken_server";
  ASSERT_TRUE(ros::service::waitForService(base + "/get_dof", ros::Duration(kWait)));
  GetDof dof;
  ASSERT_TRUE(ros::service::call(base + "/get_dof", dof));
  EXPECT_FALSE(dof.response.success);
  EXPECT_NE(dof.response.message.find("robot_description"), std::string::npos) << dof.response.message;
  LoadRobot load;
  load.request.urdf = readTextFile(config.urdfFile);
  load.request.mode = config.modeText;
  ASSERT_TRUE(ros::service::call(base + "/load_robot", load));
  EXPECT_TRUE(load.response.success) << load.response.message;
  ASSERT_TRUE(ros::service::call(base + "/get_dof", dof));
  EXPECT_TRUE(dof.response.success) << dof.response.message;
  EXPECT_EQ(dof.response.dof, expectedReport().dof);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_mobility_server");
  ros::NodeHandle privateHandle("~");
  privateHandle.getParam("urdf_file", config.urdfFile);
  privateHandle.getParam("mode", config.modeText);
  privateHandle.getParam("expect_redundant", config.expectRedundant);
  privateHandle.getParam("server", config.server);
  privateHandle.getParam("closures", config.closuresFile);
  ros::AsyncSpinner spinner(1);  // tf listeners and marker subscribers get their callbacks while tests wait
  spinner.start();
  return RUN_ALL_TESTS();
}
