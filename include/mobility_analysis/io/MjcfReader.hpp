#pragma once

#include <string>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis {

/**
 * @brief Reads a MuJoCo MJCF model with MuJoCo's own parser (libmujoco), so every element means what MuJoCo
 *        means (defaults, includes, childclass, frames).
 *
 * Links: the world and every body, at the model's reference configuration (qpos0). Tree joints: a body's
 * hinge (revolute), slide (prismatic), ball (spherical) or free (floating) joint; a body without joints is
 * welded (fixed) to its parent; a body with several joints gets one intermediate link per extra joint
 * ("<body>/<joint>"). Equality constraints: `connect` is a spherical loop joint at its anchor, `weld` a fixed
 * loop joint, `joint` (joint1 = poly(joint2)) a coupling with the linear term as multiplier and the constant
 * as offset; all are taken as satisfied at the reference configuration, as MuJoCo takes them. An inactive
 * equality, a `tendon` or `distance` equality, a joint equality without joint2 or with higher polynomial
 * terms: a warning.
 * @param[in] path the .xml file (MuJoCo resolves includes and meshes relative to it).
 * @return The mechanism, or the Diagnostic with MuJoCo's message.
 */
Result<Mechanism> readMjcf(const std::string& path);

}  // namespace mobility_analysis
