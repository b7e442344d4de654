#pragma once
// Triangle<T>: three corners, its bounds and centroid, and two ray tests:
// - Woop, Benthin and Wald 2013, "Watertight ray/triangle intersection": no ray slips through an
//   edge or vertex shared by two triangles (the default of TriangleBvh); WatertightRay holds the
//   per-ray constants so that a traversal computes them once per ray;
// - Moller and Trumbore 1997, "Fast, minimum storage ray/triangle intersection": not watertight.
//   Its three barycentric tests round independently per triangle, so a ray through a shared edge
//   (or vertex) can be outside both triangles by a rounding error and slip through to whatever lies
//   behind; measured, about 1 in 10^5..10^6 camera rays on a scanned mesh.
// PrecomputedTriangle keeps the edges and normal so the fast test does one cross product.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <type_traits>

#include "bvhkit/math/ray.hpp"
#include "bvhkit/primitives/hit.hpp"

namespace bvhkit {

template <class T>
struct TriangleHit {
    T t, u, v;
};

/// Per-ray constants of the watertight test (Woop, Benthin and Wald 2013), made once per ray: the
/// axis kz where the direction is largest, kx and ky after it (swapped when d[kz] < 0 so that the
/// winding is kept), the shear that maps the direction onto the kz axis, and the origin in that
/// order. `valid` is false for a zero direction or one with a NaN or infinite component (the test
/// then misses).
template <class T>
struct WatertightRay {
    /// Edge functions and t are evaluated in double for float triangles: a product of two floats
    /// is exact in double, so each edge function's sign is exact for the sheared coordinates and
    /// the same edge seen from its two triangles gives exactly opposite values (no gap, whatever
    /// the compiler contracts into FMAs). For double triangles the two products are kept apart
    /// from the subtraction for the same reason.
    using Wide = std::conditional_t<std::is_same_v<T, float>, double, T>;
    std::uint32_t kx = 0, ky = 1, kz = 2;
    T ox = 0, oy = 0, oz = 0;
    T sx = 0, sy = 0;
    Wide dz = 0;
    bool valid = false;

    WatertightRay() = default;
    explicit WatertightRay(const Ray<T, 3>& ray) {
        const Vec<T, 3>& d = ray.direction;
        choose_axes(ray);
        valid = d[kz] != T(0) && std::isfinite(d[0]) && std::isfinite(d[1]) && std::isfinite(d[2]);
        // |sx|, |sy| <= 1 by the choice of kz, also for subnormal components; d[kz] itself is
        // used only as a divisor of t (1 / d[kz] overflows for a subnormal d[kz]).
        sx = valid ? d[kx] / d[kz] : T(0);
        sy = valid ? d[ky] / d[kz] : T(0);
        // An invalid ray gets NaN, so that every t it produces fails the range test.
        dz = valid ? Wide(d[kz]) : std::numeric_limits<Wide>::quiet_NaN();
    }
    /// The same constants for a ray already known to have a finite direction with a component
    /// other than zero (the wide walks' wide_ray_usable): then d[kz] != 0 and the ray is valid.
    struct KnownValid {};
    [[gnu::always_inline]] WatertightRay(const Ray<T, 3>& ray, KnownValid) {
        const Vec<T, 3>& d = ray.direction;
        choose_axes(ray);
        valid = true;
        sx = d[kx] / d[kz];
        sy = d[ky] / d[kz];
        dz = Wide(d[kz]);
    }

