#pragma once
// Inside/outside of a closed surface by signed ray crossings. For a closed, oriented triangle
// surface (every edge, after welding corners at equal positions, used as often in one direction
// as in the other) the winding number at a point p is an integer: the number of times a ray from
// p leaves through a face's front side minus the number of times it enters through it (the
// degree of the map from the surface to the sphere of directions; see Jacobson, Kavan and
// Sorkine-Hornung 2013, "Robust inside-outside segmentation using generalized winding numbers").
// So one ray's hits decide what the generalized winding number decides, at the cost of one ray.
//
// Exact where the ray test is watertight: its edge functions have exact signs and a shared edge
// gets the same ones, negated, from its two triangles, so every crossing of the surface (as the
// test rounds its corners) is reported by exactly one triangle, unless the ray meets an edge or a
// vertex exactly, where both are reported. Such a hit (a barycentric coordinate of zero, within
// rounding), a hit that grazes its triangle's plane (the side it crosses from is not certain) and
// a hit at the ray's origin (p on the surface) make the answer ambiguous: the caller falls back to
// the winding number's own evaluation there.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "bvhkit/math/ray.hpp"
#include "bvhkit/math/vec.hpp"
#include "bvhkit/primitives/hit.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit {

/// The direction of the crossing rays: generic (no two components equal, none zero), so that
/// rays from the points of a grid do not run along the axis-aligned edges and faces of
/// architecture and CAD models, where every hit would be ambiguous.
template <class T>
inline Vec<T, 3> crossing_direction() {
    const double x = 0.5773502691896258, y = 0.6123724356957945, z = 0.5400617248673217;
    const double n = std::sqrt(x * x + y * y + z * z);
    return {T(x / n), T(y / n), T(z / n)};
}

/// Whether the triangles form a closed oriented surface: after welding corners at equal positions
/// (`weld`: a welded id per vertex, see weld_vertices), every edge is used by as many triangles
/// in one direction as in the other. Triangles listed in `left_out` (ascending) do not count.
/// Edges of a triangle with two equal welded corners cancel in pairs, as they should.
template <class M>
bool is_closed_surface(const M& mesh, const std::vector<std::uint32_t>& weld,
                       const std::vector<std::uint32_t>& left_out = {}) {
    // (edge key, +1 or -1 for its direction); sorted, each key's sum must be 0.
    std::vector<std::pair<std::uint64_t, int>> edges;
    edges.reserve(3 * mesh.triangle_count());
    std::size_t next_left_out = 0;
    for (std::uint32_t i = 0; i < mesh.triangle_count(); ++i) {
        if (next_left_out < left_out.size() && left_out[next_left_out] == i) {
            ++next_left_out;
            continue;
        }
        const auto& t = mesh.triangle(i);
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = weld[t[k]], b = weld[t[(k + 1) % 3]];
            if (a == b) continue;
            const std::uint64_t key = (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
            edges.emplace_back(key, a < b ? 1 : -1);
        }
    }
    std::sort(edges.begin(), edges.end());
    for (std::size_t b = 0; b < edges.size();) {
        int sum = 0;
        std::size_t e = b;
        for (; e < edges.size() && edges[e].first == edges[b].first; ++e) sum += edges[e].second;
        if (sum != 0) return false;
        b = e;
    }
    return true;
}

/// The winding number at p of a closed oriented surface traced by `rays` (an object with
/// all_hits(ray, on_hit), whose ray test is watertight and whose hits carry the geometric
/// normal), or nothing where one ray's hits cannot decide it (see above). p with a NaN or infinite
/// coordinate gives nothing too.
template <class T, class Rays>
std::optional<int> crossing_winding_number(const Rays& rays, const Vec<T, 3>& p) {
    if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) return std::nullopt;
    const Vec<T, 3> d = crossing_direction<T>();
    const Ray<T, 3> ray(p, d, T(0), std::numeric_limits<T>::infinity());
    // Barycentrics within a few roundings of 0 may be an exact edge or vertex hit: u and v are
    // exactly 0 there, 1 - u - v only within the roundings of u and v.
    const T edge = T(16) * std::numeric_limits<T>::epsilon();
    // No occlusion query first for the rays that meet nothing: on the wide layout an all-hits
    // walk that finds nothing visits what the occlusion walk would, and a ray that meets the
    // surface would be walked twice.
    int winding = 0;
    bool decided = true;
    rays.all_hits(ray, [&](const Hit<T>& h) {
        const T w0 = T(1) - h.u - h.v;
        // The side crossed from: the sign of d . n, trusted where the angle to the plane is well
        // above the rounding of n (|d| = 1).
        const double s = double(d[0]) * double(h.normal[0]) + double(d[1]) * double(h.normal[1]) +
                         double(d[2]) * double(h.normal[2]);
        const double n = std::sqrt(double(h.normal[0]) * double(h.normal[0]) +
                                   double(h.normal[1]) * double(h.normal[1]) +
                                   double(h.normal[2]) * double(h.normal[2]));
        if (!(h.t > T(0)) || h.u <= edge || h.v <= edge || w0 <= edge ||
            !(std::abs(s) > 1e-4 * n)) {
            decided = false;
            return false;
        }
        winding += s > 0 ? 1 : -1;
        return true;
    });
    if (!decided) return std::nullopt;
    return winding;
}

}  // namespace bvhkit
