#pragma once
// PosedTriangles<T>: the triangle-triangle decision of triangle_triangle.hpp for a triangle b given
// in its own frame and carried into a's by a pose, decided exactly for the pose as given: on the
// exact real values R x + t of b's corners, never on a rounding of them (rounding b's corners to
// float flips touching and near-touching pairs whose margins are below float's resolution).
//
// Three levels, each taken only where the one before cannot decide:
// - R x + t in double, with a bound e on its rounding computed per query (`transform_error`). An
//   orientation sign is accepted when the double determinant exceeds Shewchuk's (1997) bound on
//   its own rounding plus a bound on how far corners moved by up to e can move it
//   (orient3d_within). Corners touching, coplanar or collinear are never decided here (a zero
//   cannot be certified from moved corners).
// - A pose applied without rounding (a signed permutation and no translation: the identity among
//   them) has e = 0, and the double corners are b's exact corners: the exact decision on them.
// - Otherwise, the corners exactly, as integers at a common power of two (math/exact_integer.hpp:
//   sums of products of doubles are exact), and the same decision (triangle_triangle.hpp's, which
//   takes any corner type) on them.
// The segment of a contact is then computed in double from the double corners and rounded to T, as
// triangle_contact.hpp does; the decision never depends on it.
//
// Range: every finite input. Float models (coordinates and pose) never leave the range where the
// double bounds hold. For double models a pair is first scaled by one power of two (exact: the
// signs are homogeneous in the coordinates and the rounding bound scales with them) so that every
// nonzero coordinate and the bound lie in [2^-250, 2^251), where no product of the bounds
// underflows (a sunk product would make a bound too small) and none overflows; a pair spanning
// more than 2^500 skips the double level (an overflowing bound only ever declines, and the exact
// level takes every double).
#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <type_traits>

#include "bvhkit/math/exact_integer.hpp"
#include "bvhkit/math/transform.hpp"
#include "bvhkit/primitives/triangle_triangle.hpp"

