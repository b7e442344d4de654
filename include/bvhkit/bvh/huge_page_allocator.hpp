#pragma once
// HugePageAllocator: on Linux, an array of 2 MB or more is placed on 2 MB boundaries and marked
// for transparent huge pages (madvise MADV_HUGEPAGE: a hint, ignored where the kernel has them
// off). Rays through a large tree read its nodes and leaves at random; with 4 KB pages a tree of
// tens of megabytes spans more pages than the TLB holds, and most steps of the walk would add a
// page walk to their cache miss. Embree places its trees the same way. Smaller arrays, and every
// array elsewhere, take the default allocator.
#include <cstddef>
#include <memory>
#include <new>

namespace bvhkit {

namespace detail {
/// `bytes` (a multiple of huge_page_bytes) on a huge_page_bytes boundary, advised for huge pages
/// (src/bvh/huge_pages.cpp, which keeps <sys/mman.h> out of this header); throws std::bad_alloc.
void* allocate_huge_pages(std::size_t bytes);
void free_huge_pages(void* p) noexcept;
inline constexpr std::size_t huge_page_bytes = std::size_t(2) << 20;
}  // namespace detail

template <class T>
struct HugePageAllocator {
    using value_type = T;
    static constexpr std::size_t huge_page = detail::huge_page_bytes;

    HugePageAllocator() = default;
    template <class U>
    HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

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
        if (uses_huge_pages(n)) {
            const std::size_t bytes = (n * sizeof(T) + huge_page - 1) / huge_page * huge_page;
            return static_cast<T*>(detail::allocate_huge_pages(bytes));
        }
        return std::allocator<T>{}.allocate(n);
    }
    void deallocate(T* p, std::size_t n) {
        if (uses_huge_pages(n))
            detail::free_huge_pages(p);
        else
            std::allocator<T>{}.deallocate(p, n);
    }

    template <class U>
    bool operator==(const HugePageAllocator<U>&) const {
        return true;
    }
};

}  // namespace bvhkit
