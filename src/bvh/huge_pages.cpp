// The allocation behind HugePageAllocator (bvh/huge_page_allocator.hpp).
#include <cstdlib>
#include <new>

#include "bvhkit/bvh/huge_page_allocator.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace bvhkit::detail {

void* allocate_huge_pages(std::size_t bytes) {
    void* p = std::aligned_alloc(huge_page_bytes, bytes);
    if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(p, bytes, MADV_HUGEPAGE);  // only a hint: the memory is usable whatever it says
#endif
    return p;
}

void free_huge_pages(void* p) noexcept {
    std::free(p);
}

}  // namespace bvhkit::detail
