#pragma once
// The explicit stack of the BSP traversals: a fixed array on the call stack (tuning.hpp; a ray
// query needs depth + 2, a visit 2 depth + 4), one heap block per query beyond; none per step.
#include <cstddef>
#include <vector>

#include "bvhkit/tuning.hpp"

namespace bvhkit::bsp_detail {

template <class E>
class BspTraversalStack {
  public:
    static constexpr std::size_t inline_capacity = tuning::bsp_stack_inline;
    explicit BspTraversalStack(std::size_t capacity) {
        if (capacity > inline_capacity) {
            heap_.resize(capacity);
            data_ = heap_.data();
        }
    }
    BspTraversalStack(const BspTraversalStack&) = delete;
    BspTraversalStack& operator=(const BspTraversalStack&) = delete;
    void push(const E& e) { data_[size_++] = e; }
    E pop() { return data_[--size_]; }
    bool empty() const { return size_ == 0; }
    void clear() { size_ = 0; }

  private:
    E inline_[inline_capacity];
    std::vector<E> heap_;
    E* data_ = inline_;
    std::size_t size_ = 0;
};

}  // namespace bvhkit::bsp_detail
