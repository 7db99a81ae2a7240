#include "editor/memory_reuse.h"

#include <cstdlib>  // defines __GLIBC__ on glibc systems

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace waxwork {

bool keep_freed_memory_for_reuse() {
#if defined(__GLIBC__)
    // Trim first: with the threshold at 1 GiB, a block up to that size is served from the heap, and the
    // heap keeps up to that much free at its top.
    if (mallopt(M_TRIM_THRESHOLD, static_cast<int>(kMemoryReuseBytes)) != 1) return false;
    return mallopt(M_MMAP_THRESHOLD, static_cast<int>(kMemoryReuseBytes)) == 1;
#else
    return false;
#endif
}

}  // namespace waxwork
