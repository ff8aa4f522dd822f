#pragma once

#include <string>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis {

/**
 * @brief Reads a URDF with loops in any of the dialects we know, in one pass over the XML, without recursion.
 *
 * - the `<link>`/`<joint>` tree (every joint type of URDF; `<limit>` is not needed, so Drake's
 *   `<limit effort="100"/>` without velocity is accepted), checked for two parents, cycles, links not
 *   connected to the root, unknown links, duplicate names and non-finite or out-of-range numbers
 *   (|x| <= tolerances::kMaxCoordinate);
 * - our `<loop_joint>` (also Isaac Sim's and Drake's), `<distance_constraint>` and `<cable>` (DESIGN.md §2);
 * - URDF+ `<loop name type><predecessor link><origin/></predecessor><successor link><origin/></successor>
 *   <axis/></loop>`, read as a loop joint with link1 = predecessor, link2 = successor;
 * - URDF+ `<coupling name><predecessor joint/><successor joint/><ratio value/></coupling>` (also
 *   `<leader joint>`/`<follower joint>`, optional `<offset value>`): successor = ratio * predecessor +
 * offset;
 * - `<mimic joint multiplier offset/>` inside a tree joint: this joint = multiplier * that joint + offset, a
 *   coupling named "mimic_<this joint>".
 *
 * Never silent: an unknown top-level element (except the well-known gazebo, transmission, ros2_control,
 * material, sensor), an unknown child of a loop element, a repeated `<link1>`/`<predecessor>`, a loop
 * element without the axis its type needs (the axis is then 1 0 0, as in URDF) is a warning in
 * Mechanism::warnings naming the element.
 * @param[in] urdfText the XML text.
 * @param[in] fileName shown in diagnostics (its base name; may be a description such as "robot_description").
 * @return The mechanism, or the Diagnostic naming the element and the problem.
 */
Result<Mechanism> readUrdf(const std::string& urdfText, const std::string& fileName, bool sideThread = false);

/**
 * @brief readUrdf of the file at @p path, read by the XML parser into its own buffer: one copy of the text in
 *        memory instead of two (a 10^6-link chain is 0.3 GB of text).
 * @return The mechanism, or the Diagnostic ("cannot open the file" when it cannot be read).
 */
Result<Mechanism> readUrdfFile(const std::string& path, bool sideThread = false);

}  // namespace mobility_analysis
