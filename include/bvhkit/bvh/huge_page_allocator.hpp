#pragma once
// HugePageAllocator: an array of 2 MB or more is placed on 2 MB boundaries and, on Linux, marked
// for transparent huge pages (madvise MADV_HUGEPAGE: a hint, ignored where the kernel has them
// off). Rays through a large tree read its nodes and leaves at random; with 4 KB pages a tree of
// tens of megabytes spans more pages than the TLB holds, and most steps of the walk would add a
// page walk to their cache miss. Embree places its trees the same way. Smaller arrays take the
// default allocator.
#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace bvhkit {

template <class T>
struct HugePageAllocator {
    using value_type = T;
    static constexpr std::size_t huge_page = std::size_t(2) << 20;

    HugePageAllocator() = default;
    template <class U>
    HugePageAllocator(const HugePageAllocator<U>&) {}

    static bool uses_huge_pages(std::size_t n) {
#if defined(__linux__)
        // n * sizeof(T) >= huge_page, without overflow for any n.
        return n >= (huge_page + sizeof(T) - 1) / sizeof(T) && alignof(T) <= huge_page;
#else
        (void)n;
        return false;
#endif
    }

    T* allocate(std::size_t n) {
        if (n > (std::size_t(-1) - huge_page) / sizeof(T)) throw std::bad_array_new_length();
#if defined(__linux__)
        if (uses_huge_pages(n)) {
            const std::size_t bytes = (n * sizeof(T) + huge_page - 1) / huge_page * huge_page;
            void* p = std::aligned_alloc(huge_page, bytes);
            if (!p) throw std::bad_alloc();
#if defined(MADV_HUGEPAGE)
            madvise(p, bytes, MADV_HUGEPAGE);  // only a hint: the memory is usable whatever it says
#endif
            return static_cast<T*>(p);
        }
#endif
        return std::allocator<T>{}.allocate(n);
    }
    void deallocate(T* p, std::size_t n) {
        if (uses_huge_pages(n))
            std::free(p);
        else
            std::allocator<T>{}.deallocate(p, n);
    }

    template <class U>
    bool operator==(const HugePageAllocator<U>&) const {
        return true;
    }
};

}  // namespace bvhkit
