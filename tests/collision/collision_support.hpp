#pragma once
// Brute-force references for the collision tests: every pair of triangles, with an exact box
// prefilter in A's frame (two triangles that meet have boxes that meet, so the prefilter drops no
// intersecting pair; boxes are widened by a hair so rounding at touching contacts cannot either).
#include <algorithm>
#include <set>
#include <utility>
#include <vector>

#include "bvhkit/math/random.hpp"
#include "bvhkit/primitives/triangle_distance.hpp"
#include "bvhkit/query/pairs_model.hpp"

namespace bvhkit::test {

template <class T>
Aabb<T, 3> widened_box(const Triangle<T>& t, T pad) {
    Aabb<T, 3> b = t.bounds();
    b.min = b.min - Vec<T, 3>(pad);
    b.max = b.max + Vec<T, 3>(pad);
    return b;
}

/// Calls f(i, j) for every pair (i in a, j in b) whose widened boxes overlap: all pairs, by a
/// sweep over x (sorted by min x; a box of b can overlap a box of a only if its min x lies in
/// [a.min.x - widest b box, a.max.x]).
template <class T, class F>
void for_each_box_pair(const std::vector<Aabb<T, 3>>& a, const std::vector<Aabb<T, 3>>& b, F&& f) {
    std::vector<std::uint32_t> order(b.size());
    for (std::uint32_t i = 0; i < b.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](std::uint32_t x, std::uint32_t y) { return b[x].min[0] < b[y].min[0]; });
    std::vector<T> mins(b.size());
    T widest = 0;
    for (std::size_t k = 0; k < order.size(); ++k) {
        mins[k] = b[order[k]].min[0];
        widest = std::max(widest, b[order[k]].max[0] - b[order[k]].min[0]);
    }
    for (std::uint32_t i = 0; i < a.size(); ++i) {
        auto k = std::lower_bound(mins.begin(), mins.end(), a[i].min[0] - widest) - mins.begin();
        for (; k < std::ptrdiff_t(order.size()) && mins[k] <= a[i].max[0]; ++k)
            if (a[i].overlaps(b[order[k]])) f(i, order[k]);
    }
}

using PairSet = std::set<std::pair<std::uint32_t, std::uint32_t>>;

/// Every intersecting pair (i in a, j in b) with b carried into a's frame by `pose` exactly as
/// collide() carries it (transformed()).
template <class T>
PairSet brute_force_pairs(const std::vector<Triangle<T>>& a, const std::vector<Triangle<T>>& b,
                          const Transform<T>& pose, T pad) {
    std::vector<Triangle<T>> bt(b.size());
    for (std::size_t j = 0; j < b.size(); ++j) bt[j] = transformed(b[j], pose);
    std::vector<Aabb<T, 3>> ba(a.size()), bb(b.size());
    for (std::size_t i = 0; i < a.size(); ++i) ba[i] = widened_box(a[i], pad);
    for (std::size_t j = 0; j < b.size(); ++j) bb[j] = widened_box(bt[j], pad);
    PairSet out;
    for_each_box_pair(ba, bb, [&](std::uint32_t i, std::uint32_t j) {
        if (triangles_intersect(a[i], bt[j])) out.insert({i, j});
    });
    return out;
}

/// Every intersecting pair i < j of one mesh's triangles that share no vertex index.
template <class T>
PairSet brute_force_self(const BasicTriangleMesh<T>& m, T pad) {
    const auto tris = mesh_triangles(m);
    std::vector<Aabb<T, 3>> boxes(tris.size());
    for (std::size_t i = 0; i < tris.size(); ++i) boxes[i] = widened_box(tris[i], pad);
    PairSet out;
    for_each_box_pair(boxes, boxes, [&](std::uint32_t i, std::uint32_t j) {
        if (i >= j) return;
        for (auto x : m.triangles[i])
            for (auto y : m.triangles[j])
                if (x == y) return;
        if (triangles_intersect(tris[i], tris[j])) out.insert({i, j});
    });
    return out;
}

/// The least distance over all triangle pairs (zero-area ones included); pairs whose boxes are
/// already farther apart than the best so far cannot be closer and are skipped.
template <class T>
T brute_force_distance(const std::vector<Triangle<T>>& a, const std::vector<Triangle<T>>& b,
                       const Transform<T>& pose) {
    std::vector<Triangle<T>> bt(b.size());
    std::vector<Aabb<T, 3>> bb(b.size());
    for (std::size_t j = 0; j < b.size(); ++j) {
        bt[j] = transformed(b[j], pose);
        bb[j] = bt[j].bounds();
    }
    double best2 = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < a.size(); ++i) {
        const Aabb<T, 3> ba = a[i].bounds();
        for (std::size_t j = 0; j < b.size(); ++j) {
            double gap2 = 0;  // in double: float squares overflow for far-apart models
            for (int k = 0; k < 3; ++k) {
                const double g = std::max({0.0, double(ba.min[k]) - double(bb[j].max[k]),
                                           double(bb[j].min[k]) - double(ba.max[k])});
                gap2 += g * g;
            }
            if (gap2 >= best2) continue;
            best2 = std::min(best2, triangle_distance(a[i], bt[j]).distance_squared);
        }
    }
    return T(std::sqrt(best2));
}

/// A soup of `count` random triangles in the unit cube, sizes up to `size`.
template <class T>
BasicTriangleMesh<T> random_soup(std::size_t count, double size, std::uint64_t seed) {
    SplitMix64 rng(seed);
    BasicTriangleMesh<T> m;
    for (std::size_t i = 0; i < count; ++i) {
        const Vec3d c{rng.uniform(), rng.uniform(), rng.uniform()};
        const double s = size * (0.1 + 0.9 * rng.uniform());
        for (int k = 0; k < 3; ++k) m.vertices.push_back(Vec<T, 3>(c + rng.unit_vector() * s));
        const auto v = std::uint32_t(3 * i);
        m.triangles.push_back({v, v + 1, v + 2});
    }
    return m;
}

template <class U, class T>
BasicTriangleMesh<U> converted(const BasicTriangleMesh<T>& m) {
    BasicTriangleMesh<U> out;
    for (const auto& v : m.vertices) out.vertices.push_back(Vec<U, 3>(v));
    out.triangles = m.triangles;
    return out;
}

}  // namespace bvhkit::test
