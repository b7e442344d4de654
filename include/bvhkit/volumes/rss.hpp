#pragma once
// Rss<T>: a rectangle swept by a sphere (Larsen, Gottschalk, Lin, Manocha 1999, "Fast proximity
// queries with swept sphere volumes"): the points within `radius` of the rectangle centred at
// `center`, spanned by axes[0] and axes[1] with half lengths `half[0]`, `half[1]`; axes[2] is its
// normal. Fitted in the covariance frame of the OBB (obb.hpp), the normal along the thinnest
// extent. Its point: the distance lower bound is exact for the volume, the distance between the
// two rectangles minus both radii, so whole subtrees are cut that a box's axis gaps keep.
//
// Overlap under a pose is conservative: the volumes' enclosing boxes (half extents
// half + radius, half + radius, radius) meet by the 15-axis test. Exact would be "rectangle
// distance <= ra + rb", several times the cost, and collision queries prefer Obb anyway.
#include <algorithm>

#include "bvhkit/math/select.hpp"
#include "bvhkit/math/wide_length.hpp"
#include "bvhkit/volumes/obb.hpp"

namespace bvhkit {

template <class T>
struct Rss {
    using Scalar = T;
    Vec<T, 3> center{};
    Mat3<T> axes{};  // rows: two rectangle axes, then the normal (unit, orthogonal)
    T half[2] = {0, 0};
    T radius = -1;  // negative: empty
};

namespace detail {

/// Squared distance from the segment p + s d (s in [0, 1]) to the rectangle [-h0, h0] x [-h1, h1]
/// in the plane z = 0. The squared distance along the segment is convex, piecewise quadratic and
/// continuously differentiable, its pieces split where x or y leaves the rectangle's range; the
/// minimum lies on the first piece whose end has a non-negative slope, found by walking the (at
/// most four) breakpoints in order.
template <class T>
T segment_rectangle_distance_squared(const Vec<T, 3>& p, const Vec<T, 3>& d, T h0, T h1) {
    // How far x lies outside [-h, h] (signed); branch free, as the side is unpredictable.
    const auto excess = [](T x, T h) { return x - min_of(max_of(x, -h), h); };
    const auto value = [&](T s) {
        const T ex = excess(p[0] + s * d[0], h0), ey = excess(p[1] + s * d[1], h1);
        const T z = p[2] + s * d[2];
        return ex * ex + ey * ey + z * z;
    };
    const auto slope = [&](T s) {  // half the derivative
        return excess(p[0] + s * d[0], h0) * d[0] + excess(p[1] + s * d[1], h1) * d[1] +
               (p[2] + s * d[2]) * d[2];
    };
    // The breakpoints, where x crosses -h0, h0 and y crosses -h1, h1, clamped to [0, 1] (both at 0
    // when the segment runs parallel; pieces of zero length do no harm), sorted without
    // branches, then the segment's end.
    const auto crossings = [](T pa, T da, T h, T& lo, T& hi) {
        const T inv = da != T(0) ? T(1) / da : T(0);
        const T a = (-h - pa) * inv, b = (h - pa) * inv;
        lo = min_of(max_of(min_of(a, b), T(0)), T(1));
        hi = min_of(max_of(max_of(a, b), T(0)), T(1));
    };
    T xl, xh, yl, yh;
    crossings(p[0], d[0], h0, xl, xh);
    crossings(p[1], d[1], h1, yl, yh);
    const T m0 = max_of(xl, yl), m1 = min_of(xh, yh);
    const T cut[5] = {min_of(xl, yl), min_of(m0, m1), max_of(m0, m1), max_of(xh, yh), T(1)};
    const int n = 5;
    T lo = 0;
    if (slope(lo) >= T(0)) return value(lo);
    for (int k = 0; k < n; ++k) {
        const T hi = cut[k];
        const T g_hi = slope(hi);
        if (g_hi >= T(0)) {
            // The slope is linear on [lo, hi]: its root.
            const T g_lo = slope(lo);
            const T s = g_hi > g_lo ? lo + (hi - lo) * (-g_lo / (g_hi - g_lo)) : lo;
            return value(clamp_of(s, lo, hi));
        }
        lo = hi;
    }
    return value(T(1));
}

/// Distance between rectangle A (half lengths ha, axis-aligned at the origin in the plane z = 0)
/// and rectangle B (centre t, axes u = columns of c, half lengths hb), B given in A's frame.
///
/// Where two convex polygons are closest, one point can be taken on the boundary of one of them
/// (both inside their faces means parallel planes, and sliding keeps the distance). A closest
/// point on B's boundary: an edge of B against the whole of A (4 segment-rectangle distances).
/// Else the point on A's boundary faces B's interior: an edge of A whose distance to B's plane
/// could still fall along it (so a corner of A over B's face), or one that crosses B's face (the
/// rectangles meet). So: B's 4 edges against A, A's 4 corners above B, A's 4 edges through B.
///
/// `limit`: the caller needs nothing beyond it; the result is min(distance, limit). A B edge is
/// measured only when a cheap lower bound could beat the best so far (per axis of A's frame,
/// the gap when both ends lie beyond one side of its range; the squares add up), and of each
/// pair of opposite edges the one facing A's centre goes first.
template <class T>
T rectangles_distance(const Mat3<T>& c, const Vec<T, 3>& t, const T ha[2], const T hb[2],
                      T limit = std::numeric_limits<T>::infinity()) {
    T best = limit * limit;
    // The gap between [x0, x1] (either order) and [-h, h], branch free.
    const auto gap = [](T x0, T x1, T h) {
        return max_of(max_of(min_of(x0, x1) - h, -h - max_of(x0, x1)), T(0));
    };
    // A's corners in B's frame (x_B = Cᵀ (x_A - t); rows of c are A's axes there), first: they
    // settle facing rectangles at once, and their edges' crossings tell whether the two meet.
    const Vec<T, 3> tb = -c.transpose_times(t);
    const Vec<T, 3> da = c[0] * ha[0], db = c[1] * ha[1];
    const Vec<T, 3> corners[4] = {tb - da - db, tb + da - db, tb + da + db, tb - da + db};
    for (int k = 0; k < 4; ++k) {
        const Vec<T, 3>& p = corners[k];
        // The corner's distance to B (its height when it lies over B's face): a distance
        // between points of the two rectangles, so an upper bound of theirs, exact when the
        // rectangles face each other.
        const T ex = p[0] - clamp_of(p[0], -hb[0], hb[0]),
                ey = p[1] - clamp_of(p[1], -hb[1], hb[1]);
        best = min_of(best, ex * ex + ey * ey + p[2] * p[2]);
        const Vec<T, 3>& q = corners[(k + 1) % 4];
        if ((p[2] > T(0)) != (q[2] > T(0)) && p[2] != q[2]) {
            const T s = p[2] / (p[2] - q[2]);  // where the edge meets B's plane
            const T x = p[0] + s * (q[0] - p[0]), y = p[1] + s * (q[1] - p[1]);
            if (std::fabs(x) <= hb[0] && std::fabs(y) <= hb[1]) return T(0);
        }
    }
    // B's edges in A's frame (columns of c are B's axes).
    const Vec<T, 3> u0{c[0][0], c[1][0], c[2][0]}, u1{c[0][1], c[1][1], c[2][1]};
    for (int side = 0; side < 2; ++side) {
        const Vec<T, 3>& along = side == 0 ? u0 : u1;
        const Vec<T, 3>& across = side == 0 ? u1 : u0;
        const T h_along = hb[side], h_across = hb[1 - side];
        const Vec<T, 3> dir = along * (T(2) * h_along);
        const Vec<T, 3> base = t - along * h_along;
        const Vec<T, 3> offset = across * h_across;
        // The edge on the side facing A's centre first (a sign, not a branch).
        const Vec<T, 3> facing = offset * std::copysign(T(1), -dot(t, across));
        for (int pass = 0; pass < 2; ++pass) {
            const Vec<T, 3> start = pass == 0 ? base + facing : base - facing;
            const Vec<T, 3> end = start + dir;
            const T gx = gap(start[0], end[0], ha[0]), gy = gap(start[1], end[1], ha[1]);
            const T gz = gap(start[2], end[2], T(0));
            if (gx * gx + gy * gy + gz * gz >= best) continue;
            best = min_of(best, segment_rectangle_distance_squared(start, dir, ha[0], ha[1]));
        }
    }
    return std::sqrt(best);
}

}  // namespace detail

template <class T>
struct VolumeTraits<Rss<T>> {
    using V = Rss<T>;
    using Prepared = PreparedPose<T>;
    static constexpr bool merge_is_tight = false;

