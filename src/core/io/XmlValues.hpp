#pragma once

// Private to the readers in src/core/io: strict number parsing shared by the XML readers.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <string>

#include <Eigen/Geometry>

#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {
namespace io_detail {

/// @return The number in @p text (surrounding blanks allowed), or nothing when it is not one.
inline std::optional<double> parseDouble(const std::string& text) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double value = std::strtod(begin, &end);
  if (end == begin) {
    return std::nullopt;
  }
  while (*end == ' ' || *end == '\t' || *end == '\n' || *end == '\r') {
    ++end;
  }
  if (*end != '\0') {
    return std::nullopt;
  }
  return value;
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

/// URDF fixed-axis roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll).
inline Eigen::Isometry3d makeFrame(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy) {
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.linear() = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                    Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                       .toRotationMatrix();
  frame.translation() = xyz;
  return frame;
}

/**
 * @brief A URDF `<joint><origin>` frame, its rotation through the quaternion of roll-pitch-yaw as urdfdom
 *        computes it (then normalised), so tree-joint frames are bit for bit those urdfdom gave.
 */
inline Eigen::Isometry3d makeOriginFrame(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy) {
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
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.linear() = Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
  frame.translation() = xyz;
  return frame;
}

/// Reads the whole file at @p path into @p text in one read (no stream copies); false when it cannot be read.
inline bool readWholeFile(const std::string& path, std::string& text) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr)
    return false;
  text.clear();
  char buffer[1 << 16];
  if (std::fseek(file, 0, SEEK_END) == 0) {
    const long size = std::ftell(file);
    if (size > 0)
      text.reserve(static_cast<size_t>(size));
    std::rewind(file);
  }
  bool ok = true;
  while (true) {
    const size_t got = std::fread(buffer, 1, sizeof(buffer), file);
    text.append(buffer, got);
    if (got < sizeof(buffer)) {
      ok = std::ferror(file) == 0;
      break;
    }
  }
  std::fclose(file);
  return ok;
}

/// @return The base name of @p path (what diagnostics show).
inline std::string baseName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace io_detail
}  // namespace mobility_analysis
