#pragma once
// The closest hit of a ray among a BSP's polygons: front-to-back along the ray. At a node the
// segment [t0, t1] is cut into the parts on each side of the thick splitter plane; the side holding
// the ray's start is visited first, and the far side is skipped once a hit lies before the point
// where the ray enters it (polygons there lie wholly on that side of the thick plane). The walk is
// walk_depth_first (walk/walks.hpp) over nodes that carry their part of the segment.
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>

#include "bvhkit/bsp/bsp_tree.hpp"
#include "bvhkit/bsp/stack.hpp"
#include "bvhkit/math/ray.hpp"
#include "bvhkit/primitives/hit.hpp"
#include "bvhkit/walk/walks.hpp"

namespace bvhkit {

template <class T>
struct BspHit {
    T t = std::numeric_limits<T>::infinity();
    std::uint32_t polygon = invalid_index;  // index among the tree's stored polygons
    std::uint32_t source = invalid_index;   // the input triangle (or polygon) it is part of
    constexpr explicit operator bool() const { return polygon != invalid_index; }
};

/// Work counters of one or more ray queries.
struct BspRayStats {
    std::size_t nodes_visited = 0;
    std::size_t polygons_tested = 0;
};

/// Where the ray meets the convex polygon `v` lying in `plane`, if at t in [tmin, tmax). Edges are
/// tested by the sign of dir . ((a - o) x (b - o)), with a tolerance of a few roundings scaled by
/// the operands: the parts of a split share end points but may meet a neighbour's unsplit edge at
/// a T-junction, and the tolerance keeps rays from slipping through such seams. The products are
/// taken in double for a float tree: float's tolerance, scaled by the distances from the origin,
/// would accept rays that graze the polygon's plane far from it.
template <class T>
bool intersect_polygon(const Ray<T, 3>& ray, std::span<const Vec<T, 3>> v, const Plane<T>& plane,
                       T tmax, T& t_out) {
    using W = std::conditional_t<(sizeof(T) < sizeof(double)), double, T>;
    const T dn = dot(plane.normal, ray.direction);
    if (dn == T(0)) return false;
    const T t = (plane.offset - dot(plane.normal, ray.origin)) / dn;
    if (!(t >= ray.tmin && t < tmax)) return false;
    constexpr W tol = 64 * std::numeric_limits<W>::epsilon();
    const Vec<W, 3> d(ray.direction), o(ray.origin);
    const W dsize = std::abs(d[0]) + std::abs(d[1]) + std::abs(d[2]);
    bool neg = false, pos = false;
    Vec<W, 3> a = Vec<W, 3>(v[v.size() - 1]) - o;
    W asize = std::abs(a[0]) + std::abs(a[1]) + std::abs(a[2]);
    for (std::size_t k = 0; k < v.size(); ++k) {
        const Vec<W, 3> b = Vec<W, 3>(v[k]) - o;
        const W bsize = std::abs(b[0]) + std::abs(b[1]) + std::abs(b[2]);
        const W e = dot(d, cross(a, b));
        const W margin = tol * dsize * asize * bsize;
        pos = pos || e > margin;
        neg = neg || e < -margin;
        if (pos && neg) return false;
        a = b;
        asize = bsize;
    }
    t_out = t;
    return true;
}

/// Where the ray meets the 2D segment `v` lying on line `plane`, if at t in [tmin, tmax): the
/// crossing's position along the segment with a tolerance of a few roundings of the segment's
/// length (for the same reason as above).
template <class T>
bool intersect_polygon(const Ray<T, 2>& ray, std::span<const Vec<T, 2>> v, const Plane<T, 2>& plane,
                       T tmax, T& t_out) {
    const T dn = dot(plane.normal, ray.direction);
    if (dn == T(0)) return false;
    const T t = (plane.offset - dot(plane.normal, ray.origin)) / dn;
    if (!(t >= ray.tmin && t < tmax)) return false;
    const Vec<T, 2> e = v[1] - v[0];
    const T len2 = dot(e, e);
    const T s = dot(ray.at(t) - v[0], e);
    const T tol = 64 * std::numeric_limits<T>::epsilon() *
                  (len2 + std::sqrt(len2) * length(ray.at(t) - v[0]));
    if (!(s >= -tol && s <= len2 + tol)) return false;
    t_out = t;
    return true;
}

namespace bsp_detail {

/// A node of the ray walk and the part [t0, t1] of the segment in its cell.
template <class T>
struct RayRef {
    std::uint32_t node;
    T t0, t1;
};

}  // namespace bsp_detail

/// The closest polygon the ray meets in [ray.tmin, ray.tmax]; a miss for a ray that is not
/// traceable (math/ray.hpp). Ties go to the polygon found first.
template <class T, std::size_t N>
BspHit<T> closest_hit(const BspTree<T, N>& tree, const Ray<T, N>& ray,
                      BspRayStats* stats = nullptr) {
    BspHit<T> best;
    if (!is_traceable(ray)) return best;
    const auto& nodes = tree.nodes();
    const auto& pool = tree.polygons();
    // Twice the build's thickness: the traversal's distances round differently from the build's.
    const T eps = T(2) * tree.epsilon();
    std::size_t visited = 0, tested = 0;
    // tmax is inclusive in the caller's ray: test up to just past it, then drop a hit beyond.
    const T limit = std::nextafter(ray.tmax, std::numeric_limits<T>::infinity());
    T best_t = limit;
    auto test_range = [&](std::uint32_t first, std::uint32_t count) {
        for (std::uint32_t i = first; i < first + count; ++i) {
            ++tested;
            T t;
            if (intersect_polygon(ray, pool.vertices_of(i), pool.plane_of(i), best_t, t)) {
                best_t = t;
                best.t = t;
                best.polygon = i;
                best.source = pool.polygons[i].source;
            }
        }
    };
    using Ref = bsp_detail::RayRef<T>;
    // A part that starts beyond the closest hit so far holds nothing nearer.
    const auto enter = [&](const Ref& r) {
        if (r.t0 > best_t) return false;
        ++visited;
        return true;
    };
    const auto on_leaf = [&](const Ref& r) {
        test_range(nodes[r.node].first, nodes[r.node].count);
        return true;
    };
    const auto open = [&](Ref& r, bsp_detail::BspTraversalStack<Ref>& stack) -> bool {
        const BspNode<T, N>& n = nodes[r.node];
        const T d0 = n.plane.distance(ray.origin);
        const T dn = dot(n.plane.normal, ray.direction);
        // The parts of [t0, t1] where the ray is in front (d >= -eps) and behind (d <= eps).
        T f0 = r.t0, f1 = r.t1, b0 = r.t0, b1 = r.t1;
        if (dn == T(0)) {
            if (d0 < -eps) f1 = -std::numeric_limits<T>::infinity();
            if (d0 > eps) b1 = -std::numeric_limits<T>::infinity();
        } else {
            const T at_minus = (-eps - d0) / dn, at_plus = (eps - d0) / dn;
            if (dn > T(0)) {
                f0 = std::max(f0, at_minus);
                b1 = std::min(b1, at_plus);
            } else {
                f1 = std::min(f1, at_minus);
                b0 = std::max(b0, at_plus);
            }
        }
        const bool front_ok = f0 <= f1, back_ok = b0 <= b1;
        // The node's polygons lie where both parts meet (the slab |d| <= eps).
        if (n.count && front_ok && back_ok && std::max(f0, b0) <= std::min(f1, b1))
            test_range(n.first, n.count);
        // The side the segment is in first is gone on with (the one the ray leaves on ties).
        const bool front_first = f0 < b0 || (f0 == b0 && dn < T(0));
        const Ref front{n.front, f0, f1}, back{n.back, b0, b1};
        const bool first_ok = front_first ? front_ok : back_ok;
        const bool second_ok = front_first ? back_ok : front_ok;
        if (first_ok) {
            if (second_ok) stack.push(front_first ? back : front);
            r = front_first ? front : back;
            return true;
        }
        if (!second_ok) return false;
        r = front_first ? back : front;
        return true;
    };
    bsp_detail::BspTraversalStack<Ref> stack(tree.statistics().depth + 2);
    walk_depth_first(CarryingNodes<BspNode<T, N>, Ref>{nodes.data(), {0, ray.tmin, ray.tmax}},
                     stack, enter, on_leaf, open);
    if (stats) {
        stats->nodes_visited += visited;
        stats->polygons_tested += tested;
    }
    if (best && best.t > ray.tmax) best = {};
    return best;
}

}  // namespace bvhkit