namespace bvhkit {

namespace detail {

/// A corner held exactly as integers (at a scale shared by every corner of one decision); `id`
/// says which corner it is (0-2: a's, 3-5: b's).
struct ExactCorner {
    const std::array<exact::DyadicInt, 3>* xyz = nullptr;
    int id = 0;
    const exact::DyadicInt& operator[](std::size_t k) const { return (*xyz)[k]; }
};

inline int orient3d_sign(const ExactCorner& a, const ExactCorner& b, const ExactCorner& c,
                         const ExactCorner& d) {
    using exact::DyadicInt;
    const DyadicInt u0 = b[0] - a[0], u1 = b[1] - a[1], u2 = b[2] - a[2];
    const DyadicInt v0 = c[0] - a[0], v1 = c[1] - a[1], v2 = c[2] - a[2];
    const DyadicInt w0 = d[0] - a[0], w1 = d[1] - a[1], w2 = d[2] - a[2];
    return ((u1 * v2 - u2 * v1) * w0 + (u2 * v0 - u0 * v2) * w1 + (u0 * v1 - u1 * v0) * w2).sign();
}

inline void orient3d_signs(const ExactCorner& a, const ExactCorner& b, const ExactCorner& c,
                           const ExactCorner* d, int* out) {
    for (int i = 0; i < 3; ++i) out[i] = orient3d_sign(a, b, c, d[i]);
}

inline int orient2d_in(const ExactCorner& a, const ExactCorner& b, const ExactCorner& c,
                       std::size_t drop) {
    std::size_t x, y;
    kept_axes(drop, x, y);
    return ((b[x] - a[x]) * (c[y] - a[y]) - (b[y] - a[y]) * (c[x] - a[x])).sign();
}

/// The sign of orient3d(a, b, c, d) (predicates.hpp) for corners that may each lie up to ea, eb,
/// ec, ed (in every coordinate) from the given ones, or 0 where that does not settle it.
// With u = b - a, v = c - a, w = d - a moved by du, dv, dw: det(u', v', w') - det(u, v, w) =
// det(du, v', w') + det(u, dv, w') + det(u, v, dw), and |det(x, y, z)| <= |x|_inf |y|_1 |z|_1.
inline int orient3d_within(const Vec<double, 3>& a, const Vec<double, 3>& b,
                           const Vec<double, 3>& c, const Vec<double, 3>& d, double ea, double eb,
                           double ec, double ed) {
    const double ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
    const double vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
    const double wx = d[0] - a[0], wy = d[1] - a[1], wz = d[2] - a[2];
    const double p0 = uy * vz, q0 = uz * vy, p1 = uz * vx, q1 = ux * vz, p2 = ux * vy, q2 = uy * vx;
    const double det = (p0 - q0) * wx + (p1 - q1) * wy + (p2 - q2) * wz;
    const double permanent = (std::fabs(p0) + std::fabs(q0)) * std::fabs(wx) +
                             (std::fabs(p1) + std::fabs(q1)) * std::fabs(wy) +
                             (std::fabs(p2) + std::fabs(q2)) * std::fabs(wz);
    const double eu = ea + eb, ev = ea + ec, ew = ea + ed;
    const double u1 = std::fabs(ux) + std::fabs(uy) + std::fabs(uz),
                 v1 = std::fabs(vx) + std::fabs(vy) + std::fabs(vz),
                 w1 = std::fabs(wx) + std::fabs(wy) + std::fabs(wz);
    const double moved =
        eu * (v1 + 3 * ev) * (w1 + 3 * ew) + ev * u1 * (w1 + 3 * ew) + ew * u1 * v1;
    // The factor covers the rounding of the differences and of this bound itself.
    const double bound = (exact::orient3d_bound * permanent + moved) * (1 + 0x1p-40);
    if (det > bound) return 1;
    if (-det > bound) return -1;
    return 0;  // also for a NaN or an infinity: the exact level decides
}

/// orient3d_within(a, b, c, d[i], 0, 0, 0, e) for i = 0..2: an exact plane, corners within e.
inline bool orient3d_signs_within(const Vec<double, 3>& a, const Vec<double, 3>& b,
                                  const Vec<double, 3>& c, const Vec<double, 3>* d, double e,
                                  int* out) {
    const double ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
    const double vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
    const double p0 = uy * vz, q0 = uz * vy, p1 = uz * vx, q1 = ux * vz, p2 = ux * vy, q2 = uy * vx;
    const double n0 = p0 - q0, n1 = p1 - q1, n2 = p2 - q2;
    const double m0 = std::fabs(p0) + std::fabs(q0), m1 = std::fabs(p1) + std::fabs(q1),
                 m2 = std::fabs(p2) + std::fabs(q2);
    // det(u, v, dw) = (u x v) . dw, and |(u x v)_k| <= m_k.
    const double moved = e * (m0 + m1 + m2);
    for (int i = 0; i < 3; ++i) {
        const double wx = d[i][0] - a[0], wy = d[i][1] - a[1], wz = d[i][2] - a[2];
        const double det = n0 * wx + n1 * wy + n2 * wz;
        const double bound = (exact::orient3d_bound *
                                  (m0 * std::fabs(wx) + m1 * std::fabs(wy) + m2 * std::fabs(wz)) +
                              moved) *
                             (1 + 0x1p-40);
        out[i] = det > bound ? 1 : -det > bound ? -1 : 0;
        if (out[i] == 0) return false;
    }
    return true;
}

enum class Filtered { None, Crossing, Undecided };

/// The power of two 2^k that brings the pair's nonzero coordinates and e into [2^-250, 2^251)
/// (the header's range for double models), k nearest 0; false when there is none.
inline bool filter_shift(const Vec<double, 3>* u, const Vec<double, 3>* v, double e, int& k) {
    int high = INT_MIN, low = INT_MAX;
    bool finite = true;
    const auto add = [&](double x) {
        if (x == 0) return;
        if (!std::isfinite(x)) {  // a corner carried past the largest double
            finite = false;
            return;
        }
        const int b = std::ilogb(x);
        high = std::max(high, b);
        low = std::min(low, b);
    };
    for (int i = 0; i < 3; ++i)
        for (std::size_t j = 0; j < 3; ++j) {
            add(u[i][j]);
            add(v[i][j]);
        }
    add(e);
    if (!finite) return false;
    if (high == INT_MIN) return true;  // all zero: k stays 0
    if (low >= -250 && high <= 250) return true;
    if (high - low > 500) return false;
    k = std::clamp(0, -250 - low, 250 - high);
    return true;
}

/// decide() (triangle_triangle.hpp) for exact corners u and corners v within e of b's exact
/// ones, where the signs are certain; Undecided elsewhere (including every General case).
inline Filtered decide_within(const Vec<double, 3>* u, const Vec<double, 3>* v, double e,
                              Vec<double, 3>* a, Vec<double, 3>* b) {
    int dv[3], du[3];
    if (!orient3d_signs_within(u[0], u[1], u[2], v, e, dv)) return Filtered::Undecided;
    if (dv[0] == dv[1] && dv[1] == dv[2]) return Filtered::None;
    for (int i = 0; i < 3; ++i) {
        du[i] = orient3d_within(v[0], v[1], v[2], u[i], e, e, e, 0);
        if (du[i] == 0) return Filtered::Undecided;
    }
    if (du[0] == du[1] && du[1] == du[2]) return Filtered::None;
    to_apexes(u, v, du, dv, a, b);
    const int o1 = orient3d_within(a[0], a[1], b[0], b[1], 0, 0, e, e);
    if (o1 == 0) return Filtered::Undecided;
    if (o1 > 0) return Filtered::None;
    const int o2 = orient3d_within(a[0], a[2], b[2], b[0], 0, 0, e, e);
    if (o2 == 0) return Filtered::Undecided;
    return o2 > 0 ? Filtered::None : Filtered::Crossing;
}

template <class T>
TriangleIntersection<T> rounded(const TriangleIntersection<double>& x) {
    return {x.hit, x.coplanar, Vec<T, 3>(x.p), Vec<T, 3>(x.q)};
}

}  // namespace detail

/// Triangles of a model B carried into A's frame by one pose, decided exactly against A's
/// triangles (the header's levels). Made once per query; the calls allocate nothing.
template <class T>
class PosedTriangles {
  public:
    using Vec3d = Vec<double, 3>;