    static V fit(std::span<const Triangle<T>> tris) {
        if (tris.empty()) return {};
        const Obb<T> box = VolumeTraits<Obb<T>>::fit(tris);
        return around(Mat3<double>(box.axes), box.extents, [&](auto&& f) {
            for (const auto& t : tris) {
                f(Vec3d(t.p0));
                f(Vec3d(t.p1));
                f(Vec3d(t.p2));
            }
        });
    }
    /// Around the corners of both volumes' enclosing boxes (loose, but refit re-fits instead).
    static V merge(const V& a, const V& b) {
        if (a.radius < 0) return b;
        if (b.radius < 0) return a;
        const V& big = size(a) >= size(b) ? a : b;
        const Vec<T, 3> e{big.half[0] + big.radius, big.half[1] + big.radius, big.radius};
        return around(Mat3<double>(big.axes), e, [&](auto&& f) {
            for (const V* v : {&a, &b})
                for (int k = 0; k < 8; ++k) {
                    Vec3d p(v->center);
                    const double ext[3] = {double(v->half[0] + v->radius),
                                           double(v->half[1] + v->radius), double(v->radius)};
                    for (int i = 0; i < 3; ++i)
                        p += Vec3d(v->axes[i]) * ((k >> i & 1) ? ext[i] : -ext[i]);
                    f(p);
                }
        });
    }
    static bool overlaps(const V& a, const V& b) {
        return overlaps(a, b, prepare(Transform<T>::identity(), T(0)));
    }
    static Prepared prepare(const Transform<T>& pose, T slack) { return {pose, slack}; }
    static bool overlaps(const V& a, const V& b, const Prepared& p) {
        Mat3<T> c, abs_c;
        Vec<T, 3> t;
        detail::frames_relative(a, b, p, c, abs_c, t);
        return !detail::boxes_separated(c, abs_c, t, box_extents(a), box_extents(b), p.slack);
    }
    static T size(const V& v) { return length_squared(box_extents(v)); }
    static T distance_lower_bound(const V& a, const V& b, const Prepared& p) {
        return distance_lower_bound(a, b, p, std::numeric_limits<T>::infinity());
    }
    /// The bound, or any value >= cutoff when the bound is (the traversal drops the pair then):
    /// three cheap gaps first (along either normal, between the circumscribed spheres), enough
    /// for pairs plainly beyond the cutoff, then the exact rectangle distance, its edges skipped
    /// once they cannot come within the cutoff.
    static T distance_lower_bound(const V& a, const V& b, const Prepared& p, T cutoff) {
        Mat3<T> c, abs_c;
        Vec<T, 3> t;
        detail::frames_relative(a, b, p, c, abs_c, t);
        return bound_from(a, b, c, abs_c, t, p.slack, cutoff);
    }
    /// b carried into A's frame once, for the several tests a traversal step makes against it
    /// (each then skips the product of a's axes with the pose's rotation).
    static V place(const V& b, const Prepared& p) { return detail::frame_placed(b, p); }
    static bool overlaps_placed(const V& a, const V& w, T slack) {
        Mat3<T> c, abs_c;
        Vec<T, 3> t;
        detail::frames_relative_placed(a, w, c, abs_c, t);
        return !detail::boxes_separated(c, abs_c, t, box_extents(a), box_extents(w), slack);
    }
    static T distance_lower_bound_placed(const V& a, const V& w, T slack, T cutoff) {
        Mat3<T> c, abs_c;
        Vec<T, 3> t;
        detail::frames_relative_placed(a, w, c, abs_c, t);
        return bound_from(a, w, c, abs_c, t, slack, cutoff);
    }

