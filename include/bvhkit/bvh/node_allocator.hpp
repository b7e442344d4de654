#pragma once
// NodeAllocator: places a node array so that element 1 starts a 64-byte cache line. Sibling pairs
// start at odd indices (1, 3, 5, ...: the root is 0 and pairs are appended after it), so with
// 32-byte nodes every pair then fills exactly one cache line, and a traversal step that tests both
// children touches one line instead of two.
#include <cstddef>
#include <cstdlib>
#include <new>

namespace bvhkit {

template <class T>
struct NodeAllocator {
    using value_type = T;
    static constexpr std::size_t line = 64;

    NodeAllocator() = default;
    template <class U>
    NodeAllocator(const NodeAllocator<U>&) {}

    T* allocate(std::size_t n) {
        // Over-allocate one line; element 1 lands on a line boundary when sizeof(T) divides 64.
        constexpr std::size_t shift =
            sizeof(T) < line && line % sizeof(T) == 0 ? line - sizeof(T) : 0;
        const std::size_t bytes = (n * sizeof(T) + line + line - 1) / line * line;
        void* base = std::aligned_alloc(line, bytes);
        if (!base) throw std::bad_alloc();
        return reinterpret_cast<T*>(static_cast<std::byte*>(base) + shift);
    }
    void deallocate(T* p, std::size_t) {
        constexpr std::size_t shift =
            sizeof(T) < line && line % sizeof(T) == 0 ? line - sizeof(T) : 0;
        std::free(reinterpret_cast<std::byte*>(p) - shift);
    }
    template <class U>
    bool operator==(const NodeAllocator<U>&) const {
        return true;
    }
};

}  // namespace bvhkit
