#pragma once
// Point classification against a solid BSP (Thibault and Naylor 1987): built by auto-partition to
// empty leaves over a closed mesh whose triangles face outwards (in 2D: closed polygons whose
// segments run counter-clockwise), every empty leaf is wholly inside
// or wholly outside, so one descent (the point's side of each splitter) answers.
#include "bvhkit/bsp/bsp_tree.hpp"

namespace bvhkit {

enum class PointLocation : std::uint8_t { Outside, Inside, Unknown };

/// Inside or Outside for a tree with is_solid(); Unknown where the descent ends in a leaf that
/// holds polygons or lies beside an axis-aligned splitter (a non-solid tree), and for a point that
/// is not finite. A point within the plane thickness of a splitter goes to its front; the answer
/// for points that close to the surface itself is either.
template <class T, std::size_t N>
PointLocation classify_point(const BspTree<T, N>& tree, const Vec<T, N>& p) {
    if (!is_finite(p)) return PointLocation::Unknown;
    const auto& nodes = tree.nodes();
    std::uint32_t k = 0;
    while (!nodes[k].is_leaf())
        k = nodes[k].plane.distance(p) >= T(0) ? nodes[k].front : nodes[k].back;
    const BspNode<T, N>& leaf = nodes[k];
    if (leaf.count != 0) return PointLocation::Unknown;
    switch (leaf.cell) {
        case BspCell::Inside:
            return PointLocation::Inside;
        case BspCell::Outside:
            return PointLocation::Outside;
        default:
            return PointLocation::Unknown;
    }
}

}  // namespace bvhkit
