#pragma once
// Whether spatial splits (build/spatial_splits.hpp) would pay on a mesh, judged from the tree the
// default build made of it: they pay where sibling boxes overlap, since a ray in the overlap
// visits both, and an object split cannot separate triangles whose boxes cross (walls and floors
// that span the scene, unconnected triangles; the restriction of Stich et al. 2009 weighs the
// same overlap node by node). child_overlap measures it over the whole tree, in the surface area
// terms the SAH prices a ray's visits with: the summed area of the two children's intersection at
// each inner node, over the summed area of the inner nodes. Scans and height fields, whose
// triangles are small and connected, share little; rooms and triangle soups share much more.
#include <algorithm>
#include <cstddef>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

/// The tree's child overlap, in [0, 1]: sum over inner nodes of the area of the intersection of
/// the children's boxes, over the sum of the inner nodes' areas; 0 for a tree without inner nodes
/// or of zero area. Areas are summed in double.
template <class T>
double child_overlap(const Bvh<Aabb<T, 3>>& bvh) {
    // The area of the box [lo, hi]; 0 if it is empty on some axis (a flat box has the area of
    // its face: siblings that touch share it).
    const auto area = [](const Vec<T, 3>& lo, const Vec<T, 3>& hi) {
        double d[3];
        for (int a = 0; a < 3; ++a) {
            if (!(lo[a] <= hi[a])) return 0.0;
            d[a] = double(hi[a]) - double(lo[a]);
        }
        return 2 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
    };
    double shared = 0, total = 0;
    for (const auto& n : bvh.nodes) {
        if (n.is_leaf()) continue;
        const auto& l = bvh.nodes[n.left()].bounds;
        const auto& r = bvh.nodes[n.right()].bounds;
        Vec<T, 3> lo, hi;
        for (int a = 0; a < 3; ++a)
            lo[a] = std::max(l.min[a], r.min[a]), hi[a] = std::min(l.max[a], r.max[a]);
        shared += area(lo, hi);
        total += area(n.bounds.min, n.bounds.max);
    }
    // The intersection lies in the node's box, so the share is at most 1 (NaN boxes aside).
    return total > 0 ? std::min(1.0, shared / total) : 0.0;
}

/// Whether a tree of this overlap is worth rebuilding with spatial splits (tuning.hpp).
inline bool spatial_splits_pay(double overlap) {
    return overlap >= tuning::spatial_splits_from_overlap;
}

}  // namespace bvhkit
