#pragma once

// Private to the readers in src/core/io: strict number parsing shared by the XML readers.

#include <sys/stat.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {
namespace io_detail {

/// Blanks as std::strtod skips them before a number (the "C" locale's isspace).
inline bool isSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r';
}

/**
 * @brief The number that is exactly the characters [@p begin, @p end) as std::strtod reads them, or nothing
 *        when strtod would stop before @p end.
 *
 * std::from_chars first (no locale, no errno; about 4x faster than strtod): wherever it reads the whole
 * range, strtod reads the same range to the same double (both round correctly). Everything else — a leading
 * '+' or blank, hexadecimal, out of range, not a number — goes to strtod itself, so the values and the
 * refusals are strtod's, as before.
 * @note *end must be a character strtod stops at (a blank or '\0'): strtod reads on to it.
 */
inline std::optional<double> parseNumber(const char* begin, const char* end) {
  if (end - begin == 1 && *begin >= '0' && *begin <= '9')  // "0", "1": most of a URDF's numbers
    return static_cast<double>(*begin - '0');
  double value = 0.0;
  const std::from_chars_result fast = std::from_chars(begin, end, value);
  if (fast.ec == std::errc() && fast.ptr == end)
    return value;
  char* stop = nullptr;
  value = std::strtod(begin, &stop);
  if (stop == begin || stop != end)
    return std::nullopt;
  return value;
}

/// @return The number in @p text (surrounding blanks allowed), or nothing when it is not one.
inline std::optional<double> parseDouble(const char* text) {
  const char* begin = text;
  while (isSpace(*begin))
    ++begin;
  const char* end = begin + std::strlen(begin);
  while (end > begin && (end[-1] == ' ' || end[-1] == '\t' || end[-1] == '\n' || end[-1] == '\r'))
    --end;
  if (end == begin)
    return std::nullopt;
  // strtod stops at a blank, so the number is [begin, end) or the text is not one.
  return parseNumber(begin, end);
}

/// Why a number was refused, or nothing when it is usable: finite and |x| <= tolerances::kMaxCoordinate.
inline std::optional<std::string> checkRange(double value) {
  if (!std::isfinite(value)) {
    return std::string("is not finite");
  }
  if (std::abs(value) > tolerances::kMaxCoordinate) {
    return std::string("is outside the accepted range |x| <= 1e12");
  }
  return std::nullopt;
}

/// True when @p rpy is +0 +0 +0 (not -0): the angles whose rotation is the identity bit for bit.
inline bool isPositiveZero(const Eigen::Vector3d& rpy) {
  return rpy.x() == 0.0 && rpy.y() == 0.0 && rpy.z() == 0.0 && !std::signbit(rpy.x()) &&
         !std::signbit(rpy.y()) && !std::signbit(rpy.z());
}

/// URDF fixed-axis roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll).
inline Eigen::Matrix3d rollPitchYaw(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

/// The frame at @p xyz turned by roll-pitch-yaw @p rpy; +0 +0 +0 (most frames) skips the product of the
/// three angle-axis quaternions, each (1, +0, +0, +0), whose matrix is the identity bit for bit
/// (UrdfLoaderTest checks it).
inline Eigen::Isometry3d makeFrame(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy) {
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  if (!isPositiveZero(rpy))
    frame.linear() = rollPitchYaw(rpy);
  frame.translation() = xyz;
  return frame;
}

/// The rotation of URDF roll-pitch-yaw @p rpy through its quaternion, as urdfdom computes it (then
/// normalised).
inline Eigen::Matrix3d originRotation(const Eigen::Vector3d& rpy) {
  const double phi = rpy.x() / 2.0, the = rpy.y() / 2.0, psi = rpy.z() / 2.0;
  double x = std::sin(phi) * std::cos(the) * std::cos(psi) - std::cos(phi) * std::sin(the) * std::sin(psi);
  double y = std::cos(phi) * std::sin(the) * std::cos(psi) + std::sin(phi) * std::cos(the) * std::sin(psi);
  double z = std::cos(phi) * std::cos(the) * std::sin(psi) - std::sin(phi) * std::sin(the) * std::cos(psi);
  double w = std::cos(phi) * std::cos(the) * std::cos(psi) + std::sin(phi) * std::sin(the) * std::sin(psi);
  const double norm = std::sqrt(x * x + y * y + z * z + w * w);
  x /= norm;
  y /= norm;
  z /= norm;
  w /= norm;
  return Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
}

/**
 * @brief A URDF `<joint><origin>` frame, its rotation through the quaternion of roll-pitch-yaw as urdfdom
 *        computes it (then normalised), so tree-joint frames are bit for bit those urdfdom gave.
 */
inline Eigen::Isometry3d makeOriginFrame(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy) {
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.translation() = xyz;
  if (!isPositiveZero(rpy))
    frame.linear() = originRotation(rpy);
  // else rpy is +0 +0 +0 (most tree joints): sin +0 = +0 and cos +0 = 1 exactly, so the quaternion is
  // (1, +0, +0, +0) and its matrix the identity, bit for bit (UrdfLoaderTest checks it).
  return frame;
}

/**
 * @brief Reads the whole file at @p path into @p text; false when it cannot be read (also a directory).
 *
 * A regular file is read in one fread straight into the string, sized from fstat (one allocation, no block
 * copies: a 10^6-link chain is 0.3 GB); anything else (a pipe) in 64 KiB blocks.
 */
inline bool readWholeFile(const std::string& path, std::string& text) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr)
    return false;
  struct stat status {};
  size_t size = 0;  // expected; one more byte is asked for so that the first read meets the end
  if (::fstat(::fileno(file), &status) == 0 && S_ISREG(status.st_mode) && status.st_size > 0)
    size = static_cast<size_t>(status.st_size);
  text.clear();
  text.reserve(size + 1);
  size_t used = 0;
  bool ok = true;
  while (true) {
    if (used == text.size())
      text.resize(std::max({2 * used, size + 1, size_t{1} << 16}));
    const size_t got = std::fread(&text[used], 1, text.size() - used, file);
    used += got;
    if (used < text.size()) {  // a short read: the end, or an error
      ok = std::ferror(file) == 0;
      break;
    }
  }
  std::fclose(file);
  text.resize(used);
  return ok;
}

/// @return The base name of @p path (what diagnostics show).
inline std::string baseName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace io_detail
}  // namespace mobility_analysis
