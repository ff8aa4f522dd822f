#pragma once

#include <string>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis {

/**
 * @brief Reads an SDFormat model with libsdformat's own parser (Debian libsdformat-dev), so poses mean what
 *        SDFormat means (`relative_to` frames, `<frame>` elements, joint poses relative to the child link,
 * axes `expressed_in` a frame): every pose is resolved by libsdformat (`SemanticPose().Resolve()`).
 *
 * The model is the file's `<model>`, or the first `<model>` of its first `<world>` (any other model is a
 * warning). Links: `world` (when a joint names it as parent: the ground) and every `<link>`; without a joint
 * to the world the first link is the ground. SDFormat writes a closed loop as a cyclic joint graph: walking
 * from the ground through the joints from parent to child, a joint whose child is not reached yet is a tree
 * joint, and a joint whose child is already reached closes a loop (a loop joint, after every tree joint,
 * DESIGN.md §3), both in document order. Types: revolute, continuous, prismatic, ball (spherical), universal
 * (axis and axis2), fixed. Each link's frame is moved to the frame of the joint that reaches it (the joint
 * pose at the written configuration, where every joint value is 0).
 *
 * Refused with a Diagnostic: what libsdformat refuses (its first error, one line), a revolute2, screw or
 * gearbox joint (not read: its constraint would be lost), a zero axis, a link no joint reaches from the
 * ground (parent to child), non-finite or out-of-range numbers. Warnings (never silent): elements SDFormat
 * does not define (a misspelt `<jiont>`, with "did you mean"), deprecated elements, a revolute, continuous,
 * prismatic or universal joint without `<axis>` (SDFormat's default 0 0 1 is used), nested models and further
 * models.
 * @param[in] sdfText the XML text.
 * @param[in] fileName shown in diagnostics (its base name).
 * @return The mechanism, or the Diagnostic naming the element and the problem.
 */
Result<Mechanism> readSdf(const std::string& sdfText, const std::string& fileName);

}  // namespace mobility_analysis
