#pragma once
// SmallStack: the traversal stack of the dynamic tree's queries. The first Inline entries live in
// the object itself (on the caller's stack frame), so a query allocates nothing unless the tree is
// deeper than any balanced tree could be; past that it spills into a heap vector instead of
// failing.
#include <cstddef>
#include <vector>

#include "bvhkit/tuning.hpp"

namespace bvhkit::dynamic_detail {

template <class E, std::size_t Inline = tuning::dynamic_stack_inline>
class SmallStack {
  public:
    bool empty() const { return size_ == 0; }
    std::size_t size() const { return size_; }
    void clear() {
        size_ = 0;
        overflow_.clear();
    }

    void push(const E& e) {
        if (size_ < Inline) {
            inline_[size_++] = e;
        } else {
            overflow_.push_back(e);
            ++size_;
        }
    }
    E pop() {
        --size_;
        if (size_ < Inline) return inline_[size_];
        E e = overflow_.back();
        overflow_.pop_back();
        return e;
    }

  private:
    E inline_[Inline];
    std::size_t size_ = 0;
    std::vector<E> overflow_;
};

}  // namespace bvhkit::dynamic_detail