  private:
    [[gnu::always_inline]] void choose_axes(const Ray<T, 3>& ray) {
        const Vec<T, 3>& d = ray.direction;
        // kz = d0 >= d1 ? (d0 >= d2 ? 0 : 2) : (d1 >= d2 ? 1 : 2) in magnitudes, and the swap,
        // without branches: for incoherent rays each would be a coin toss for the predictor.
        const T a0 = std::fabs(d[0]), a1 = std::fabs(d[1]), a2 = std::fabs(d[2]);
        const unsigned c01 = a0 >= a1, c02 = a0 >= a2, c12 = a1 >= a2;
        kz = 2u - 2u * (c01 & c02) - ((c01 ^ 1u) & c12);
        // (kz + 1) % 3 and (kz + 2) % 3, read from two-bit fields.
        const std::uint32_t x0 = (0b00'10'01u >> (2u * kz)) & 3u,
                            y0 = (0b01'00'10u >> (2u * kz)) & 3u;
        const std::uint32_t swap = (x0 ^ y0) & (0u - std::uint32_t(d[kz] < T(0)));
        kx = x0 ^ swap;
        ky = y0 ^ swap;
        ox = ray.origin[kx];
        oy = ray.origin[ky];
        oz = ray.origin[kz];
    }
};

/// A triangle's corners moved to a watertight ray's origin and sheared so that the ray runs along
/// its kz axis: x and y across the ray, z along it; a, b, c are the corners p0, p1, p2. What
/// watertight_finish takes.
template <class T>
struct ShearedTriangle {
    T ax, ay, az, bx, by, bz, cx, cy, cz;
};

namespace detail {
/// Keeps `x` as computed: stops the compiler from fusing the product that made it into a later
/// subtraction (an FMA there would make a shared edge's two edge functions differ in more than
/// sign).
template <class T>
[[gnu::always_inline]] inline T opaque(T x) {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    asm("" : "+x"(x));
#elif defined(__GNUC__) && defined(__aarch64__)
    asm("" : "+w"(x));
#endif
    return x;
}

/// The edge functions and t of the watertight test for sheared corners, in W: the arithmetic of
/// watertight_finish's paths. Gives t (before any power of two of the scaled path), det and the
/// edge functions of p1 and p2, whose quotients by det are the barycentrics.
template <class W>
[[gnu::always_inline]] inline bool watertight_solve(const ShearedTriangle<W>& s, W dz, W& t, W& det,
                                                    W& ev_out, W& ew_out) {
    const auto [ax, ay, az, bx, by, bz, cx, cy, cz] = s;
    const W eu = opaque(cx * by) - opaque(cy * bx);  // edge b-c: weight of p0
    const W ev = opaque(ax * cy) - opaque(ay * cx);  // edge c-a: weight of p1
    const W ew = opaque(bx * ay) - opaque(by * ax);  // edge a-b: weight of p2
    if ((eu < 0 || ev < 0 || ew < 0) && (eu > 0 || ev > 0 || ew > 0)) return false;
    det = eu + ev + ew;
    if (det == W(0)) return false;
    // t = (eu az + ev bz + ew cz) / (det d[kz]): the paper's scaled z without 1 / d[kz].
    t = (eu * az + ev * bz + ew * cz) / (det * dz);
    ev_out = ev;
    ew_out = ew;
    return true;
}

/// The power of two a double corner's sheared x and y are divided by before the edge functions: 0
/// while the larger of |x| and |y| lies in [2^-200, 2^200] (or is 0), else its exponent. It depends
/// on the corner alone, so every triangle that shares the corner uses the same scaled values, and
/// a shared edge's two edge functions are the same products, negated: watertight whatever scale
/// each triangle's other corners need, even where scaling rounds a small coordinate.
inline int corner_exponent(double x, double y) {
    const double m = std::max(std::fabs(x), std::fabs(y));
    if (!(m > 0) || !std::isfinite(m) || (m >= 0x1p-200 && m <= 0x1p200)) return 0;
    return std::ilogb(m);
}

/// Whether |x| lies in [2^-200, 2^200]: with every corner's exponent 0 and the largest |z| and
/// |d[kz]| there, the edge functions (products of two), t's numerator (of three) and det d[kz]
/// stay within double's range.
inline bool in_direct_window(double x) {
    const double a = std::fabs(x);
    return a >= 0x1p-200 && a <= 0x1p200;
}

/// The exponent e with x = f 2^e, f in [1, 2); 0 for 0 (nothing to scale).
inline int scale_exponent(double x) {
    return x > 0 && std::isfinite(x) ? std::ilogb(x) : 0;
}

/// watertight_finish's scaled path for double corners (see there): each corner's x and y scaled
/// by its own power of two for the edge functions' signs, then the edge functions brought to the
/// triangle's common scale for det, t and the barycentrics (exact, or sinking towards zero with
/// their signs kept), z and d[kz] scaled apart.
[[gnu::noinline]] inline bool watertight_solve_scaled(const int (&e)[3], const double (&x)[3],
                                                      const double (&y)[3], const double (&z)[3],
                                                      double dz, double& t, double& det,
                                                      double& ev_out, double& ew_out) {
    // The common scale is that of the largest corner (its own exponent, whether or not the
    // corner itself was scaled), so the largest edge functions land near 1 and the small ones
    // keep what bits they can. A corner on the ray (x = y = 0) scales to 0 by any power and sets
    // nothing.
    int top = std::numeric_limits<int>::min();
    for (int k = 0; k < 3; ++k) {
        const double m = std::max(std::fabs(x[k]), std::fabs(y[k]));
        // Corners near DBL_MAX shear to inf or NaN: no sign can be told, the ray misses.
        if (!std::isfinite(m)) return false;
        if (m > 0) top = std::max(top, std::ilogb(m));
    }
    if (top == std::numeric_limits<int>::min()) return false;  // all three on the ray
    double xs[3], ys[3];
    for (int k = 0; k < 3; ++k) xs[k] = std::ldexp(x[k], -e[k]), ys[k] = std::ldexp(y[k], -e[k]);
    const double eu = opaque(xs[2] * ys[1]) - opaque(ys[2] * xs[1]);  // at 2^-(e1 + e2)
    const double ev = opaque(xs[0] * ys[2]) - opaque(ys[0] * xs[2]);  // at 2^-(e2 + e0)
    const double ew = opaque(xs[1] * ys[0]) - opaque(ys[1] * xs[0]);  // at 2^-(e0 + e1)
    if ((eu < 0 || ev < 0 || ew < 0) && (eu > 0 || ev > 0 || ew > 0)) return false;
    const double u = std::ldexp(eu, e[1] + e[2] - 2 * top),
                 v = std::ldexp(ev, e[2] + e[0] - 2 * top),
                 w = std::ldexp(ew, e[0] + e[1] - 2 * top);
    det = u + v + w;
    if (det == 0) return false;
    const int ez = scale_exponent(std::max({std::fabs(z[0]), std::fabs(z[1]), std::fabs(z[2])})),
              ed = scale_exponent(std::fabs(dz));
    // t = (numerator 2^(2 top + ez)) / (det 2^(2 top) * d[kz] 2^ed): 2^(ez - ed) is left over.
    const double num =
        u * std::ldexp(z[0], -ez) + v * std::ldexp(z[1], -ez) + w * std::ldexp(z[2], -ez);
    t = std::ldexp(num / (det * std::ldexp(dz, -ed)), ez - ed);
    ev_out = v;
    ew_out = w;
    return true;
}

}  // namespace detail

/// The watertight test's second half, for the triangle's corners already moved to the ray's origin
/// and sheared (a*, b*, c*: corners p0, p1, p2; x, y sheared, z along the ray): the edge functions
/// and t in `Wide`. Shared by the scalar test below and the four-abreast one
/// (primitives/triangle_group.hpp), which shears in SIMD and finishes here.
///
/// Double corners, or a direction, outside [2^-200, 2^200] (meshes beyond about 1e+-60 across, or a
/// ray far from them) take a scaled path: the products of two and three coordinates would otherwise
/// leave double's range. Each corner's x and y are scaled by a power of two of its own
/// (detail::corner_exponent), so a shared edge gets the same products, negated, from its two
/// triangles (watertight); the edge functions are then brought to one scale per triangle, and z
/// and d[kz] are scaled apart. Inside the window nothing is scaled and the bits are as before.
/// Float corners never need it: their products of three stay within double's range.
template <class T>
inline bool watertight_finish(const WatertightRay<T>& r, const ShearedTriangle<T>& s, T tmin,
                              T tmax, TriangleHit<T>& hit) {
    using W = typename WatertightRay<T>::Wide;
    W t_wide, det, ev, ew;
    if constexpr (std::is_same_v<T, double>) {
        const int e[3] = {detail::corner_exponent(s.ax, s.ay), detail::corner_exponent(s.bx, s.by),
                          detail::corner_exponent(s.cx, s.cy)};
        const double mz = std::max({std::fabs(s.az), std::fabs(s.bz), std::fabs(s.cz)});
        if ((e[0] | e[1] | e[2]) == 0 && detail::in_direct_window(mz) &&
            detail::in_direct_window(r.dz)) {
            if (!detail::watertight_solve<W>(s, r.dz, t_wide, det, ev, ew)) return false;
        } else if (!detail::watertight_solve_scaled(e, {s.ax, s.bx, s.cx}, {s.ay, s.by, s.cy},
                                                    {s.az, s.bz, s.cz}, r.dz, t_wide, det, ev,
                                                    ew)) {
            return false;
        }
    } else {
        const ShearedTriangle<W> w{W(s.ax), W(s.ay), W(s.az), W(s.bx), W(s.by),
                                   W(s.bz), W(s.cx), W(s.cy), W(s.cz)};
        if (!detail::watertight_solve<W>(w, r.dz, t_wide, det, ev, ew)) return false;
    }
    const T t = T(t_wide);
    if (!(t >= tmin && t <= tmax) || !std::isfinite(t)) return false;
    const W inv_det = W(1) / det;
    hit = {t, T(ev * inv_det), T(ew * inv_det)};
    return true;
}
/// The corners one by one: kept for one release.
template <class T>
[[deprecated("use watertight_finish(r, ShearedTriangle<T>{...}, tmin, tmax, hit)")]] inline bool
watertight_finish(const WatertightRay<T>& r, T ax, T ay, T az, T bx, T by, T bz, T cx, T cy, T cz,
                  T tmin, T tmax, TriangleHit<T>& hit) {
    return watertight_finish(r, ShearedTriangle<T>{ax, ay, az, bx, by, bz, cx, cy, cz}, tmin, tmax,
                             hit);
}

/// The watertight test of the triangle (p0, p1, p2) for a ray prepared as `r`: hits with t in
/// [tmin, tmax]. A ray through an edge or vertex shared by two triangles hits at least one of them
/// (edge functions of zero count as inside). Degenerate triangles and rays in the triangle's plane
/// (det = 0) miss, as does a hit whose t is not finite (a subnormal direction whose t overflows).
template <class T>
inline bool intersect_watertight(const WatertightRay<T>& r, const Vec<T, 3>& p0,
                                 const Vec<T, 3>& p1, const Vec<T, 3>& p2, T tmin, T tmax,
                                 TriangleHit<T>& hit) {
    // Vertices relative to the origin, sheared so that the ray runs along the kz axis. The
    // products are kept apart from the subtractions, as in the four-abreast test, so both round
    // alike whatever the compiler would contract.
    using detail::opaque;
    const T az = p0[r.kz] - r.oz, bz = p1[r.kz] - r.oz, cz = p2[r.kz] - r.oz;
    const T ax = (p0[r.kx] - r.ox) - opaque(r.sx * az), ay = (p0[r.ky] - r.oy) - opaque(r.sy * az);
    const T bx = (p1[r.kx] - r.ox) - opaque(r.sx * bz), by = (p1[r.ky] - r.oy) - opaque(r.sy * bz);
    const T cx = (p2[r.kx] - r.ox) - opaque(r.sx * cz), cy = (p2[r.ky] - r.oy) - opaque(r.sy * cz);
    return watertight_finish(r, ShearedTriangle<T>{ax, ay, az, bx, by, bz, cx, cy, cz}, tmin, tmax,
                             hit);
}

template <class T>
struct Triangle {
    using Scalar = T;
    Vec<T, 3> p0, p1, p2;

