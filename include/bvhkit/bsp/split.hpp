#pragma once
// Classifying a convex polygon against a thick plane and splitting it there.
//
// Classification uses the thick plane (plane.hpp): a polygon is Front when no vertex is more than
// epsilon behind and one is more than epsilon in front, Back likewise, Coplanar when every vertex
// is within epsilon, and Spanning when one vertex is beyond epsilon on each side. Only a Spanning
// polygon is split, along a chord between two boundary points: an edge's crossing where it runs
// from beyond epsilon on one side to beyond epsilon on the other, or a vertex within epsilon of the
// plane (which then needs no new vertex beside it). The two parts share the chord's end points bit
// for bit and so tile the polygon exactly, up to the rounding of a crossing point.
#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "bvhkit/bsp/plane.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

/// Counts of a polygon's vertices against a thick plane.
template <class T, std::size_t N>
Side classify_polygon(std::span<const Vec<T, N>> v, const Plane<T, N>& plane, T epsilon) {
    bool front = false, back = false;
    for (const auto& p : v) {
        const T d = plane.distance(p);
        front = front || d > epsilon;
        back = back || d < -epsilon;
    }
    if (front && back) return Side::Spanning;
    if (front) return Side::Front;
    if (back) return Side::Back;
    return Side::Coplanar;
}

/// Splits a spanning convex polygon `v` by `plane` into `front` and `back` (both cleared first),
/// each convex and in the same vertex order (a 2D segment into two segments, the same way round).
/// Called only for Spanning polygons, so both parts have at least three vertices (two for a
/// segment).
template <class T, std::size_t N>
void split_polygon(std::span<const Vec<T, N>> v, const Plane<T, N>& plane, T epsilon,
                   std::vector<Vec<T, N>>& front, std::vector<Vec<T, N>>& back) {
    front.clear();
    back.clear();
    const std::size_t n = v.size();
    if (n == 2) {
        // A segment (2D): the crossing, interpolated from the lexicographically smaller end.
        const T da = plane.distance(v[0]), db = plane.distance(v[1]);
        const bool a_first = std::lexicographical_compare(v[0].v, v[0].v + N, v[1].v, v[1].v + N);
        const Vec<T, N>& p = a_first ? v[0] : v[1];
        const Vec<T, N>& q = a_first ? v[1] : v[0];
        const T dp = a_first ? da : db, dq = a_first ? db : da;
        const Vec<T, N> x = p + (q - p) * (dp / (dp - dq));
        const bool a_front = da > T(0);
        front = {a_front ? v[0] : x, a_front ? x : v[1]};
        back = {a_front ? x : v[0], a_front ? v[1] : x};
        return;
    }
    // Each vertex goes to the front part (+1), the back part (-1) or both (0, a cut point).
    constexpr std::size_t max_inline = tuning::bsp_split_inline;
    T dist_inline[max_inline];
    signed char tag_inline[max_inline];
    std::vector<T> dist_heap;
    std::vector<signed char> tag_heap;
    T* dist = dist_inline;
    signed char* tag = tag_inline;
    if (n > max_inline) {
        dist_heap.resize(n);
        tag_heap.resize(n);
        dist = dist_heap.data();
        tag = tag_heap.data();
    }
    std::size_t start = n;
    for (std::size_t k = 0; k < n; ++k) {
        dist[k] = plane.distance(v[k]);
        tag[k] = dist[k] > epsilon ? 1 : (dist[k] < -epsilon ? -1 : 2);  // 2: on, to settle
        if (tag[k] != 2 && start == n) start = k;
    }
    // A run of vertices on the thick plane between the two sides holds the chord's end: its
    // vertex nearest the plane goes to both parts, those before it to the side before, those after
    // to the side after. Cutting at one point per run keeps the parts from overlapping.
    for (std::size_t j = 1; j < n; ++j) {
        const std::size_t k = (start + j) % n;
        if (tag[k] != 2) continue;
        std::size_t len = 0;
        while (tag[(k + len) % n] == 2) ++len;
        const signed char before = tag[(k + n - 1) % n], after = tag[(k + len) % n];
        std::size_t cut = 0;
        for (std::size_t r = 1; r < len; ++r)
            if (std::abs(dist[(k + r) % n]) < std::abs(dist[(k + cut) % n])) cut = r;
        for (std::size_t r = 0; r < len; ++r)
            tag[(k + r) % n] =
                before == after ? before : (r < cut ? before : (r == cut ? 0 : after));
        j += len - 1;
    }
    for (std::size_t k = 0; k < n; ++k) {
        const std::size_t k1 = (k + 1) % n;
        if (tag[k] >= 0) front.push_back(v[k]);
        if (tag[k] <= 0) back.push_back(v[k]);
        if (tag[k] * tag[k1] == -1) {
            // The edge crosses from one side to the other, the crossing interpolated from the
            // lexicographically smaller end: the same point whichever way the edge is walked, so
            // a neighbour split by the same plane gets the identical vertex.
            const Vec<T, N>& a = v[k];
            const Vec<T, N>& b = v[k1];
            const bool a_first = std::lexicographical_compare(a.v, a.v + N, b.v, b.v + N);
            const Vec<T, N>& p = a_first ? a : b;
            const Vec<T, N>& q = a_first ? b : a;
            const T dp = a_first ? dist[k] : dist[k1], dq = a_first ? dist[k1] : dist[k];
            const Vec<T, N> x = p + (q - p) * (dp / (dp - dq));
            front.push_back(x);
            back.push_back(x);
        }
    }
}

}  // namespace bvhkit
