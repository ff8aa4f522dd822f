#include "mobility_analysis/ros/MobilityServer.hpp"

#include <chrono>
#include <cmath>
#include <exception>
#include <new>
#include <stdexcept>

#include <std_msgs/String.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "mobility_analysis/Kinematics.hpp"
#include "mobility_analysis/analysis/DriveableJoints.hpp"
#include "mobility_analysis/io/ReadMechanism.hpp"
#include "mobility_analysis/motion/Deployment.hpp"
#include "mobility_analysis/ros/RosConversions.hpp"

namespace mobility_analysis {

namespace {

/// Analyses shorter than this log nothing; longer ones log each further tenth of progress [s].
constexpr double kProgressQuietTime = 1.0;
/// A driven value counts as reached within this many rad (revolute) or characteristic lengths (prismatic).
constexpr double kReachedTolerance = 1e-6;
/// Without input for this long, ~animate moves the mechanism [s].
constexpr double kAnimateIdleTime = 2.0;
/// Animation: one step every kAnimatePeriod s, a turn in kAnimateTurnSteps steps (slides: 1 % of the length).
constexpr double kAnimatePeriod = 0.05;
constexpr int kAnimateTurnSteps = 180;

/// Thrown from the progress callback when an analysis passes ~load_timeout; caught in this file only.
struct AnalysisTimeout : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Thrown from a deployment's step callback when a new model was loaded meanwhile; caught in this file only.
struct DeploymentInterrupted : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// ~deploy: steps when the request says 0, and the most it accepts.
constexpr int kDefaultDeploySteps = 100;
constexpr int kMaxDeploySteps = 100000;

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Runs @p callback, turning an escaped exception into success = false (the outer edge of STYLE.md §4).
template <class Response, class Callback>
bool guarded(const char* service, Response& response, Callback&& callback) {
  try {
    callback();
  } catch (const std::bad_alloc&) {
    ROS_ERROR("%s: out of memory; nothing changed", service);
    toFailure(
        makeDiagnostic("", "service", service, "out of memory: the request was refused, nothing changed"),
        response);
  } catch (const std::exception& e) {
    ROS_ERROR("%s: internal error: %s", service, e.what());
    toFailure(makeDiagnostic("", "service", service, std::string("internal error: ") + e.what()), response);
  }
  return true;  // A false return would drop the message.
}

}  // namespace

MobilityServer::MobilityServer(ros::NodeHandle& nodeHandle, ros::NodeHandle& privateNodeHandle)
    : nodeHandle_(nodeHandle), privateNodeHandle_(privateNodeHandle) {
  if (!readParameters()) {
    ros::requestShutdown();
    return;
  }
  configured_ = true;
  markerPublisher_ = privateNodeHandle_.advertise<visualization_msgs::MarkerArray>("markers", 1, true);
  jointStatePublisher_ = nodeHandle_.advertise<sensor_msgs::JointState>("joint_states", 100, true);
  tfStaticPublisher_ = nodeHandle_.advertise<tf2_msgs::TFMessage>("/tf_static", 1, true);
  descriptionPublisher_ = privateNodeHandle_.advertise<std_msgs::String>("robot_description", 1, true);

  std::string description;
  if (!nodeHandle_.getParam("robot_description", description)) {
    loadError_ = "parameter '" + nodeHandle_.resolveName("robot_description") +
                 "' is not set (or not a string); call ~load_robot to load a model";
    ROS_ERROR("%s", loadError_.c_str());
  } else {
    Result<std::shared_ptr<State>> state = loadDescription(description, "robot_description", mode_);
    if (isOk(state)) {
      const MobilityReport& r = valueOf(state)->analysis.report;
      ROS_INFO("Serving '%s' (%s): DOF %d, Grubler %d, %d redundant equations", r.robot.c_str(),
               r.mode.c_str(), r.dof, r.grublerKutzbachDof, r.numRedundant);
      served_ = valueOf(state);
      publish(*served_, ros::Time::now(), true);
    } else {
      loadError_ = diagnosticOf(state).toString();
      ROS_ERROR("Bad robot_description, serving nothing until ~load_robot succeeds: %s", loadError_.c_str());
    }
  }

  getDofServer_ = privateNodeHandle_.advertiseService("get_dof", &MobilityServer::getDof, this);
  getRedundancyServer_ =
      privateNodeHandle_.advertiseService("get_redundancy", &MobilityServer::getRedundancy, this);
  loadRobotServer_ = privateNodeHandle_.advertiseService("load_robot", &MobilityServer::loadRobot, this);
  moveServer_ = privateNodeHandle_.advertiseService("move", &MobilityServer::move, this);
  deployServer_ = privateNodeHandle_.advertiseService("deploy", &MobilityServer::deploy, this);

  // The joint-state loop has a queue and a thread of its own: a long analysis there never delays a service.
  ros::SubscribeOptions options = ros::SubscribeOptions::create<sensor_msgs::JointState>(
      "input_joint_states", 1, [this](const sensor_msgs::JointStateConstPtr& m) { onJointStates(m); },
      ros::VoidPtr(), &motionQueue_);
  jointStateSubscriber_ = nodeHandle_.subscribe(options);
  if (publishRate_ > 0.0) {
    // robot_state_publisher turns each joint_states into /tf, which is not latched: repeat the state (as
    // joint_state_publisher does) so a late rviz or tf listener sees it.
    ros::NodeHandle motionHandle(nodeHandle_);
    motionHandle.setCallbackQueue(&motionQueue_);
    republishTimer_ = motionHandle.createWallTimer(
        ros::WallDuration(1.0 / publishRate_), [this](const ros::WallTimerEvent&) {
          if (const StatePtr state = current()) {
            jointStatePublisher_.publish(toJointState(state->analysis.report, ros::Time::now()));
            // ~forces_state changed: redraw (skipped while a state change holds the lock; next tick then).
            std::unique_lock<std::mutex> motion(motionMutex_, std::try_to_lock);
            if (motion.owns_lock() && forcesChoice() != publishedForces_) {
              if (const StatePtr latest = current())
                publish(*latest, ros::Time::now(), false);
            }
          }
        });
  }
  motionSpinner_ = std::make_unique<ros::AsyncSpinner>(1, &motionQueue_);
  motionSpinner_->start();
  if (animate_)
    animation_ = std::thread([this] { animate(); });
}

MobilityServer::~MobilityServer() {
  stopping_ = true;
  republishTimer_.stop();
  if (animation_.joinable())
    animation_.join();
  if (motionSpinner_)
    motionSpinner_->stop();
  jointStateSubscriber_.shutdown();
}

bool MobilityServer::readParameters() {
  std::string modeText = "auto";
  if (privateNodeHandle_.hasParam("mode") && !privateNodeHandle_.getParam("mode", modeText)) {
    ROS_FATAL("Parameter '%s' must be a string: auto, planar or spatial",
              privateNodeHandle_.resolveName("mode").c_str());
    return false;
  }
  const Result<AnalysisMode> mode = parseAnalysisMode(modeText);
  if (!isOk(mode)) {
    ROS_FATAL("Parameter '%s' = '%s' is not one of auto, planar, spatial",
              privateNodeHandle_.resolveName("mode").c_str(), modeText.c_str());
    return false;
  }
  mode_ = valueOf(mode);

  auto readNumber = [&](const char* name, double& out, double lower, double upper, const char* what) {
    if (!privateNodeHandle_.hasParam(name))
      return true;
    XmlRpc::XmlRpcValue value;
    privateNodeHandle_.getParam(name, value);
    double number = std::nan("");
    if (value.getType() == XmlRpc::XmlRpcValue::TypeDouble)
      number = static_cast<double>(value);
    if (value.getType() == XmlRpc::XmlRpcValue::TypeInt)
      number = static_cast<int>(value);
    if (!(number > lower && number < upper)) {
      ROS_FATAL("Parameter '%s' = %s is not a number in (%g, %g) (%s)",
                privateNodeHandle_.resolveName(name).c_str(), value.toXml().c_str(), lower, upper, what);
      return false;
    }
    out = number;
    return true;
  };
  if (!readNumber("rank_tolerance", rankTolerance_, 0.0, 1.0, "a relative rank threshold, default 1e-8") ||
      !readNumber("load_timeout", loadTimeout_, 0.0, 1e9, "seconds a ~load_robot may take, default 600") ||
      !readNumber("publish_rate", publishRate_, -1e-9, 1e4, "joint_states repeated per second, default 10")) {
    return false;
  }

  if (privateNodeHandle_.hasParam("closures") && !privateNodeHandle_.getParam("closures", closuresFile_)) {
    ROS_FATAL("Parameter '%s' must be a string (the path of a closure file)",
              privateNodeHandle_.resolveName("closures").c_str());
    return false;
  }
  if (privateNodeHandle_.hasParam("fixed_frame") &&
      !privateNodeHandle_.getParam("fixed_frame", fixedFrame_)) {
    ROS_FATAL("Parameter '%s' must be a string (a tf frame id, or empty)",
              privateNodeHandle_.resolveName("fixed_frame").c_str());
    return false;
  }
  for (auto [name, flag] :
       {std::pair<const char*, bool*>{"publish_link_tf", &publishLinkTf_}, {"animate", &animate_}}) {
    if (privateNodeHandle_.hasParam(name) && !privateNodeHandle_.getParam(name, *flag)) {
      ROS_FATAL("Parameter '%s' must be a boolean", privateNodeHandle_.resolveName(name).c_str());
      return false;
    }
  }
  return true;
}

MobilityServer::StatePtr MobilityServer::current() const {
  std::lock_guard<std::mutex> lock(stateMutex_);
  return served_;
}

AnalysisOptions MobilityServer::makeOptions(AnalysisMode mode, const JointPositions& positions,
                                            double timeout) const {
  AnalysisOptions options;
  options.mode = mode;
  options.positions = positions;
  options.rankTolerance = rankTolerance_;
  options.progress = [start = std::chrono::steady_clock::now(), last = -1.0, timeout](
                         const std::string& phase, double fraction) mutable {
    const double elapsed = secondsSince(start);
    if (elapsed > timeout) {
      throw AnalysisTimeout("the analysis took longer than ~load_timeout = " + std::to_string(timeout) +
                            " s (in phase " + phase + "); refused, nothing changed");
    }
    if (elapsed > kProgressQuietTime && fraction - last >= 0.1) {
      ROS_INFO("analysis: %s %d%% (%.1f s)", phase.c_str(), static_cast<int>(100.0 * fraction), elapsed);
      last = fraction;
    }
  };
  return options;
}

Result<std::shared_ptr<MobilityServer::State>> MobilityServer::loadDescription(const std::string& urdfText,
                                                                               const std::string& source,
                                                                               AnalysisMode mode) const {
  const auto start = std::chrono::steady_clock::now();
  try {
    // Any URDF dialect or MJCF text, with the ~closures file if one is given (README, "Formats").
    ReadOptions readOptions;
    readOptions.closuresFile = closuresFile_;
    Result<Mechanism> mechanism = readMechanismFromString(urdfText, source, readOptions);
    if (!isOk(mechanism))
      return diagnosticOf(mechanism);
    for (const Diagnostic& warning : valueOf(mechanism).warnings)
      ROS_WARN("%s", warning.toString().c_str());
    const double loadSeconds = secondsSince(start);
    if (loadSeconds > kProgressQuietTime) {
      ROS_INFO("analysis: loaded %zu links and %zu connections (%.1f s)", valueOf(mechanism).links.size(),
               valueOf(mechanism).joints.size(), loadSeconds);
    }
    if (loadSeconds > loadTimeout_) {
      return makeDiagnostic(source, "load_robot", "",
                            "reading the URDF took longer than ~load_timeout = " +
                                std::to_string(loadTimeout_) + " s; refused");
    }
    auto state = std::make_shared<State>();
    state->mechanism = std::make_shared<const Mechanism>(valueOf(std::move(mechanism)));
    state->description = urdfText;
    state->mode = mode;
    Result<MobilityAnalysis> analysis =
        analyzeMechanism(*state->mechanism, makeOptions(mode, {}, loadTimeout_ - loadSeconds));
    if (!isOk(analysis))
      return diagnosticOf(analysis);
    state->analysis = valueOf(std::move(analysis));
    return state;
  } catch (const AnalysisTimeout& e) {
    return makeDiagnostic(source, "load_robot", "", e.what());
  } catch (const std::bad_alloc&) {
    return makeDiagnostic(source, "load_robot", "",
                          "out of memory while reading or analysing the model; refused, nothing changed");
  }
}

Result<MobilityServer::StatePtr> MobilityServer::solve(const StatePtr& from,
                                                       const JointPositions& driven) const {
  AnalysisOptions options = makeOptions(from->mode, driven, loadTimeout_);
  options.startPoses =
      from->analysis.assembled.poses;  // Continuation from the previous state, on its branch.
  Result<MobilityAnalysis> analysis = [&]() -> Result<MobilityAnalysis> {
    try {
      return analyzeMechanism(*from->mechanism, options);
    } catch (const AnalysisTimeout& e) {
      return makeDiagnostic("", "input_joint_states", "", e.what());
    }
  }();
  if (!isOk(analysis))
    return diagnosticOf(analysis);
  const MobilityReport& report = valueOf(analysis).report;
  for (const auto& [name, value] : driven) {
    const Joint& joint = from->mechanism->joints[*from->mechanism->findJoint(name)];
    const double tolerance =
        kReachedTolerance * (joint.type == JointType::Prismatic ? report.characteristicLength : 1.0);
    double reached = std::nan("");
    for (const JointValue& v : report.positions) {
      if (v.name == name)
        reached = v.value;
    }
    if (!(std::abs(reached - value) <= tolerance)) {
      char text[200];
      std::snprintf(text, sizeof(text), "%.9g cannot be reached from the current state (the loop gives %.9g)",
                    value, reached);
      return makeDiagnostic("", "joint", name, text);
    }
  }
  auto state = std::make_shared<State>(
      State{from->mechanism, from->description, from->mode, valueOf(std::move(analysis)), from->generation});
  return StatePtr(std::move(state));
}

bool MobilityServer::commit(const StatePtr& state, const ros::Time& stamp) {
  {
    std::lock_guard<std::mutex> lock(stateMutex_);
    if (!served_ || served_->generation != state->generation)
      return false;  // A newer model came in meanwhile.
    served_ = state;
  }
  publish(*state, stamp, false);
  return true;
}

template <class Request>
Result<MobilityReport> MobilityServer::reportFor(const Request& request) const {
  const StatePtr state = current();
  if (!state) {
    std::lock_guard<std::mutex> lock(stateMutex_);
    return makeDiagnostic("", "robot_description", "", "no model loaded: " + loadError_);
  }
  const Result<JointPositions> positions = fromRequest(request, *state->mechanism);
  if (!isOk(positions))
    return diagnosticOf(positions);
  if (valueOf(positions).empty())
    return state->analysis.report;
  // A pose of the caller's: analysed aside (as the CLI's --positions), the served state is not changed.
  Result<MobilityAnalysis> analysis =
      analyzeMechanism(*state->mechanism, makeOptions(state->mode, valueOf(positions), loadTimeout_));
  if (!isOk(analysis))
    return diagnosticOf(analysis);
  return valueOf(std::move(analysis)).report;
}

bool MobilityServer::getDof(GetDof::Request& request, GetDof::Response& response) {
  return guarded("get_dof", response, [&] {
    const Result<MobilityReport> report = reportFor(request);
    if (isOk(report)) {
      toResponse(valueOf(report), response);
    } else {
      toFailure(diagnosticOf(report), response);
      ROS_WARN_THROTTLE(1.0, "get_dof: %s", response.message.c_str());
    }
  });
}

bool MobilityServer::getRedundancy(GetRedundancy::Request& request, GetRedundancy::Response& response) {
  return guarded("get_redundancy", response, [&] {
    const Result<MobilityReport> report = reportFor(request);
    if (isOk(report)) {
      toResponse(valueOf(report), response);
    } else {
      toFailure(diagnosticOf(report), response);
      ROS_WARN_THROTTLE(1.0, "get_redundancy: %s", response.message.c_str());
    }
  });
}

bool MobilityServer::loadRobot(LoadRobot::Request& request, LoadRobot::Response& response) {
  return guarded("load_robot", response, [&] {
    std::lock_guard<std::mutex> loading(loadMutex_);
    const auto start = std::chrono::steady_clock::now();
    Result<std::shared_ptr<State>> loaded = [&]() -> Result<std::shared_ptr<State>> {
      if (request.mode.empty())
        return loadDescription(request.urdf, "load_robot", mode_);
      const Result<AnalysisMode> mode = parseAnalysisMode(request.mode);
      if (!isOk(mode)) {
        return makeDiagnostic("load_robot", "request", "mode",
                              "'" + request.mode + "' is not one of auto, planar, spatial");
      }
      return loadDescription(request.urdf, "load_robot", valueOf(mode));
    }();
    if (!isOk(loaded)) {
      if (const StatePtr still = current())
        toResponse(still->analysis.report, response);  // What is still served.
      toFailure(diagnosticOf(loaded), response);
      ROS_WARN("load_robot: %s (the previous model stays loaded)", response.message.c_str());
      return;
    }
    const double analysed = secondsSince(start);
    std::shared_ptr<State> state = valueOf(std::move(loaded));
    double described = 0.0;
    {
      // Swap in: the state loop finishes the step it is in (its result, of the old model, is then dropped).
      std::lock_guard<std::mutex> motion(motionMutex_);
      state->generation = ++generation_;
      {
        std::lock_guard<std::mutex> lock(stateMutex_);
        served_ = state;
        loadError_.clear();
      }
      unreachableLogged_ = false;
      const auto setting = std::chrono::steady_clock::now();
      nodeHandle_.setParam("robot_description", state->description);
      described = secondsSince(setting);
      publish(*state, ros::Time::now(), true);
    }
    toResponse(state->analysis.report, response);
    const MobilityReport& r = state->analysis.report;
    ROS_INFO(
        "load_robot: now serving '%s' (%s): DOF %d, Grubler %d, %d redundant equations (read and analysed in "
        "%.3f s, served in %.3f s of which robot_description %.3f s)",
        r.robot.c_str(), r.mode.c_str(), r.dof, r.grublerKutzbachDof, r.numRedundant, analysed,
        secondsSince(start), described);
  });
}

bool MobilityServer::move(Move::Request& request, Move::Response& response) {
  return guarded("move", response, [&] {
    response.success = false;
    const StatePtr start = current();
    if (!start) {
      response.message = "move: no model loaded";
      return;
    }
    const Mechanism& mechanism = *start->mechanism;
    response.characteristic_length = start->analysis.report.characteristicLength;
    response.driveable_joints = findDriveableJoints(mechanism, start->analysis);
    std::string name = request.joint;
    if (name.empty()) {
      if (request.free_direction < 0 ||
          request.free_direction >= static_cast<int>(response.driveable_joints.size())) {
        response.message = "move: free_direction " + std::to_string(request.free_direction) +
                           " is not in [0, " + std::to_string(response.driveable_joints.size()) +
                           ") (see driveable_joints)";
        return;
      }
      name = response.driveable_joints[request.free_direction];
    }
    const std::optional<int> index = mechanism.findJoint(name);
    if (!index || !hasSingleValue(mechanism.joints[*index])) {
      response.message = "move: joint '" + name + "' is not a revolute, continuous or prismatic tree joint";
      return;
    }
    if (!std::isfinite(request.start) || !std::isfinite(request.end) || request.steps < 2 ||
        request.steps > 100000 || !(request.duration >= 0.0 && request.duration <= 3600.0)) {
      response.message = "move: start and end must be finite, steps in [2, 100000], duration in [0, 3600] s";
      return;
    }
    response.joint = name;
    double origin = 0.0;
    for (const JointValue& v : start->analysis.report.positions) {
      if (v.name == name)
        origin = v.value;
    }
    const ros::WallDuration pause(request.duration / (request.steps - 1));
    for (int k = 0; k < request.steps && ros::ok(); ++k) {
      if (k > 0 && request.duration > 0.0)
        pause.sleep();
      lastInputTime_ = ros::WallTime::now().toSec();  // A sweep is input: ~animate waits for it.
      const double value = origin + request.start + (request.end - request.start) * k / (request.steps - 1);
      std::lock_guard<std::mutex> motion(motionMutex_);
      const StatePtr from = current();
      if (!from || from->generation != start->generation) {
        response.message = "move: a new model was loaded during the sweep; stopped";
        return;
      }
      const Result<StatePtr> next = solve(from, {{name, value}});
      if (!isOk(next)) {
        response.message = "move: stopped after " + std::to_string(response.states) +
                           " states: " + diagnosticOf(next).toString();
        return;
      }
      commit(valueOf(next), ros::Time::now());
      ++response.states;
      response.max_residual =
          std::max(response.max_residual, valueOf(next)->analysis.report.assembly.residual);
    }
    response.success = true;
  });
}

bool MobilityServer::deploy(Deploy::Request& request, Deploy::Response& response) {
  return guarded("deploy", response, [&] {
    response.success = false;
    std::unique_lock<std::mutex> deploying(deployMutex_, std::try_to_lock);
    if (!deploying.owns_lock()) {
      response.message = "deploy: another deployment is running; refused";
      return;
    }
    const StatePtr start = current();
    if (!start) {
      response.message = "deploy: no model loaded";
      return;
    }
    const int steps = request.steps == 0 ? kDefaultDeploySteps : request.steps;
    if (steps < 1 || steps > kMaxDeploySteps || !std::isfinite(request.target_length) ||
        request.target_length < 0.0 || !(request.duration >= 0.0 && request.duration <= 3600.0)) {
      response.message = "deploy: steps must be in [1, " + std::to_string(kMaxDeploySteps) +
                         "] (0: " + std::to_string(kDefaultDeploySteps) +
                         "), target_length finite and >= 0, duration in [0, 3600] s";
      return;
    }
    const Mechanism& mechanism = *start->mechanism;
    DeploymentOptions options;
    options.cable = request.cable;
    options.steps = steps;
    options.targetLength = request.target_length;
    // The final analysis may take ~load_timeout beyond the paced steps.
    options.analysis = makeOptions(start->mode, {}, loadTimeout_ + request.duration);
    options.analysis.startPoses = start->analysis.assembled.poses;  // From the state in force.
    options.analysis.lockActiveCables = request.lock_active_cables;
    // Each step is shown through the one publishing path (commit): a display state that carries the start's
    // analysis with this step's poses, positions and cables; the final state replaces it with a full
    // analysis.
    const ros::WallDuration pause(request.duration / steps);
    int published = 0;
    JointPositions previous = start->analysis.assembled.positions;
    options.onStep = [&](const DeploymentStep& step, const LinkPoses& poses) {
      if (published > 0 && request.duration > 0.0)
        pause.sleep();
      lastInputTime_ = ros::WallTime::now().toSec();  // A deployment is input: ~animate waits for it.
      std::lock_guard<std::mutex> motion(motionMutex_);
      const StatePtr from = current();
      if (!from || from->generation != start->generation)
        throw DeploymentInterrupted("a new model was loaded during the deployment; stopped");
      auto state = std::make_shared<State>(*start);
      MobilityAnalysis& analysis = state->analysis;
      analysis.assembled.poses = poses;
      analysis.assembled.q = computeCoordinates(analysis.assembled.model, poses);
      previous = computeJointPositions(mechanism, poses, previous);
      analysis.assembled.positions = previous;
      MobilityReport& report = analysis.report;
      report.positions.clear();
      for (const Joint& joint : mechanism.joints) {
        const auto value = previous.find(joint.name);
        if (joint.kind == ConnectionKind::TreeJoint && value != previous.end())
          report.positions.push_back(JointValue{joint.name, value->second});
      }
      report.cables = step.cables;
      char line[200];
      std::snprintf(line, sizeof(line),
                    "deploying: %s at %.9g m (step %d); the rest of this report is the start's until the "
                    "deployment ends",
                    request.cable.c_str(), step.activeLength, published);
      report.warnings.push_back(line);
      commit(state, ros::Time::now());
      ++published;
    };
    Result<MobilityAnalysis> result = [&]() -> Result<MobilityAnalysis> {
      try {
        return deployMechanism(mechanism, options);
      } catch (const AnalysisTimeout& e) {
        return makeDiagnostic("", "deploy", request.cable, e.what());
      } catch (const DeploymentInterrupted& e) {
        return makeDiagnostic("", "deploy", request.cable, e.what());
      }
    }();
    if (!isOk(result)) {
      toFailure(diagnosticOf(result), response);
      response.steps = published;
      if (published > 0) {
        // The steps shown carried the start's report: the start, fully analysed, is served again.
        std::lock_guard<std::mutex> motion(motionMutex_);
        if (commit(start, ros::Time::now()))
          response.message += " (the start state is served again)";
      }
      ROS_WARN("deploy: %s (%d states were shown)", response.message.c_str(), published);
      return;
    }
    MobilityAnalysis analysis = valueOf(std::move(result));
    const DeploymentInfo& info = *analysis.report.deployment;
    // Served from now on: the mechanism with the active cable at the length it was shortened to (as the
    // core's final report has it), its full analysis at the deployed pose.
    auto deployed = std::make_shared<Mechanism>(mechanism);
    if (const std::optional<int> cable = deployed->findJoint(info.cable))
      deployed->joints[*cable].length = info.finalLength;
    auto state = std::make_shared<State>(
        State{deployed, start->description, start->mode, std::move(analysis), start->generation});
    {
      std::lock_guard<std::mutex> motion(motionMutex_);
      if (!commit(state, ros::Time::now())) {
        response.message = "deploy: a new model was loaded during the deployment; its result was dropped";
        return;
      }
    }
    toResponse(state->analysis.report, response);
    const DeploymentInfo& d = *state->analysis.report.deployment;
    ROS_INFO("deploy: %s from %.6g m to %.6g m in %zu states, %s; DOF %d, %d states of self-stress%s",
             d.cable.c_str(), d.initialLength, d.finalLength, d.steps.size(), d.reason.c_str(), d.finalDof,
             state->analysis.report.selfStress.count,
             state->analysis.report.selfStress.prestressable ? ", prestressable" : "");
  });
}

int MobilityServer::forcesChoice() const {
  int choice = kForcesAuto;
  if (!privateNodeHandle_.getParamCached("forces_state", choice) || choice < kForcesAuto)
    return kForcesAuto;
  return choice;
}

void MobilityServer::onJointStates(const sensor_msgs::JointStateConstPtr& message) {
  try {
    lastInputTime_ = ros::WallTime::now().toSec();
    std::lock_guard<std::mutex> motion(motionMutex_);
    const StatePtr from = current();
    if (!from)
      return;
    const Mechanism& mechanism = *from->mechanism;
    JointPositions driven;
    for (size_t i = 0; i < message->name.size() && i < message->position.size(); ++i) {
      const std::optional<int> index = mechanism.findJoint(message->name[i]);
      if (!index || !hasSingleValue(mechanism.joints[*index]) || !std::isfinite(message->position[i])) {
        ROS_WARN_THROTTLE(5.0,
                          "input_joint_states: '%s' is not a revolute, continuous or prismatic tree joint of "
                          "'%s' with a finite value; ignored",
                          message->name[i].c_str(), mechanism.name.c_str());
        continue;
      }
      driven[message->name[i]] = message->position[i];
    }
    const ros::Time stamp = message->header.stamp.isZero() ? ros::Time::now() : message->header.stamp;
    bool unchanged = true;
    for (const JointValue& v : from->analysis.report.positions) {
      const auto d = driven.find(v.name);
      if (d != driven.end() && d->second != v.value)
        unchanged = false;
    }
    if (unchanged) {  // Nothing moves: the same state, stamped as the input.
      jointStatePublisher_.publish(toJointState(from->analysis.report, stamp));
      return;
    }
    const Result<StatePtr> next = solve(from, driven);
    if (!isOk(next)) {
      if (!unreachableLogged_) {
        ROS_WARN("input_joint_states: %s; keeping the last good state (logged once until a state is reached)",
                 diagnosticOf(next).toString().c_str());
        unreachableLogged_ = true;
      }
      jointStatePublisher_.publish(toJointState(from->analysis.report, stamp));
      return;
    }
    unreachableLogged_ = false;
    commit(valueOf(next), stamp);
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(5.0, "input_joint_states: %s; keeping the last good state", e.what());
  }
}

void MobilityServer::animate() {
  double direction = 1.0;
  uint64_t generation = 0;
  std::string joint;
  double step = 0.0;
  while (!stopping_ && ros::ok()) {
    std::this_thread::sleep_for(std::chrono::duration<double>(kAnimatePeriod));
    if (ros::WallTime::now().toSec() - lastInputTime_ < kAnimateIdleTime)
      continue;
    try {
      std::lock_guard<std::mutex> motion(motionMutex_);
      const StatePtr from = current();
      if (!from)
        continue;
      if (from->generation != generation || joint.empty()) {
        generation = from->generation;
        const std::vector<std::string> driveable = findDriveableJoints(*from->mechanism, from->analysis);
        joint = driveable.empty() ? std::string() : driveable.front();
        if (joint.empty())
          continue;
        const Joint& j = from->mechanism->joints[*from->mechanism->findJoint(joint)];
        step = j.type == JointType::Prismatic ? 0.01 * from->analysis.report.characteristicLength
                                              : 2.0 * M_PI / kAnimateTurnSteps;
      }
      double value = 0.0;
      for (const JointValue& v : from->analysis.report.positions) {
        if (v.name == joint)
          value = v.value;
      }
      Result<StatePtr> next = solve(from, {{joint, value + direction * step}});
      if (!isOk(next)) {  // A dead point or a limit of the branch: go back the other way.
        direction = -direction;
        next = solve(from, {{joint, value + direction * step}});
      }
      if (isOk(next))
        commit(valueOf(next), ros::Time::now());
    } catch (const std::exception& e) {
      ROS_ERROR_THROTTLE(5.0, "animate: %s", e.what());
    }
  }
}

void MobilityServer::publish(const State& state, const ros::Time& stamp, bool newModel) {
  const Mechanism& mechanism = *state.mechanism;
  const LinkPoses& poses = state.analysis.assembled.poses;
  if (newModel) {
    std_msgs::String description;
    description.data = state.description;
    descriptionPublisher_.publish(description);
  }
  jointStatePublisher_.publish(toJointState(state.analysis.report, stamp));
  const int forces = forcesChoice();
  markerPublisher_.publish(toMarkerArray(mechanism, poses, state.analysis.report, ros::Time(0), forces));
  publishedForces_ = forces;
  // One latched message with every frame of this state (tf2 listeners keep the latest per child frame).
  tf2_msgs::TFMessage tf;
  tf.transforms = toTransforms(mechanism, poses, fixedFrame_, stamp,
                               publishLinkTf_ ? LinkFrames::All : LinkFrames::FloatingHung);
  tfStaticPublisher_.publish(tf);
}

}  // namespace mobility_analysis