    Aabb<T, 3> bounds() const { return Aabb<T, 3>::of_points(p0, p1, p2); }
    Vec<T, 3> centroid() const { return (p0 + p1 + p2) * (T(1) / T(3)); }
    Vec<T, 3> normal() const { return cross(p1 - p0, p2 - p0); }  // not normalized
    T area() const { return T(0.5) * length(normal()); }

    /// Moller-Trumbore. Hits with t in [ray.tmin, ray.tmax]; degenerate and parallel cases miss.
    std::optional<TriangleHit<T>> intersect(const Ray<T, 3>& ray) const {
        const Vec<T, 3> e1 = p1 - p0, e2 = p2 - p0;
        const Vec<T, 3> p = cross(ray.direction, e2);
        const T det = dot(e1, p);
        if (det == T(0) || !std::isfinite(det)) return std::nullopt;
        const T inv_det = T(1) / det;
        const Vec<T, 3> s = ray.origin - p0;
        const T u = dot(s, p) * inv_det;
        if (!(u >= T(0) && u <= T(1))) return std::nullopt;
        const Vec<T, 3> q = cross(s, e1);
        const T v = dot(ray.direction, q) * inv_det;
        if (!(v >= T(0) && u + v <= T(1))) return std::nullopt;
        const T t = dot(e2, q) * inv_det;
        if (!(t >= ray.tmin && t <= ray.tmax)) return std::nullopt;
        return TriangleHit<T>{t, u, v};
    }

