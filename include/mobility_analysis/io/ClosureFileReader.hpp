#pragma once

#include <string>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis {

/**
 * @brief Adds the loop closures of a Pinocchio / Gepetto closure file (`robot.yaml`) to a mechanism read from
 *        its URDF.
 *
 * Reads `closed_loop: [[frameA, frameB], …]` and `type: ['6d' | '3d', …]` (one per pair): 6d holds the two
 * frames together (a `fixed` loop joint), 3d holds their origins together (a `spherical` loop joint). A frame
 * is a link name, or a tree joint's name (its child link's frame, as Pinocchio's joint frames are). Optional
 * `joint_name: [...]` names the closures (default "closed_loop_<i>"); optional `joint_type: [...]` with
 * `SPHERICAL` makes that closure spherical, any other value is a warning and the `type` is used. The motor
 * lists (`name_mot`, `Lidmot`, `Lidvmot`, `rotule_name`) are known and skipped; any other key is a warning.
 * The closures are loop joints, after the mechanism's own (DESIGN.md §3).
 * @param[in] mechanism the tree (and loops) read from the URDF.
 * @param[in] path the YAML file.
 * @return The mechanism with the closures, or the Diagnostic naming the file, the entry and the problem.
 */
Result<Mechanism> addClosureFile(Mechanism mechanism, const std::string& path);

}  // namespace mobility_analysis
