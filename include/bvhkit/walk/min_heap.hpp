#pragma once
// A 4-ary min-heap over a caller's vector: the heap of the best-first walk (walk/walks.hpp).
// Against std::push_heap/pop_heap on a binary heap it halves the levels a pop sifts through, and
// the least of four children is found with selects rather than jumps: the comparisons of a
// best-first walk are unpredictable, and their mispredictions were the largest single cost of a
// nearest query (d-ary heaps: Johnson 1975, "Priority queues with update and finding minimum
// spanning trees").
#include <cstddef>
#include <vector>

#include "bvhkit/math/select.hpp"

namespace bvhkit {

/// `key(entry)` gives the value ordered by (smallest first). The vector is the heap's storage,
/// kept by the caller so queries reuse its capacity.
template <class Entry, class Key>
class MinHeap4 {
  public:
    MinHeap4(std::vector<Entry>& storage, Key key) : v_(storage), key_(key) { v_.clear(); }

    bool empty() const { return v_.empty(); }
    const Entry& top() const { return v_.front(); }
    /// The value an entry is ordered by.
    auto key(const Entry& e) const { return key_(e); }

    void push(const Entry& e) {
        std::size_t i = v_.size();
        v_.push_back(e);
        const auto k = key_(e);
        while (i > 0) {
            const std::size_t parent = (i - 1) / 4;
            if (!(k < key_(v_[parent]))) break;
            v_[i] = v_[parent];
            i = parent;
        }
        v_[i] = e;
    }

    Entry pop() {
        const Entry top = v_.front();
        const Entry last = v_.back();
        v_.pop_back();
        const std::size_t n = v_.size();
        if (n == 0) return top;
        const auto k = key_(last);
        std::size_t i = 0;
        while (true) {
            const std::size_t first = 4 * i + 1;
            if (first >= n) break;
            std::size_t least = first;
            auto least_key = key_(v_[first]);
            if (first + 3 < n) {
                // All four children: a tournament in arithmetic on the comparisons' outcomes,
                // which the compiler keeps free of jumps.
                const auto k0 = key_(v_[first]), k1 = key_(v_[first + 1]);
                const auto k2 = key_(v_[first + 2]), k3 = key_(v_[first + 3]);
                const std::size_t a = first + std::size_t(k1 < k0);
                const std::size_t b = first + 2 + std::size_t(k3 < k2);
                const auto ka = min_of(k0, k1), kb = min_of(k2, k3);
                const std::size_t right = std::size_t(kb < ka);
                least = a + (b - a) * right;
                least_key = min_of(ka, kb);
            } else {
                for (std::size_t c = first + 1; c < n; ++c) {
                    const auto kc = key_(v_[c]);
                    if (kc < least_key) least = c, least_key = kc;
                }
            }
            if (!(least_key < k)) break;
            v_[i] = v_[least];
            i = least;
        }
        v_[i] = last;
        return top;
    }

  private:
    std::vector<Entry>& v_;
    Key key_;
};

}  // namespace bvhkit