    /// `scale_b`: at least the largest |coordinate| of B's triangles (CollisionModel::scale()).
    PosedTriangles(const Transform<T>& pose, T scale_b)
        : rotation_(pose.rotation),
          translation_(pose.translation),
          error_(transform_error(pose, scale_b)) {}

    /// A bound on |fl(R x + t) - (R x + t)| per coordinate for |x_j| <= scale, R x + t evaluated
    /// in double as apply() does: the error of a dot product of four terms (Higham, "Accuracy and
    /// stability of numerical algorithms", 3.1), gamma_4 <= 4.01 u with u = 2^-53. Zero when the
    /// pose moves no bit: a signed permutation and no translation.
    static double transform_error(const Transform<T>& pose, T scale) {
        bool permutation = true;
        double rows = 0, shift = 0;
        for (std::size_t i = 0; i < 3; ++i) {
            double row = 0;
            int units = 0;
            for (std::size_t j = 0; j < 3; ++j) {
                const double r = double(pose.rotation[i][j]);
                row += std::fabs(r);
                units += std::fabs(r) == 1 ? 1 : r == 0 ? 0 : 2;
            }
            permutation = permutation && units == 1 && pose.translation[i] == 0;
            rows = std::max(rows, row);
            shift = std::max(shift, std::fabs(double(pose.translation[i])));
        }
        if (permutation) return 0;
        return 4.01 * 0x1p-53 * (rows * double(scale) + shift) * (1 + 0x1p-40);
    }

    Vec3d apply(const Vec<T, 3>& x) const { return rotation_ * Vec3d(x) + translation_; }

    /// Whether a (in A's frame) and b (in B's, carried by the pose) meet. Exact.
    bool intersects(const Triangle<T>& a, const Triangle<T>& b) const {
        const Vec3d u[3] = {Vec3d(a.p0), Vec3d(a.p1), Vec3d(a.p2)};
        const Vec3d v[3] = {apply(b.p0), apply(b.p1), apply(b.p2)};
        if (error_ == 0)
            return triangles_intersect(Triangle<double>{u[0], u[1], u[2]},
                                       Triangle<double>{v[0], v[1], v[2]});
        Vec3d ra[3], rb[3];
        int k = 0;
        switch (filtered(u, v, ra, rb, k)) {
            case detail::Filtered::None:
                return false;
            case detail::Filtered::Crossing:
                return true;
            case detail::Filtered::Undecided:
                break;
        }
        return exactly(b, u, v, nullptr);
    }

    /// intersects() with the contact's segment (triangle_triangle.hpp's rules), in A's frame.
    TriangleIntersection<T> intersect(const Triangle<T>& a, const Triangle<T>& b) const {
        const Vec3d v[3] = {apply(b.p0), apply(b.p1), apply(b.p2)};
        return intersect(a, b, v);
    }

    /// intersect() with b's corners already carried: v[i] == apply(b's corner i).
    TriangleIntersection<T> intersect(const Triangle<T>& a, const Triangle<T>& b,
                                      const Vec3d* v) const {
        const Vec3d u[3] = {Vec3d(a.p0), Vec3d(a.p1), Vec3d(a.p2)};
        if (error_ == 0)
            return detail::rounded<T>(intersect_triangles(Triangle<double>{u[0], u[1], u[2]},
                                                          Triangle<double>{v[0], v[1], v[2]}));
        Vec3d ra[3], rb[3];
        int k = 0;
        switch (filtered(u, v, ra, rb, k)) {
            case detail::Filtered::None:
                return {};
            case detail::Filtered::Crossing: {
                TriangleIntersection<double> x = detail::crossing_segment(ra, rb);
                if constexpr (!std::is_same_v<T, float>)
                    if (k != 0) x.p = scaled(x.p, -k), x.q = scaled(x.q, -k);
                return detail::rounded<T>(x);
            }
            case detail::Filtered::Undecided:
                break;
        }
        TriangleIntersection<double> x;
        exactly(b, u, v, &x);
        return detail::rounded<T>(x);
    }

