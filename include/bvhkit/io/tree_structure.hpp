#pragma once
// check_tree_structure(): what a loaded tree must satisfy before any query may walk it, whatever
// its boxes hold. Loaders run it even when the caller opts out of validate(), which adds the
// geometric checks (enclosure, finite boxes, each primitive once): a tree that passes this one can
// give wrong answers but cannot make a query read out of range, overflow the traversal stack or
// loop. Linear time; allocates two bytes per node and per slot.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/bvh/validate.hpp"
#include "bvhkit/error.hpp"

namespace bvhkit::serial_detail {

/// Children in range and after their parent, every node reached exactly once from the root (no
/// cycle, no shared child), depth <= max_bvh_depth, leaf runs non-empty and tiling the slots
/// exactly, every primitive index < primitive_count (callers index their own arrays with it).
template <class Tree>  // a Bvh or a BvhView
void check_tree_structure(const Tree& bvh, std::uint64_t primitive_count, const char* what) {
    auto fail = [&](const std::string& m) { throw Error(std::string(what) + ": " + m); };
    for (std::size_t s = 0; s < bvh.primitive_indices.size(); ++s)
        if (bvh.primitive_indices[s] >= primitive_count)
            fail("slot " + std::to_string(s) + " names primitive " +
                 std::to_string(bvh.primitive_indices[s]) + " of " +
                 std::to_string(primitive_count));
    check_structure(
        bvh, fail, [](const auto&, std::uint32_t) {}, [](const auto&, std::uint32_t) {});
}

}  // namespace bvhkit::serial_detail
