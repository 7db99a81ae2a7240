#include "base/memory_reuse.h"

#include <cstdlib>  // defines __GLIBC__ on glibc systems

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace waxwork {

bool keep_freed_memory_for_reuse() {
#if defined(__GLIBC__)
    // The trim threshold keeps freed memory at the heap's top; the mmap threshold makes blocks up to
    // 1 GiB come from the heap in the first place (a mapped block is unmapped on free whatever the trim).
    if (mallopt(M_TRIM_THRESHOLD, static_cast<int>(kMemoryReuseBytes)) != 1) return false;
    return mallopt(M_MMAP_THRESHOLD, static_cast<int>(kMemoryReuseBytes)) == 1;
#else
    return false;
#endif
}

}  // namespace waxwork