  private:
    /// b's axes as the columns of c and its centre t, both in a's frame.
    static T bound_from(const V& a, const V& b, const Mat3<T>& c, const Mat3<T>& abs_c,
                        const Vec<T, 3>& t, T slack, T cutoff) {
        const T reach = a.radius + b.radius + slack;
        const T along_a = std::fabs(t[2]) - b.half[0] * abs_c[2][0] - b.half[1] * abs_c[2][1];
        const T tb2 = c[0][2] * t[0] + c[1][2] * t[1] + c[2][2] * t[2];  // -(A's centre in B).z
        const T along_b = std::fabs(tb2) - a.half[0] * abs_c[0][2] - a.half[1] * abs_c[1][2];
        const T spheres = length(t) - std::sqrt(a.half[0] * a.half[0] + a.half[1] * a.half[1]) -
                          std::sqrt(b.half[0] * b.half[0] + b.half[1] * b.half[1]);
        const T cheap = std::max({along_a, along_b, spheres}) - reach;
        if (cheap >= cutoff) return cheap;
        // One rectangle wholly on one side of the other's plane, its corner nearest that plane
        // above the other rectangle: the normal gap is the distance (facing patches of two
        // surfaces), no edge to measure.
        if (along_a > T(0)) {
            const T s = t[2] > T(0) ? T(-1) : T(1);
            const T s0 = c[2][0] > T(0) ? s : -s, s1 = c[2][1] > T(0) ? s : -s;
            const T x = t[0] + s0 * b.half[0] * c[0][0] + s1 * b.half[1] * c[0][1];
            const T y = t[1] + s0 * b.half[0] * c[1][0] + s1 * b.half[1] * c[1][1];
            if (std::fabs(x) <= a.half[0] && std::fabs(y) <= a.half[1])
                return std::max(T(0), along_a - reach);
        }
        if (along_b > T(0)) {
            const Vec<T, 3> tb = -c.transpose_times(t);  // A's centre in B's frame
            const T s = tb[2] > T(0) ? T(-1) : T(1);
            const T s0 = c[0][2] > T(0) ? s : -s, s1 = c[1][2] > T(0) ? s : -s;
            const T x = tb[0] + s0 * a.half[0] * c[0][0] + s1 * a.half[1] * c[1][0];
            const T y = tb[1] + s0 * a.half[0] * c[0][1] + s1 * a.half[1] * c[1][1];
            if (std::fabs(x) <= b.half[0] && std::fabs(y) <= b.half[1])
                return std::max(T(0), along_b - reach);
        }
        const T d = detail::rectangles_distance(c, t, a.half, b.half, cutoff + reach) - reach;
        return std::max({T(0), d, cheap});
    }