    /// Woop, Benthin, Wald 2013 (see intersect_watertight above). Hits with t in [ray.tmin,
    /// ray.tmax]; a zero, NaN or infinite direction, a degenerate triangle and a ray in the
    /// triangle's plane miss.
    std::optional<TriangleHit<T>> intersect_watertight(const Ray<T, 3>& ray) const {
        TriangleHit<T> h;
        if (bvhkit::intersect_watertight(WatertightRay<T>(ray), p0, p1, p2, ray.tmin, ray.tmax, h))
            return h;
        return std::nullopt;
    }
};

/// A triangle stored for fast ray tests: p0, e1 = p0 - p1, e2 = p2 - p0 and n = e1 x e2.
/// Solving o + t d = p0 + u (p1 - p0) + v (p2 - p0) by Cramer's rule with c = p0 - o and r = d x c
/// gives det = d.n, u = r.e2 / det, v = r.e1 / det, t = c.n / det (the Moller-Trumbore solution
/// with the triple products regrouped so that only r is computed per ray).
template <class T>
struct PrecomputedTriangle {
    Vec<T, 3> p0, e1, e2, n;

    PrecomputedTriangle() = default;
    explicit PrecomputedTriangle(const Triangle<T>& tri)
        : p0(tri.p0), e1(tri.p0 - tri.p1), e2(tri.p2 - tri.p0), n(cross(e1, e2)) {}

    /// Hits with t in [ray.tmin, tmax]. A degenerate triangle or a parallel ray makes det 0, and
    /// the resulting inf/NaN fails the comparisons, so it misses without a branch of its own.
    bool intersect(const Ray<T, 3>& ray, T tmax, TriangleHit<T>& hit) const {
        const Vec<T, 3> c = p0 - ray.origin;
        const Vec<T, 3> r = cross(ray.direction, c);
        const T inv_det = T(1) / dot(n, ray.direction);
        const T u = dot(r, e2) * inv_det;
        const T v = dot(r, e1) * inv_det;
        const T w = T(1) - u - v;
        if (!(u >= T(0) && v >= T(0) && w >= T(0))) return false;
        const T t = dot(n, c) * inv_det;
        if (!(t >= ray.tmin && t <= tmax)) return false;
        hit = {t, u, v};
        return true;
    }
};

using Trianglef = Triangle<float>;
using Triangled = Triangle<double>;

}  // namespace bvhkit
