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
 * is a link name, or a tree joint's name (its child link's frame, as Pinocchio's joint frames are). The
 * closures are named "closed_loop_<i>". Optional `joint_name: [...]` with `joint_type: [...]` (one each)
 * build tree joints of the URDF as Gepetto's loader does: `SPHERICAL` a ball at the joint's origin,
 * `UJOINT_XY` (any two of X, Y, Z) a universal joint about the joint frame's first axis on the parent and its
 * second on the child, `FIXED` the joint frozen at its zero; an older file's `rotule_name: text` makes every
 * tree joint whose name contains the text a ball. A name that is no tree joint, or another type, is a warning
 * and not read; a joint that a
 * `<mimic>` couples cannot be rebuilt (an error). The motor lists (`name_mot`, `Lidmot`, `Lidvmot`) are known
 * and skipped; any other key is a warning. The closures are loop joints, after the mechanism's own (DESIGN.md
 * §3).
 * @param[in] mechanism the tree (and loops) read from the URDF.
 * @param[in] path the YAML file.
 * @return The mechanism with the closures, or the Diagnostic naming the file, the entry and the problem.
 */
Result<Mechanism> addClosureFile(Mechanism mechanism, const std::string& path);

}  // namespace mobility_analysis
