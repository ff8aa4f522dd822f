#include "mobility_analysis/UrdfLoader.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "mobility_analysis/Tolerances.hpp"
#include "mobility_analysis/io/LengthRange.hpp"
#include "mobility_analysis/io/UrdfReader.hpp"

namespace mobility_analysis {

namespace {

/// The URDF reader's result, with every length checked against the model's own size.
Result<Mechanism> checked(Result<Mechanism> mechanism) {
  if (isOk(mechanism)) {
    if (std::optional<Diagnostic> outOfRange = checkLengthRange(valueOf(mechanism)))
      return *outOfRange;
  }
  return mechanism;
}

}  // namespace

Result<Mechanism> loadMechanismFromString(const std::string& urdfText, const std::string& fileName) {
  return checked(readUrdf(urdfText, fileName));
}

Result<Mechanism> loadMechanismFromFile(const std::string& path) {
  return checked(readUrdfFile(path));
}

Result<JointPositions> makeJointPositions(const std::vector<std::string>& names,
                                          const std::vector<double>& values, const Mechanism& mechanism) {
  if (names.size() != values.size()) {
    return makeDiagnostic(
        mechanism.file, "positions", "",
        std::to_string(values.size()) + " values for " + std::to_string(names.size()) + " joint_names");
  }
  JointPositions positions;
  for (size_t i = 0; i < names.size(); ++i) {
    const std::optional<int> joint = mechanism.findJoint(names[i]);
    if (!joint) {
      return makeDiagnostic(mechanism.file, "positions", names[i],
                            "is not a joint of '" + mechanism.name + "'");
    }
    const Joint& j = mechanism.joints[*joint];
    if (!hasSingleValue(j)) {
      return makeDiagnostic(mechanism.file, "positions", names[i],
                            std::string("is a ") + toString(j.kind) + " of type " + toString(j.type) +
                                "; only revolute, continuous and prismatic tree joints take a position");
    }
    if (!std::isfinite(values[i])) {
      return makeDiagnostic(mechanism.file, "positions", names[i], "value is not finite");
    }
    if (std::abs(values[i]) > tolerances::kMaxCoordinate) {
      char what[96];
      std::snprintf(what, sizeof(what), "value %.6g is outside the accepted range |x| <= 1e12", values[i]);
      return makeDiagnostic(mechanism.file, "positions", names[i], what);
    }
    if (!positions.emplace(names[i], values[i]).second) {
      return makeDiagnostic(mechanism.file, "positions", names[i], "is given twice");
    }
  }
  return positions;
}

Result<JointPositions> parseJointPositions(const std::string& text, const Mechanism& mechanism) {
  std::vector<std::string> names;
  std::vector<double> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    if (item.empty()) {
      continue;
    }
    const size_t equals = item.find('=');
    if (equals == std::string::npos) {
      return makeDiagnostic(mechanism.file, "positions", item, "expected NAME=VALUE");
    }
    const std::string name = item.substr(0, equals);
    const std::string valueText = item.substr(equals + 1);
    char* end = nullptr;
    const double value = std::strtod(valueText.c_str(), &end);
    if (valueText.empty() || *end != '\0') {
      return makeDiagnostic(mechanism.file, "positions", name, "value '" + valueText + "' is not a number");
    }
    names.push_back(name);
    values.push_back(value);
  }
  return makeJointPositions(names, values, mechanism);
}

}  // namespace mobility_analysis