    /// The bound on the double corners' rounding (0: they are exact).
    double transform_error() const { return error_; }

  private:
    static Vec3d scaled(const Vec3d& p, int k) {
        return {std::ldexp(p[0], k), std::ldexp(p[1], k), std::ldexp(p[2], k)};
    }

    /// The double level (decide_within) on a pair; for double models on the pair scaled by 2^k
    /// (filter_shift), with ra, rb then scaled too. Undecided where no such k exists.
    detail::Filtered filtered(const Vec3d* u, const Vec3d* v, Vec3d* ra, Vec3d* rb, int& k) const {
        if constexpr (std::is_same_v<T, float>) {
            return detail::decide_within(u, v, error_, ra, rb);
        } else {
            if (!detail::filter_shift(u, v, error_, k)) return detail::Filtered::Undecided;
            if (k == 0) return detail::decide_within(u, v, error_, ra, rb);
            const Vec3d us[3] = {scaled(u[0], k), scaled(u[1], k), scaled(u[2], k)};
            const Vec3d vs[3] = {scaled(v[0], k), scaled(v[1], k), scaled(v[2], k)};
            return detail::decide_within(us, vs, std::ldexp(error_, k), ra, rb);
        }
    }

    /// The exact level: the corners as integers at one scale 2^s (a's coordinates, t, and each
    /// product R_ij x_j are integers there), the decision on them. With `segment`, a contact's
    /// segment from the double corners u, v.
    bool exactly(const Triangle<T>& b, const Vec3d* u, const Vec3d* v,
                 TriangleIntersection<double>* segment) const {
        using exact::DyadicInt;
        const Vec3d xb[3] = {Vec3d(b.p0), Vec3d(b.p1), Vec3d(b.p2)};
        int s_a = -4000, s_r = -4000, s_x = -4000;
        for (std::size_t k = 0; k < 3; ++k) {
            s_a = std::max(s_a, DyadicInt::lowest_shift(translation_[k]));
            for (int i = 0; i < 3; ++i) {
                s_a = std::max(s_a, DyadicInt::lowest_shift(u[i][k]));
                s_x = std::max(s_x, DyadicInt::lowest_shift(xb[i][k]));
                s_r = std::max(s_r, DyadicInt::lowest_shift(rotation_[i][k]));
            }
        }
        const int s = std::max(s_a, s_r + s_x);
        std::array<DyadicInt, 3> corner[6];
        for (int i = 0; i < 3; ++i)
            for (std::size_t k = 0; k < 3; ++k) {
                corner[i][k] = DyadicInt::from_double(u[i][k], s);
                DyadicInt c = DyadicInt::from_double(translation_[k], s);
                for (std::size_t j = 0; j < 3; ++j)
                    c = c + DyadicInt::from_double(rotation_[k][j], s_r) *
                                DyadicInt::from_double(xb[i][j], s - s_r);
                corner[3 + i][k] = c;
            }
        const detail::ExactCorner eu[3] = {{&corner[0], 0}, {&corner[1], 1}, {&corner[2], 2}};
        const detail::ExactCorner ev[3] = {{&corner[3], 3}, {&corner[4], 4}, {&corner[5], 5}};
        detail::ExactCorner ea[3], eb[3];
        const detail::Meet m = detail::decide(eu, ev, ea, eb);
        if (m == detail::Meet::None) return false;
        if (m == detail::Meet::General && !detail::edges_meet(eu, ev)) return false;
        if (segment == nullptr) return true;
        const auto at = [&](const detail::ExactCorner& c) {
            return c.id < 3 ? u[c.id] : v[c.id - 3];
        };
        // The segment from the double corners, which are within rounding of the exact ones.
        Vec3d ra[3], rb[3];
        for (int i = 0; i < 3; ++i) ra[i] = at(ea[i]), rb[i] = at(eb[i]);
        if constexpr (std::is_same_v<T, float>)
            *segment = detail::contact_segment(m, u, v, ra, rb, eu, ev);
        else  // double models reach scales where the constructions need scaling
            *segment = detail::contact_segment_scaled(m, u, v, ra, rb, eu, ev);
        return true;
    }

    Mat3<double> rotation_;
    Vec3d translation_;
    double error_ = 0;
};

}  // namespace bvhkit
