/// Every executable of the package (the CLI, the node, the benchmarks) runs on jemalloc with transparent huge
/// pages. Why: a large report spends much of its time on first touches of fresh memory. A 10^5-link chain's
/// report takes 92 000 page faults of 4 KiB; on the virtual machines we measure on, each costs microseconds,
/// 27 % of the report's profile (perf: exc_page_fault), and the report is 1.2-2.3x faster without them.
/// Huge pages of 2 MiB cut the faults by up to 512; jemalloc asks the kernel for them with
/// madvise(MADV_HUGEPAGE), which works where the system's policy is "madvise" (Debian's default) without any
/// system setting. Measured in bench/RESULTS.md, tenth round.
///
/// jemalloc reads its options from the global `malloc_conf` once, at start-up (jemalloc(3), TUNING); the
/// environment variable MALLOC_CONF, read after it, still overrides any of them.
///   thp:always         huge pages for every arena's memory
///   metadata_thp:auto  and for jemalloc's own metadata once it grows past one huge page
/// Freed pages go back to the system on jemalloc's default decay (10 s). Never handing them back
/// (MALLOC_CONF=dirty_decay_ms:-1) spares the pages faulted in again: the 200 x 200 braced lattice's faults
/// fall from 12 400 to 2 600 and its report from 2.4-3.2 to 2.2-2.4 s (one thread: 4.6 to 2.9 s), the
/// 10^5-size families move within the noise, but the peak grows by up to 25 % (the 10^6-link chain 2.2-2.4 to
/// 2.9 GB), and memory is the target we are closer to.
///
/// The library itself (libmobility_analysis_core) leaves the allocator to whatever program links it.
#include "HugePageHeap.hpp"

#include <jemalloc/jemalloc.h>

extern "C" {
// NOLINTNEXTLINE(cppcoreguidelines-avoid-non-const-global-variables): the name and type jemalloc looks up
const char* malloc_conf = "thp:always,metadata_thp:auto";
}

namespace mobility_analysis {

std::string heapDescription() {
  const char* version = nullptr;
  const char* thp = nullptr;
  ssize_t dirtyDecay = 0;
  std::size_t size = sizeof(const char*);
  std::size_t decaySize = sizeof(ssize_t);
  // mallctl answers 0 when the option exists; anything else means jemalloc is not the heap after all (a
  // preloaded allocator, say), which the description says instead of guessing.
  if (mallctl("version", &version, &size, nullptr, 0) != 0 ||
      mallctl("opt.thp", &thp, &size, nullptr, 0) != 0 ||
      mallctl("opt.dirty_decay_ms", &dirtyDecay, &decaySize, nullptr, 0) != 0) {
    return "unknown";
  }
  std::string shortVersion(version);
  shortVersion = shortVersion.substr(0, shortVersion.find('-'));
  return "jemalloc-" + shortVersion + ",thp:" + thp + ",dirty_decay_ms:" + std::to_string(dirtyDecay);
}

}  // namespace mobility_analysis
