#pragma once

#include <string>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis {

/**
 * @brief Reads a closed-loop URDF (DESIGN.md §2) from text.
 *
 * The URDF reader of io/UrdfReader.hpp (every loop dialect; warnings in Mechanism::warnings, not strict);
 * io/ReadMechanism.hpp is the front door for every format and for strict reading.
 * @param[in] urdfText the XML text.
 * @param[in] fileName shown in diagnostics (may be a description such as "robot_description").
 * @return The mechanism, or the Diagnostic naming the element and the problem.
 */
Result<Mechanism> loadMechanismFromString(const std::string& urdfText, const std::string& fileName);

/// Reads @p path and calls loadMechanismFromString; an unreadable file is a Diagnostic.
Result<Mechanism> loadMechanismFromFile(const std::string& path);

/**
 * @brief Parses a "j1=0.3,j2=-1" list of tree-joint positions and checks every name against @p mechanism.
 * @return The positions [rad or m], or a Diagnostic naming the joint and the problem.
 */
Result<JointPositions> parseJointPositions(const std::string& text, const Mechanism& mechanism);

/**
 * @brief Checks joint names and values (as given to the services) against @p mechanism.
 * @return The positions, or a Diagnostic: sizes differ ("3 values for 4 joint_names"), unknown joint,
 *         joint that has no single value (loop, fixed, floating), non-finite value or |value| > 1e12.
 */
Result<JointPositions> makeJointPositions(const std::vector<std::string>& names, const std::vector<double>& values,
                                          const Mechanism& mechanism);

}  // namespace mobility_analysis
