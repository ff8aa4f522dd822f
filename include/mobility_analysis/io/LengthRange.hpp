#pragma once

#include <optional>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis {

/**
 * @brief The model's typical length: the lower median of the nonzero lengths it is made of (the offset |xyz|
 * of every joint frame on either side, the declared length of every cable, the offset of every coupling whose
 * follower slides) [m]; lengths below tolerances::kZeroVector (CAD round-off) count as zero; 0 when there is
 * none. The median, not the characteristic length, so one far-out element does not hide its own distance from
 * the rest of the model.
 */
double typicalLength(const Mechanism& mechanism);

/**
 * @brief Checks every length of @p mechanism against the model's own size, where it enters (the readers'
 * front door, readMechanism*, and loadMechanismFrom*).
 *
 * The readers already refuse any number that is not finite or beyond |x| <= tolerances::kMaxCoordinate (1e12
 * m). This adds the relative range: every length is at most tolerances::kMaxRelativeLength (1e6) times the
 * typical length. Past about 1e9 times the rank decisions lose the small parts (a four-bar with one link
 * welded 1e9 m away reported DOF 3 instead of 1).
 * @return The Diagnostic naming the first element out of range (file, kind, name, its length, the typical
 *         length and the accepted ratio), or nothing.
 */
std::optional<Diagnostic> checkLengthRange(const Mechanism& mechanism);

}  // namespace mobility_analysis
