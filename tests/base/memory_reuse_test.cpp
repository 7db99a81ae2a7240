#include "base/memory_reuse.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace waxwork {
namespace {

#if defined(__GLIBC__)
// A block of `bytes`, every page written (as a matrix being filled would be).
char* touched_block(size_t bytes) {
    auto* block = static_cast<char*>(std::malloc(bytes));
    if (block) std::memset(block, 1, bytes);
    return block;
}

// Each test of this binary runs in its own process (gtest_discover_tests), so the allocator starts
// with glibc's defaults here and the policy changes only this process.
TEST(MemoryReuse, LargeBlocksComeFromTheHeapAndStayForTheNextEdit) {
    constexpr size_t kBlock = size_t{96} << 20;  // above glibc's largest adaptive mmap threshold (32 MiB)

    // glibc's default: the block is mapped on its own and unmapped when freed.
    const size_t mapped_before = mallinfo2().hblkhd;
    char* block = touched_block(kBlock);
    ASSERT_NE(block, nullptr);
    EXPECT_GE(mallinfo2().hblkhd, mapped_before + kBlock);
    std::free(block);
    EXPECT_LT(mallinfo2().hblkhd, mapped_before + kBlock);

    ASSERT_TRUE(keep_freed_memory_for_reuse());
    const size_t mapped = mallinfo2().hblkhd;
    block = touched_block(kBlock);
    ASSERT_NE(block, nullptr);
    EXPECT_LT(mallinfo2().hblkhd, mapped + kBlock);  // from the heap, not a mapping of its own
    std::free(block);
    // Freed but kept: the heap holds it as free memory instead of trimming it back to the system.
    EXPECT_GE(mallinfo2().fordblks, kBlock);
    // And the next block of that size reuses it without growing the heap.
    const size_t arena = mallinfo2().arena;
    block = touched_block(kBlock);
    ASSERT_NE(block, nullptr);
    EXPECT_EQ(mallinfo2().arena, arena);
    std::free(block);
}
#endif

}  // namespace
}  // namespace waxwork
