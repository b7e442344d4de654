#pragma once
// convex_distance: the distance between two posed convex shapes and their closest points, by GJK
// (Gilbert, Johnson and Keerthi 1988) on the Minkowski difference D = A - B, with the simplex step
// of volumes/gjk.hpp. GJK runs on the shapes' cores (a sphere's centre, a capsule's segment) and
// the margins are subtracted afterwards, so sphere and capsule answers are exact to rounding (van
// den Bergen, Collision Detection in Interactive 3D Environments, 2003).
//
// Frames: the poses place each shape in the world. The work is done in a frame with A's position at
// the origin (world orientation), so two shapes far from the world origin (1e6) but near each other
// lose nothing to the size of their coordinates; the points returned are in the world frame. That
// frame is also scaled by a power of two (exact) that brings the pair's size near 1: GJK's and
// EPA's determinants multiply up to four coordinates, which at 1e-80 or 1e80 would underflow or
// overflow a double (at 1e-10 or 1e10 a float), and the answers are scaled back at the end.
//
// Termination: with v the simplex's nearest point and w the new support point, |v| bounds the core
// distance from above and v.w / |v| from below; GJK stops when the gap |v|^2 - v.w is within a
// relative tolerance (gjk_relative_tolerance) plus an absolute one scaled by the shapes' size, when
// w is already in the simplex, when |v| stops shrinking (rounding), or after gjk_max_iterations.
// Each of these leaves an answer: nothing loops for ever on degenerate input.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "bvhkit/convex/convex_shape.hpp"
#include "bvhkit/math/transform.hpp"
#include "bvhkit/primitives/closest_point.hpp"
#include "bvhkit/volumes/gjk.hpp"

namespace bvhkit {

/// The answer of convex_distance (world frame).
template <class T>
struct ConvexDistance {
    /// The distance between the shapes; 0 when they meet (touching counts as meeting).
    T distance = 0;
    /// Apart: the closest points, on A and on B (point_b - point_a = distance * normal). Meeting:
    /// both are one point of the intersection (to rounding).
    Vec<T, 3> point_a{}, point_b{};
    /// Apart: the unit direction from A to B. Meeting: zero (convex_signed_distance gives one).
    Vec<T, 3> normal{};
    bool overlap = false;
    int iterations = 0;  // GJK steps
};

namespace convex_detail {

inline constexpr int gjk_max_iterations = 128;

/// The relative gap at which GJK stops: near the precision of T, with room for rounding.
template <class T>
constexpr T gjk_relative_tolerance() {
    return sizeof(T) > sizeof(float) ? T(1e-11) : T(1e-6);
}

/// One shape under its pose, in the working frame (A's position at the origin).
template <class T>
struct PosedSupport {
    const ConvexShape<T>* shape;
    Mat3<T> rotation;
    Vec<T, 3> offset;
    bool core;
    // The last support vertex of a hull, where the next query's climb starts: GJK's and EPA's
    // successive directions are close, so their support vertices are near each other. One query
    // owns its pair, so the hint is never shared between threads.
    mutable std::uint32_t hint = HullSupport<T>::none;

    T factor;  // the working frame's scale (a power of two); offset is already scaled

    Vec<T, 3> operator()(const Vec<T, 3>& d) const {
        const Vec<T, 3> local = rotation.transpose_times(d);
        return rotation * ((core ? shape->core_support(local, hint) : shape->support(local, hint)) *
                           factor) +
               offset;
    }
};

/// A pair of posed shapes: the support mapping of D = A - B and the absolute tolerance.
template <class T>
struct ShapePair {
    PosedSupport<T> a, b;
    Vec<T, 3> origin;  // A's position in the world: working frame * unscale + origin = world
    T abs_tolerance;   // distances below this are rounding of the shapes' coordinates
    T unscale;         // 1 / the working frame's factor

    /// A point of the working frame in the world.
    Vec<T, 3> world(const Vec<T, 3>& x) const { return x * unscale + origin; }

    using Scalar = T;

