#pragma once

// Private to src/core: numbers compared or handed on only to the digits that mean something, so that a
// model's rounding (the same model in millimetres instead of metres) cannot change what the report shows.
// Used by the self-stress report (analysis/SelfStressReport.cpp: the order of a state's elements, the sign of
// a state) and the prestress program (analysis/Prestress.cpp: its coefficients).

#include <cmath>
#include <cstdint>
#include <cstring>

namespace mobility_analysis {
namespace core_detail {

/// The bit pattern of |@p value| (finite) rounded to the nearest multiple of 2^@p droppedBits: an integer
/// that orders as the magnitude. A positive double's bit pattern orders as the number does, across powers of
/// two too (1 and 1 - 2^-53 are neighbours there and round together; a rounded mantissa alone would put them
/// a binade apart). @p droppedBits in [1, 52].
inline uint64_t roundedMagnitudeBits(double value, int droppedBits) {
  const double magnitude = std::abs(value);
  uint64_t bits = 0;
  std::memcpy(&bits, &magnitude, sizeof(bits));
  const uint64_t half = uint64_t{1} << (droppedBits - 1);
  return (bits + half) & ~((half << 1) - 1);
}

/// @p value (finite, of magnitude well below 2^(52 - @p fractionBits)) rounded to the nearest multiple of
/// 2^-@p fractionBits: an absolute grid, for numbers of a known scale (a state's coefficients, at most 1),
/// where a relative one would leave the small ones with their rounding.
inline double roundToGrid(double value, int fractionBits) {
  return std::ldexp(std::nearbyint(std::ldexp(value, fractionBits)), -fractionBits);
}

}  // namespace core_detail
}  // namespace mobility_analysis
