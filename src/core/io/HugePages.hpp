#pragma once

// Private to the readers in src/core/io: large fresh buffers backed by huge pages where the kernel allows it.

#include <sys/mman.h>

#include <cstddef>
#include <cstdint>

namespace mobility_analysis {
namespace io_detail {

/**
 * @brief Asks the kernel to back the whole 2 MiB pages inside [@p data, @p data + @p bytes) with huge pages
 *        (transparent huge pages in "madvise" mode); nothing where it does not support them.
 *
 * A fresh buffer of tens of megabytes (a 10^5-link file's text, its 10^5 connections of 400 bytes) is
 * otherwise touched in 4 KiB page faults, each charged to the memory cgroup: a fault costs more than the
 * bytes it clears. Call it before the buffer is first written; it changes no byte of it.
 */
inline void adviseHugePages(const void* data, size_t bytes) {
#ifdef MADV_HUGEPAGE
  constexpr uintptr_t kHugePage = uintptr_t{1} << 21;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHugePage - 1) & ~(kHugePage - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHugePage - 1);
  if (end > begin)
    ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

}  // namespace io_detail
}  // namespace mobility_analysis
