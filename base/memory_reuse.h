// Keeping freed memory for reuse: the allocator policy of the waxwork process (and of the benchmarks,
// which measure what it does).
//
// Why. Every edit allocates and frees large arrays: after a cut the connectivity, the matrix, the
// boundary and shadow BVH and, for the multigrid method, the hierarchy and the Galerkin operators are
// built anew, hundreds of MB at 500K tets. glibc's malloc serves each block above its mmap threshold
// (adaptive, at most 32 MiB) with a fresh mmap, unmaps it on free, and trims the heap top beyond 128
// KiB, so the next edit first pays a page fault and the zeroing of every 4 KiB page it touches. On
// the virtual machine measured here that is most of the setup's time (spot at 486,745 tets: the
// plane cut with the live scene's rebuild, the multigrid setup and a hierarchy build after other work
// take 2 to 4 times as long without the policy; docs/performance.md). With the policy, blocks up to
// 1 GiB come from the heap and freed memory stays there for the next edit instead of going back to
// the system.
//
// Cost: the process keeps up to 1 GiB of freed memory mapped (its resident size stays near its peak
// instead of falling after an edit), and large blocks may fragment the heap. Allocations of other
// threads' arenas above their 64 MiB heaps are still mapped.
#pragma once

namespace waxwork {

// Applies the policy (glibc mallopt: M_MMAP_THRESHOLD and M_TRIM_THRESHOLD at kMemoryReuseBytes).
// Process-wide and meant for main(), before the work starts. Returns false when the C library refused
// (or is not glibc), leaving the allocator as it was.
bool keep_freed_memory_for_reuse();

inline constexpr long kMemoryReuseBytes = 1L << 30;

}  // namespace waxwork
