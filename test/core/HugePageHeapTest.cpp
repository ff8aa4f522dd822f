/// Every executable runs on jemalloc with transparent huge pages (src/tools/HugePageHeap.cpp): this test
/// links the same file as they do and checks that jemalloc really read our options (it would not if it were
/// built with a symbol prefix, or if the linker dropped it) and that the kernel really backs a large touched
/// buffer with huge pages where the system allows them at all.
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "HugePageHeap.hpp"

using namespace mobility_analysis;

namespace {

/// @return The kilobytes of "AnonHugePages" in /proc/self/smaps_rollup, or -1 when the file cannot be read.
long anonymousHugePageKilobytes() {
  std::ifstream rollup("/proc/self/smaps_rollup");
  std::string line;
  while (std::getline(rollup, line)) {
    if (line.rfind("AnonHugePages:", 0) == 0) {
      std::istringstream fields(line.substr(14));
      long kilobytes = -1;
      fields >> kilobytes;
      return kilobytes;
    }
  }
  return -1;
}

/// @return The system's policy, the bracketed word of /sys/kernel/mm/transparent_hugepage/enabled.
std::string systemPolicy() {
  std::ifstream file("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const size_t open = text.find('['), close = text.find(']');
  return open == std::string::npos || close == std::string::npos ? ""
                                                                 : text.substr(open + 1, close - open - 1);
}

}  // namespace

TEST(HugePageHeap, JemallocReadTheOptions) {
  const std::string heap = heapDescription();
  EXPECT_EQ(heap.rfind("jemalloc-", 0), 0u) << heap;
  EXPECT_NE(heap.find(",thp:always,"), std::string::npos) << heap;
  EXPECT_NE(heap.find(",dirty_decay_ms:10000"), std::string::npos) << heap;
}

TEST(HugePageHeap, LargeBuffersGetHugePages) {
  const std::string policy = systemPolicy();
  if (policy != "madvise" && policy != "always")
    GTEST_SKIP() << "transparent huge pages are '" << policy << "' on this system";
  const long before = anonymousHugePageKilobytes();
  ASSERT_GE(before, 0) << "no /proc/self/smaps_rollup";
  // 64 MiB, every page touched by the zeroing: at least one aligned 2 MiB range of it must be a huge page.
  // Each page then gets its own index, read back at the end, so that the compiler cannot drop the buffer
  // (a new-expression whose memory is never observed may be elided).
  constexpr size_t kBytes = size_t{64} << 20;
  const std::unique_ptr<char[]> buffer = std::make_unique<char[]>(kBytes);
  for (size_t i = 0; i < kBytes; i += 4096)
    buffer[i] = static_cast<char>(i / 4096);
  const long after = anonymousHugePageKilobytes();
  EXPECT_GE(after - before, 2048) << "AnonHugePages " << before << " -> " << after << " kB";
  EXPECT_EQ(buffer[5 * 4096], 5);
}
