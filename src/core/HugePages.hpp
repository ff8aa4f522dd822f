#pragma once

// Private to src/core: large buffers the analysis fills once, backed by transparent huge pages where the
// system offers them on request (Linux, /sys/kernel/mm/transparent_hugepage/enabled = madvise).

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace mobility_analysis {
namespace core_detail {

/// Buffers smaller than this are left alone (below a few huge pages the advice saves nothing) [bytes].
constexpr size_t kHugePageAdviceFloor = size_t{8} << 20;

/**
 * @brief Asks the kernel to back the untouched buffer [@p data, @p data + @p bytes) with huge pages.
 *
 * A 10^5-link model fills 10^2 MB of fresh memory while it is assembled: at 4 KiB a page, the page faults
 * (a fault and a cgroup charge each) were a fifth of the phase's time. With 2 MiB pages there are 512 times
 * fewer. Only the whole 2 MiB blocks inside the buffer are advised; the contents are unchanged, and where the
 * system refuses (or is not Linux) nothing happens.
 */
inline void adviseHugePages(const void* data, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (bytes < kHugePageAdviceFloor)
    return;
  constexpr uintptr_t kHuge = uintptr_t{2} << 20;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (end > begin)
    madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

/// adviseHugePages for the room a vector has reserved.
template <class Vector>
void adviseHugePagesOf(const Vector& vector) {
  adviseHugePages(vector.data(), vector.capacity() * sizeof(typename Vector::value_type));
}

/// @p count identity poses, in huge pages when large (LinkPoses: 128 bytes a link).
inline std::vector<Eigen::Isometry3d> makeLinkPoses(size_t count) {
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(count);
  adviseHugePagesOf(poses);
  poses.assign(count, Eigen::Isometry3d::Identity());
  return poses;
}

}  // namespace core_detail
}  // namespace mobility_analysis
