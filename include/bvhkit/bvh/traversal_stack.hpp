#pragma once
// TraversalStack: the fixed-size stack of a depth-first walk, in place of a raw array. A walk that
// pushes one child and goes on into the other holds at most one entry per level, so max_bvh_depth
// entries suffice for every tree the builders make (and validate() accepts). Debug builds (!NDEBUG)
// check the bound on every push and pop and throw bvhkit::Error, so a deeper tree (one assembled by
// hand) fails loudly there instead of writing past the array; release builds do not pay for the
// check. Never zero-filled: made per query, it costs nothing until used.
#include <cstddef>
#include <cstdint>
#include <string>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/error.hpp"

namespace bvhkit {

template <class Entry, std::size_t Capacity>
class FixedStack {
  public:
    static constexpr std::size_t capacity = Capacity;

    bool empty() const { return size_ == 0; }
    std::size_t size() const { return size_; }
    void clear() { size_ = 0; }

    void push(const Entry& e) {
#if !defined(NDEBUG)
        if (size_ == Capacity)
            throw Error("traversal stack: more than " + std::to_string(Capacity) +
                        " entries (a tree deeper than max_bvh_depth?)");
#endif
        items_[size_++] = e;
    }
    /// Writes `e` on top and keeps it only when `keep`: a push without a data-dependent branch,
    /// for walks whose choice mispredicts (ray traversal of incoherent rays).
    void push_if(const Entry& e, bool keep) {
#if !defined(NDEBUG)
        if (size_ == Capacity)
            throw Error("traversal stack: more than " + std::to_string(Capacity) +
                        " entries (a tree deeper than max_bvh_depth?)");
#endif
        items_[size_] = e;
        size_ += keep;
    }
    Entry pop() {
#if !defined(NDEBUG)
        if (size_ == 0) throw Error("traversal stack: pop from an empty stack");
#endif
        return items_[--size_];
    }
    const Entry& top() const {
        return items_[size_ - 1];
    }
    /// The entry k below the top (0: the top), for walks that reorder what they just pushed.
    Entry& from_top(std::size_t k) {
#if !defined(NDEBUG)
        if (k >= size_) throw Error("traversal stack: read below the bottom");
#endif
        return items_[size_ - 1 - k];
    }

  private:
    Entry items_[Capacity];  // left uninitialized: only [0, size_) is ever read
    std::size_t size_ = 0;
};

/// The stack of node indices every depth-first walk over a Bvh uses.
using TraversalStack = FixedStack<std::uint32_t, max_bvh_depth>;

}  // namespace bvhkit
