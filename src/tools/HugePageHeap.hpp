#pragma once

#include <string>

namespace mobility_analysis {

/// The heap our executables run on, as one line (`jemalloc-5.3.0,thp:always,dirty_decay_ms:10000`): what
/// mobility_benchmark prints beside its figures, so a table says which allocator it was measured on.
/// Defined in HugePageHeap.cpp, which every executable links (CMakeLists.txt, ma_huge_page_heap).
std::string heapDescription();

}  // namespace mobility_analysis