    /// The support point w = a - b of D along d, and the point a of A behind it.
    std::pair<Vec<T, 3>, Vec<T, 3>> support(const Vec<T, 3>& d) const {
        const Vec<T, 3> pa = a(d);
        return {pa - b(-d), pa};
    }
    /// GJK's first direction: from A's position to B's.
    Vec<T, 3> initial_direction() const { return b.offset; }
};

/// The shapes' size: the larger bounding radius. A radius computed from squares underflows for
/// shapes below about the square root of T's smallest normal number and overflows above the root
/// of its largest; there the shapes' own extents along the axes (six supports each) stand in.
template <class T>
T shapes_size(const ConvexShape<T>& a, const ConvexShape<T>& b) {
    T size = std::max(a.bounding_radius(), b.bounding_radius());
    const T low = std::sqrt(std::numeric_limits<T>::min()) * T(1024);
    const T high = std::sqrt(std::numeric_limits<T>::max()) / T(1024);
    if (size >= low && size <= high) return size;
    size = T(0);
    for (const ConvexShape<T>* s : {&a, &b})
        for (std::size_t i = 0; i < 3; ++i)
            for (const T sign : {T(1), T(-1)}) {
                Vec<T, 3> d{};
                d[i] = sign;
                const Vec<T, 3> p = s->support(d);
                size = std::max({size, std::fabs(p[0]), std::fabs(p[1]), std::fabs(p[2])});
            }
    return size;
}

/// The power of two 2^e that brings `scale` near [1, 2): e = ilogb(scale), kept where both 2^e and
/// 2^-e are normal numbers of T (a subnormal scale, or an offset beyond T's range measured in the
/// wider type, would otherwise make one of them 0 or infinite). 0 for a zero or non-finite scale.
template <class T, class W>
int unit_exponent(W scale) {
    if (!(scale > W(0)) || !std::isfinite(scale)) return 0;
    return std::clamp(int(std::ilogb(scale)), std::numeric_limits<T>::min_exponent,
                      std::numeric_limits<T>::max_exponent - 2);
}

template <class T>
ShapePair<T> make_shape_pair(const ConvexShape<T>& a, const Transform<T>& pose_a,
                             const ConvexShape<T>& b, const Transform<T>& pose_b, bool core,
                             const char* where) {
    check_rigid_pose(pose_a, where, "pose_a");
    check_rigid_pose(pose_b, where, "pose_b");
    // B's position from A's in the wider type, where two finite translations' difference is
    // finite (as a T it could overflow: poses at -1e308 and 1e308); scaled, then narrowed.
    using W = AccurateScalar<T>;
    Vec<W, 3> offset;
    W scale = W(shapes_size(a, b));
    for (std::size_t i = 0; i < 3; ++i) {
        offset[i] = W(pose_b.translation[i]) - W(pose_a.translation[i]);
        scale = std::max(scale, W(std::fabs(offset[i])));
    }
    const int e = unit_exponent<T>(scale);
    const T factor = std::ldexp(T(1), -e), unscale = std::ldexp(T(1), e);
    Vec<T, 3> scaled_offset;
    for (std::size_t i = 0; i < 3; ++i) scaled_offset[i] = T(offset[i] * W(factor));
    constexpr std::uint32_t none = HullSupport<T>::none;
    return {{&a, pose_a.rotation, Vec<T, 3>{}, core, none, factor},
            {&b, pose_b.rotation, scaled_offset, core, none, factor},
            pose_a.translation,
            T(W(64) * W(std::numeric_limits<T>::epsilon()) * scale * W(factor)),
            unscale};
}

template <class T>
struct GjkRun {
    GjkSimplex<T> simplex;
    Vec<T, 3> v{};         // the simplex's point nearest the origin (its weights give witnesses)
    bool overlap = false;  // the origin is in D, or within the absolute tolerance of it
    int iterations = 0;
};

/// GJK on a pair with support(d) -> {w, a} (w a point of D = A - B, a the point of A behind it),
/// initial_direction() and abs_tolerance: ShapePair, or a shape against a triangle
/// (query/convex_mesh.hpp).
template <class Pair, class T = typename Pair::Scalar>
GjkRun<T> run_gjk(const Pair& p) {
    GjkRun<T> r;
    Vec<T, 3> dir = p.initial_direction();
    if (!(length_squared(dir) > T(0))) dir = {T(1), T(0), T(0)};
    const auto [w0, a0] = p.support(dir);
    r.simplex.add(w0, a0);
    bool single_point_inside = false;  // never set for one point; nearest() sets its weight
    Vec<T, 3> v = r.simplex.nearest(single_point_inside);
    const T rel = gjk_relative_tolerance<T>(), tol = p.abs_tolerance;
    // Whether some support value has proved the origin outside D: v.w > 0 for w = the support
    // along -v puts all of D on the far side of a plane through the origin.
    bool separated = false;
    for (; r.iterations < gjk_max_iterations; ++r.iterations) {
        const T v2 = length_squared(v);
        if (v2 <= tol * tol) {
            r.overlap = true;
            break;
        }
        const auto [w, a] = p.support(-v);
        const T vw = dot(v, w);
        const T gap = v2 - vw;  // |v| (|v| - lower bound)
        separated |= vw > tol * std::sqrt(v2);
        if (gap <= rel * v2 + tol * std::sqrt(v2) || r.simplex.holds(w)) break;
        const GjkSimplex<T> before = r.simplex;
        r.simplex.add(w, a);
        bool inside = false;
        const Vec<T, 3> next = r.simplex.nearest(inside);
        if (inside) {
            ++r.iterations;
            // A nearly flat tetrahedron (points of a flat face of D) can hold the origin by
            // rounding alone; a proof of separation overrules it and keeps the last simplex.
            if (separated) {
                r.simplex = before;
                break;
            }
            r.overlap = true;
            break;
        }
        if (!(length_squared(next) < v2)) {  // no progress: rounding; keep the better simplex
            r.simplex = before;
            break;
        }
        v = next;
    }
    r.v = v;
    return r;
}

/// The point of A that the simplex's weights give; for a full tetrahedron holding the origin
/// (whose weights GjkSimplex leaves unset) the origin's barycentric coordinates are used.
template <class T>
Vec<T, 3> simplex_witness_a(const GjkSimplex<T>& s) {
    if (s.size() < 4) return s.witness_a();
    const Vec<T, 3> w0 = s.point(0), e1 = s.point(1) - w0, e2 = s.point(2) - w0,
                    e3 = s.point(3) - w0;
    const T volume = dot(e1, cross(e2, e3));
    T l[4] = {T(0.25), T(0.25), T(0.25), T(0.25)};
    if (volume != T(0) && std::isfinite(volume)) {
        l[1] = dot(-w0, cross(e2, e3)) / volume;
        l[2] = dot(e1, cross(-w0, e3)) / volume;
        l[3] = dot(e1, cross(e2, -w0)) / volume;
        l[0] = T(1) - l[1] - l[2] - l[3];
    }
    Vec<T, 3> a{};
    for (std::size_t i = 0; i < 4; ++i) a += s.point_a(i) * l[i];
    return a;
}

}  // namespace convex_detail

/// The distance between shape `a` at `pose_a` and shape `b` at `pose_b` (rigid poses, world
/// frame), with the closest points and the direction from A to B. Throws Error for a pose that is
/// not finite or not rigid (check_rigid_pose).
template <class T>
ConvexDistance<T> convex_distance(const ConvexShape<T>& a, const Transform<T>& pose_a,
                                  const ConvexShape<T>& b, const Transform<T>& pose_b) {
    const convex_detail::ShapePair<T> pair =
        convex_detail::make_shape_pair(a, pose_a, b, pose_b, true, "convex_distance");
    const convex_detail::GjkRun<T> g = convex_detail::run_gjk(pair);
    ConvexDistance<T> r;
    r.iterations = g.iterations;
    if (g.overlap) {
        r.overlap = true;
        r.point_a = r.point_b = pair.world(convex_detail::simplex_witness_a(g.simplex));
        return r;
    }
    // Back in world units (the working frame's factor undone) before the margins enter.
    const T ma = a.margin(), mb = b.margin();
    const T v_length = length(g.v);
    const T core_distance = v_length * pair.unscale;
    const Vec<T, 3> n = g.v * (T(-1) / v_length);
    const Vec<T, 3> core_a = g.simplex.witness_a() * pair.unscale;
    const Vec<T, 3> core_b = core_a + n * core_distance;
    const T distance = core_distance - ma - mb;
    if (distance > T(0)) {
        r.distance = distance;
        r.normal = n;
        r.point_a = core_a + n * ma + pair.origin;
        r.point_b = core_b - n * mb + pair.origin;
        return r;
    }
    // The margins meet: along the cores' closest segment A holds [0, ma] and B holds
    // [core_distance - mb, core_distance] (distances from core_a); their common part's middle.
    r.overlap = true;
    const T from = std::max(T(0), core_distance - mb), to = std::min(ma, core_distance);
    r.point_a = r.point_b = core_a + n * ((from + to) / T(2)) + pair.origin;
    return r;
}

}  // namespace bvhkit
