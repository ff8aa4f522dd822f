#include "mobility_analysis/ros/MobilityServer.hpp"

#include <chrono>
#include <cmath>
#include <exception>

#include <visualization_msgs/MarkerArray.h>

#include "mobility_analysis/UrdfLoader.hpp"
#include "mobility_analysis/ros/RosConversions.hpp"

namespace mobility_analysis {

namespace {

/// Analyses shorter than this log nothing; longer ones log each further tenth of progress [s].
constexpr double kProgressQuietTime = 1.0;

/// Runs @p callback, turning an escaped exception into success = false (the outer edge of STYLE.md §4).
template <class Response, class Callback>
bool guarded(const char* service, Response& response, Callback&& callback) {
  try {
    callback();
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
  tfBroadcaster_ = std::make_unique<tf2_ros::StaticTransformBroadcaster>();

  std::string description;
  if (!nodeHandle_.getParam("robot_description", description)) {
    loadError_ = "parameter '" + nodeHandle_.resolveName("robot_description") +
                 "' is not set (or not a string); call ~load_robot to load a model";
    ROS_ERROR("%s", loadError_.c_str());
  } else {
    Result<ServedModel> model = analyseDescription(description, "robot_description", mode_);
    if (isOk(model)) {
      served_ = valueOf(std::move(model));
      const MobilityReport& r = served_->analysis.report;
      ROS_INFO("Serving '%s' (%s): DOF %d, Grubler %d, %d redundant equations", r.robot.c_str(),
               r.mode.c_str(), r.dof, r.grublerKutzbachDof, r.numRedundant);
      publish();
    } else {
      loadError_ = diagnosticOf(model).toString();
      ROS_ERROR("Bad robot_description, serving nothing until ~load_robot succeeds: %s", loadError_.c_str());
    }
  }

  getDofServer_ = privateNodeHandle_.advertiseService("get_dof", &MobilityServer::getDof, this);
  getRedundancyServer_ =
      privateNodeHandle_.advertiseService("get_redundancy", &MobilityServer::getRedundancy, this);
  loadRobotServer_ = privateNodeHandle_.advertiseService("load_robot", &MobilityServer::loadRobot, this);
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

  if (privateNodeHandle_.hasParam("rank_tolerance")) {
    XmlRpc::XmlRpcValue value;
    privateNodeHandle_.getParam("rank_tolerance", value);
    double tolerance = std::nan("");
    if (value.getType() == XmlRpc::XmlRpcValue::TypeDouble)
      tolerance = static_cast<double>(value);
    if (value.getType() == XmlRpc::XmlRpcValue::TypeInt)
      tolerance = static_cast<int>(value);
    if (!(tolerance > 0.0 && tolerance < 1.0)) {
      ROS_FATAL("Parameter '%s' = %s is not a number in (0, 1) (a relative rank threshold, default 1e-8)",
                privateNodeHandle_.resolveName("rank_tolerance").c_str(), value.toXml().c_str());
      return false;
    }
    rankTolerance_ = tolerance;
  }

  if (privateNodeHandle_.hasParam("fixed_frame") &&
      !privateNodeHandle_.getParam("fixed_frame", fixedFrame_)) {
    ROS_FATAL("Parameter '%s' must be a string (a tf frame id, or empty)",
              privateNodeHandle_.resolveName("fixed_frame").c_str());
    return false;
  }
  return true;
}

AnalysisOptions MobilityServer::makeOptions(AnalysisMode mode, const JointPositions& positions) const {
  AnalysisOptions options;
  options.mode = mode;
  options.positions = positions;
  options.rankTolerance = rankTolerance_;
  options.progress = [start = std::chrono::steady_clock::now(), last = -1.0](const std::string& phase,
                                                                             double fraction) mutable {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (elapsed > kProgressQuietTime && fraction - last >= 0.1) {
      ROS_INFO("analysis: %s %d%% (%.1f s)", phase.c_str(), static_cast<int>(100.0 * fraction), elapsed);
      last = fraction;
    }
  };
  return options;
}

Result<MobilityServer::ServedModel> MobilityServer::analyseDescription(const std::string& urdfText,
                                                                       const std::string& source,
                                                                       AnalysisMode mode) const {
  const auto start = std::chrono::steady_clock::now();
  Result<Mechanism> mechanism = loadMechanismFromString(urdfText, source);
  if (!isOk(mechanism))
    return diagnosticOf(mechanism);
  const double loadSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (loadSeconds > kProgressQuietTime) {
    ROS_INFO("analysis: loaded %zu links and %zu connections (%.1f s)", valueOf(mechanism).links.size(),
             valueOf(mechanism).joints.size(), loadSeconds);
  }
  Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), makeOptions(mode, {}));
  if (!isOk(analysis))
    return diagnosticOf(analysis);
  return ServedModel{valueOf(std::move(mechanism)), valueOf(std::move(analysis))};
}

template <class Request>
Result<MobilityReport> MobilityServer::reportFor(const Request& request) const {
  if (!served_)
    return makeDiagnostic("", "robot_description", "", "no model loaded: " + loadError_);
  const Result<JointPositions> positions = fromRequest(request, served_->mechanism);
  if (!isOk(positions))
    return diagnosticOf(positions);
  if (valueOf(positions).empty())
    return served_->analysis.report;
  // A pose of the caller's: analysed aside, the served model is not changed.
  Result<MobilityAnalysis> analysis =
      analyzeMechanism(served_->mechanism, makeOptions(mode_, valueOf(positions)));
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
    const Result<ServedModel> model = [&]() -> Result<ServedModel> {
      if (request.mode.empty())
        return analyseDescription(request.urdf, "load_robot", mode_);
      const Result<AnalysisMode> mode = parseAnalysisMode(request.mode);
      if (!isOk(mode)) {
        return makeDiagnostic("load_robot", "request", "mode",
                              "'" + request.mode + "' is not one of auto, planar, spatial");
      }
      return analyseDescription(request.urdf, "load_robot", valueOf(mode));
    }();
    if (isOk(model)) {
      served_ = valueOf(model);
      loadError_.clear();
      const MobilityReport& r = served_->analysis.report;
      toResponse(r, response);
      ROS_INFO("load_robot: now serving '%s' (%s): DOF %d, Grubler %d, %d redundant equations",
               r.robot.c_str(), r.mode.c_str(), r.dof, r.grublerKutzbachDof, r.numRedundant);
      publish();
      return;
    }
    if (served_)
      toResponse(served_->analysis.report, response);  // Says what is still served.
    toFailure(diagnosticOf(model), response);
    ROS_WARN("load_robot: %s (the previous model stays loaded)", diagnosticOf(model).toString().c_str());
  });
}

void MobilityServer::publish() {
  if (!served_)
    return;
  const Mechanism& mechanism = served_->mechanism;
  const LinkPoses& poses = served_->analysis.assembled.poses;
  markerPublisher_.publish(toMarkerArray(mechanism, poses, served_->analysis.report));
  // A fresh broadcaster so the latched /tf_static holds only this model's frames, not the previous model's
  // too.
  tfBroadcaster_ = std::make_unique<tf2_ros::StaticTransformBroadcaster>();
  tfBroadcaster_->sendTransform(toTransforms(mechanism, poses, fixedFrame_, ros::Time::now()));
}

}  // namespace mobility_analysis
