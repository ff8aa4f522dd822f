#pragma once

#include <string>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis {

/// How a model is read.
struct ReadOptions {
  std::string closuresFile;  ///< A Pinocchio/Gepetto closure file (robot.yaml) for a URDF; empty: none.
  bool strict = false;       ///< Every warning is an error (the first one is returned).
  /// A large URDF (from 1 MB) checks its well-formedness on a second thread while it is read; false: one
  /// thread. The answer is the same.
  bool sideThread = true;
};

/**
 * @brief The one front door of the readers: a URDF in any of our dialects (io/UrdfReader.hpp), plus a closure
 *        file if given (io/ClosureFileReader.hpp), an MJCF model (io/MjcfReader.hpp) or an SDFormat model
 *        (io/SdfReader.hpp).
 *
 * The format is told by the root element (`<robot>`: URDF, `<mujoco>`: MJCF, `<sdf>`: SDFormat); a `.sdf`
 * file whose root is not `<robot>` goes to the SDFormat reader, whose parser names what is wrong.
 * @param[in] path the model file.
 * @param[in] options closure file and strictness.
 * @return The mechanism with its warnings, or a Diagnostic (in strict mode: the first warning).
 */
Result<Mechanism> readMechanism(const std::string& path, const ReadOptions& options = {});

/**
 * @brief The same from text (the node's `robot_description` and `~load_robot`): URDF, MJCF or SDFormat.
 * @param[in] text the XML.
 * @param[in] sourceName shown in diagnostics ("robot_description").
 */
Result<Mechanism> readMechanismFromString(const std::string& text, const std::string& sourceName,
                                          const ReadOptions& options = {});

}  // namespace mobility_analysis