    static Vec<T, 3> box_extents(const V& v) {
        return {v.half[0] + v.radius, v.half[1] + v.radius, v.radius};
    }
    /// The volume with the given frame around some points. `extents` (the points' half extents
    /// along the axes) picks the normal: the axis of the thinnest extent. The radius is half the
    /// thickness along it; then each rectangle side is pulled in as far as every point stays
    /// within the radius: first x with a point's whole remaining budget sqrt(r² - z²), then y
    /// with what x left it, so no point ends farther than r from the rectangle.
    ///
    /// The squares r², z² and x² overflow double for coordinates beyond about 1e154 and sink for
    /// ones below 1e-154: there the points are divided by a power of two 2^k first (exact but for
    /// coordinates far below the rest, which sink into denormals by less than the pad) and the
    /// volume's sizes multiplied back.
    template <class ForEachPoint>
    static V around(const Mat3<double>& frame, const Vec<T, 3>& extents,
                    ForEachPoint&& for_each_point) {
        int k = 0;
        if constexpr (sizeof(T) > sizeof(float)) {  // float coordinates square safely in double
            double m = 0;
            for_each_point(
                [&](const Vec3d& p) { m = std::max(m, max_component(bvhkit::max(p, -p))); });
            k = squaring_exponent(m);
        }
        if (k == 0) return around_scaled(frame, extents, for_each_point, 0);
        const double unit = std::ldexp(1.0, -k);
        return around_scaled(
            frame, extents, [&](auto&& f) { for_each_point([&](const Vec3d& p) { f(p * unit); }); },
            k);
    }
    /// around() on points divided by 2^k (k = 0: as given); the volume is multiplied back.
    template <class ForEachPoint>
    static V around_scaled(const Mat3<double>& frame, const Vec<T, 3>& extents,
                           ForEachPoint&& for_each_point, int k) {
        int normal = 0;
        for (int i = 1; i < 3; ++i)
            if (extents[i] < extents[normal]) normal = i;
        const int i0 = (normal + 1) % 3, i1 = (normal + 2) % 3;
        Mat3<double> axes;
        axes[0] = frame[i0];
        axes[1] = frame[i1];
        axes[2] = cross(axes[0], axes[1]);
        constexpr double inf = std::numeric_limits<double>::infinity();
        double zlo = inf, zhi = -inf, scale = 0;
        for_each_point([&](const Vec3d& p) {
            const double z = dot(axes[2], p);
            zlo = std::min(zlo, z);
            zhi = std::max(zhi, z);
            scale = std::max(scale, max_component(bvhkit::max(p, -p)));
        });
        V v;
        if (!(zlo <= zhi)) return v;
        const double zmid = (zlo + zhi) * 0.5, r = (zhi - zlo) * 0.5;
        const double r2 = r * r;
        // x side: lo = min(x + budget), hi = max(x - budget).
        double xlo = inf, xhi = -inf;
        for_each_point([&](const Vec3d& p) {
            const double z = dot(axes[2], p) - zmid;
            const double budget = std::sqrt(std::max(0.0, r2 - z * z));
            const double x = dot(axes[0], p);
            xlo = std::min(xlo, x + budget);
            xhi = std::max(xhi, x - budget);
        });
        if (xlo > xhi) xlo = xhi = (xlo + xhi) * 0.5;  // every point reaches the middle
        double ylo = inf, yhi = -inf;
        for_each_point([&](const Vec3d& p) {
            const double z = dot(axes[2], p) - zmid;
            const double x = dot(axes[0], p);
            const double ex = x > xhi ? x - xhi : (x < xlo ? xlo - x : 0.0);
            const double budget = std::sqrt(std::max(0.0, r2 - z * z - ex * ex));
            const double y = dot(axes[1], p);
            ylo = std::min(ylo, y + budget);
            yhi = std::max(yhi, y - budget);
        });
        if (ylo > yhi) ylo = yhi = (ylo + yhi) * 0.5;
        const Vec3d mid{(xlo + xhi) * 0.5, (ylo + yhi) * 0.5, zmid};
        const Vec3d c = axes.transpose_times(mid);
        // Rounding of the sums above and of storing in T: widen the radius by a few ulps of the
        // coordinates' scale.
        const double pad = (scale + max_component(bvhkit::max(c, -c))) * double(detail::fit_pad<T>);
        const auto back = [k](double x) { return k == 0 ? x : std::ldexp(x, k); };
        v.center = Vec<T, 3>(Vec3d(back(c[0]), back(c[1]), back(c[2])));
        v.axes = Mat3<T>(axes);
        v.half[0] = T(back((xhi - xlo) * 0.5));
        v.half[1] = T(back((yhi - ylo) * 0.5));
        v.radius = T(back(r + pad));
        return v;
    }
};

}  // namespace bvhkit
