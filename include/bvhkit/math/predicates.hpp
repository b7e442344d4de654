#pragma once
// Exact orientation predicates: the sign of a 2x2 or 3x3 determinant of coordinate differences,
// decided without error for float and double input. A double evaluation decides when its value
// exceeds a proved bound on its rounding error (the filter of Shewchuk 1997, "Adaptive precision
// floating-point arithmetic and fast robust geometric predicates", bounds A); otherwise the
// determinant is evaluated exactly as a floating-point expansion (same paper: sums and products of
// doubles kept as lists of non-overlapping doubles) and the sign is read off its largest term.
//
// Range: every finite input, float or double. Float input converted to double never leaves the
// range where the arithmetic above is exact (differences below 2^129, products of three below
// 2^390, every term a multiple of 2^-447). Double input can: products of three differences
// overflow above ~2^341 and lose bits below ~2^-358. There
// - the filter's bound carries an absolute term for what underflowing products can lose, so a
//   sign it accepts is right at every scale (overflow makes the bound infinite: never accepted);
// - what it leaves is first scaled by one power of two that brings every coordinate into the
//   expansions' exact range (exact: a determinant of degree 3 in the coordinates keeps its sign),
//   which exists while the largest coordinate is within 2^688 of the lowest set bit of any
//   (2^1027 for orient2d);
// - beyond that (say 1e300 and 1e-10 in one call) the determinant is taken in exact integers
//   (math/exact_integer.hpp), slow but exact.
// A NaN or infinite coordinate has no sign: 0 (the expansions must never see one).
#include <algorithm>
#include <array>
#include <bit>
#include <climits>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "bvhkit/math/exact_integer.hpp"
#include "bvhkit/math/vec.hpp"

namespace bvhkit::exact {

/// A floating-point expansion: `n` doubles of increasing magnitude, non-overlapping, whose exact
/// sum is the value (Shewchuk 1997).
template <std::size_t N>
struct Expansion {
    std::array<double, N> e{};
    std::size_t n = 0;
};

/// x + y = a + b exactly, |y| <= ulp(x) / 2 (Knuth's two-sum).
inline void two_sum(double a, double b, double& x, double& y) {
    x = a + b;
    const double bv = x - a, av = x - bv;
    y = (a - av) + (b - bv);
}

/// x + y = a * b exactly (the fused multiply-add gives the rounding error of the product).
inline void two_product(double a, double b, double& x, double& y) {
    x = a * b;
    y = std::fma(a, b, -x);
}

/// h = e + f by growing e with each term of f (Shewchuk's Expansion-Sum): quadratic, which is fine
/// for the few dozen terms used here. The result has at most e.n + f.n terms; M must allow it.
template <std::size_t M, std::size_t N, std::size_t K>
void sum(const Expansion<N>& e, const Expansion<K>& f, Expansion<M>& h) {
    Expansion<M> cur, next;
    cur.n = e.n;
    for (std::size_t i = 0; i < e.n; ++i) cur.e[i] = e.e[i];
    for (std::size_t j = 0; j < f.n; ++j) {
        next.n = 0;
        double q = f.e[j];
        for (std::size_t i = 0; i < cur.n; ++i) {
            double s, t;
            two_sum(q, cur.e[i], s, t);
            if (t != 0) next.e[next.n++] = t;
            q = s;
        }
        if (q != 0 || next.n == 0) next.e[next.n++] = q;
        cur = next;
    }
    h = cur;
}

/// h = e * b (Shewchuk's Scale-Expansion, zero terms dropped).
template <std::size_t M, std::size_t N>
void scale(const Expansion<N>& e, double b, Expansion<M>& h) {
    static_assert(M >= 2 * N);
    h.n = 0;
    if (e.n == 0) {
        h.e[h.n++] = 0;
        return;
    }
    double q, t;
    two_product(e.e[0], b, q, t);
    if (t != 0) h.e[h.n++] = t;
    for (std::size_t i = 1; i < e.n; ++i) {
        double p1, p0, s, u;
        two_product(e.e[i], b, p1, p0);
        two_sum(q, p0, s, u);
        if (u != 0) h.e[h.n++] = u;
        two_sum(p1, s, q, u);
        if (u != 0) h.e[h.n++] = u;
    }
    if (q != 0 || h.n == 0) h.e[h.n++] = q;
}

/// h = e * f.
template <std::size_t M, std::size_t N, std::size_t K>
void product(const Expansion<N>& e, const Expansion<K>& f, Expansion<M>& h) {
    static_assert(M >= 2 * N * K);  // each term of f adds at most 2 * N terms
    h.n = 1;
    h.e[0] = 0;
    for (std::size_t j = 0; j < f.n; ++j) {
        Expansion<2 * N> part;
        scale(e, f.e[j], part);
        Expansion<M> acc;
        sum(h, part, acc);
        h = acc;
    }
}

template <std::size_t N>
Expansion<N> negated(Expansion<N> e) {
    for (std::size_t i = 0; i < e.n; ++i) e.e[i] = -e.e[i];
    return e;
}

template <std::size_t N>
int sign(const Expansion<N>& e) {
    for (std::size_t i = e.n; i-- > 0;)
        if (e.e[i] != 0) return e.e[i] > 0 ? 1 : -1;
    return 0;
}

/// a - b exactly, as two terms.
inline Expansion<2> difference(double a, double b) {
    double x = a - b;
    const double bv = a - x, av = x + bv;
    const double y = (a - av) + (bv - b);
    Expansion<2> r;
    if (y != 0) r.e[r.n++] = y;
    r.e[r.n++] = x;
    return r;
}

/// a * d - b * c exactly, each operand an exact difference.
inline Expansion<16> cross_term(const Expansion<2>& a, const Expansion<2>& b, const Expansion<2>& c,
                                const Expansion<2>& d) {
    Expansion<8> ad, bc;
    product(a, d, ad);
    product(b, c, bc);
    Expansion<16> r;
    sum(ad, negated(bc), r);
    return r;
}

inline int orient2d_exact(double ax, double ay, double bx, double by, double cx, double cy) {
    return sign(
        cross_term(difference(bx, ax), difference(by, ay), difference(cx, ax), difference(cy, ay)));
}

inline int orient3d_exact(const Vec<double, 3>& a, const Vec<double, 3>& b, const Vec<double, 3>& c,
                          const Vec<double, 3>& d) {
    Expansion<2> u[3], v[3], w[3];
    for (std::size_t k = 0; k < 3; ++k) {
        u[k] = difference(b[k], a[k]);
        v[k] = difference(c[k], a[k]);
        w[k] = difference(d[k], a[k]);
    }
    // (u x v) . w, one component of the cross product at a time.
    Expansion<64> term[3];
    for (std::size_t k = 0; k < 3; ++k) {
        const std::size_t i = (k + 1) % 3, j = (k + 2) % 3;
        product(cross_term(u[i], u[j], v[i], v[j]), w[k], term[k]);
    }
    Expansion<128> two;
    sum(term[0], term[1], two);
    Expansion<192> total;
    sum(two, term[2], total);
    return sign(total);
}

inline constexpr double epsilon = 0x1p-53;  // half an ulp of 1: the relative rounding error
inline constexpr double orient2d_bound = (3.0 + 16.0 * epsilon) * epsilon;  // Shewchuk 1997
inline constexpr double orient3d_bound = (7.0 + 56.0 * epsilon) * epsilon;  // Shewchuk 1997

// Shewchuk's bounds assume no product underflows. An underflowing product is off by at most
// 2^-1075 in absolute terms. In orient3d the six products of u and v reach the determinant times
// a coordinate of w, 2^-1074 |w|_1 in all, and the last products and the bound's own add a few
// 2^-1075 more; in orient2d the two products and the bound, 2^-1073. The terms below exceed these
// many times over and are far below Shewchuk's bound wherever nothing underflows.
inline constexpr double orient2d_underflow = 0x1p-1068;
inline constexpr double orient3d_underflow = 0x1p-1069;

/// The exponents of the leading and the lowest set bits of a set of finite doubles (nonzero ones).
struct BitSpan {
    int high = INT_MIN, low = INT_MAX;
    bool finite = true;

    void add(double x) {
        const auto bits = std::bit_cast<std::uint64_t>(x);
        const int biased = int(bits >> 52) & 0x7ff;
        std::uint64_t m = bits & ((std::uint64_t(1) << 52) - 1);
        if (biased == 0x7ff) {
            finite = false;
            return;
        }
        if (biased != 0) m |= std::uint64_t(1) << 52;
        if (m == 0) return;
        const int e = std::max(biased, 1) - 1075;  // |x| = m 2^e
        high = std::max(high, e + int(std::bit_width(m)) - 1);
        low = std::min(low, e + std::countr_zero(m));
    }
    bool empty() const { return high == INT_MIN; }

    /// A k with low + k >= lo and high + k <= hi, nearest 0; false when there is none.
    bool shift_into(int lo, int hi, int& k) const {
        const int k_min = lo - low, k_max = hi - high;
        if (k_min > k_max) return false;
        k = std::clamp(0, k_min, k_max);
        return true;
    }
};

/// The determinants as exact integers: every double is an integer times 2^-1074, so at the set's
/// common shift (at most 1074 bits) coordinates stay below 2^2098 and a determinant of three
/// differences below 2^6300, within DyadicInt's capacity.
inline int orient2d_integer(const double* x) {  // ax, ay, bx, by, cx, cy
    int s = -4000;
    for (int i = 0; i < 6; ++i) s = std::max(s, DyadicInt::lowest_shift(x[i]));
    DyadicInt v[6];
    for (int i = 0; i < 6; ++i) v[i] = DyadicInt::from_double(x[i], s);
    return ((v[2] - v[0]) * (v[5] - v[1]) - (v[3] - v[1]) * (v[4] - v[0])).sign();
}

inline int orient3d_integer(const Vec<double, 3>* p) {
    int s = -4000;
    for (int i = 0; i < 4; ++i)
        for (std::size_t k = 0; k < 3; ++k) s = std::max(s, DyadicInt::lowest_shift(p[i][k]));
    DyadicInt d[3][3];  // p[i + 1] - p[0]
    for (int i = 0; i < 3; ++i)
        for (std::size_t k = 0; k < 3; ++k)
            d[i][k] = DyadicInt::from_double(p[i + 1][k], s) - DyadicInt::from_double(p[0][k], s);
    return ((d[0][1] * d[1][2] - d[0][2] * d[1][1]) * d[2][0] +
            (d[0][2] * d[1][0] - d[0][0] * d[1][2]) * d[2][1] +
            (d[0][0] * d[1][1] - d[0][1] * d[1][0]) * d[2][2])
        .sign();
}

// Where the expansions are exact: every term is a multiple of 2^(3 low) (of 2^(2 low) in 2D), which
// must not pass below 2^-1074, and the largest, below 2^(3 high + 9), must stay finite.
inline constexpr int orient3d_low = -358, orient3d_high = 330;
inline constexpr int orient2d_low = -537, orient2d_high = 490;

/// The exact sign for any double input the filter left (the header's steps after the filter).
/// Kept out of line: callers inline the filter, not this rare path.
[[gnu::noinline]] inline int orient3d_any(const Vec<double, 3>& a, const Vec<double, 3>& b,
                                          const Vec<double, 3>& c, const Vec<double, 3>& d) {
    BitSpan span;
    for (std::size_t k = 0; k < 3; ++k) {
        span.add(a[k]);
        span.add(b[k]);
        span.add(c[k]);
        span.add(d[k]);
    }
    if (!span.finite || span.empty()) return 0;
    int k = 0;
    if (!span.shift_into(orient3d_low, orient3d_high, k)) {
        const Vec<double, 3> p[4] = {a, b, c, d};
        return orient3d_integer(p);
    }
    if (k == 0) return orient3d_exact(a, b, c, d);
    const auto scaled = [k](const Vec<double, 3>& p) {
        return Vec<double, 3>{std::ldexp(p[0], k), std::ldexp(p[1], k), std::ldexp(p[2], k)};
    };
    return orient3d_exact(scaled(a), scaled(b), scaled(c), scaled(d));
}

[[gnu::noinline]] inline int orient2d_any(double ax, double ay, double bx, double by, double cx,
                                          double cy) {
    double x[6] = {ax, ay, bx, by, cx, cy};
    BitSpan span;
    for (const double v : x) span.add(v);
    if (!span.finite || span.empty()) return 0;
    int k = 0;
    if (!span.shift_into(orient2d_low, orient2d_high, k)) return orient2d_integer(x);
    if (k != 0)
        for (double& v : x) v = std::ldexp(v, k);
    return orient2d_exact(x[0], x[1], x[2], x[3], x[4], x[5]);
}

}  // namespace bvhkit::exact

namespace bvhkit {

/// Sign of (b - a) x (c - a) in the plane: +1 when a, b, c turn counterclockwise, 0 when they
/// are collinear, -1 otherwise. Exact (the header's range).
inline int orient2d_sign(double ax, double ay, double bx, double by, double cx, double cy) {
    const double l = (bx - ax) * (cy - ay), r = (by - ay) * (cx - ax);
    const double det = l - r;
    const double bound =
        exact::orient2d_bound * (std::fabs(l) + std::fabs(r)) + exact::orient2d_underflow;
    if (det > bound) return 1;
    if (-det > bound) return -1;
    return exact::orient2d_any(ax, ay, bx, by, cx, cy);
}

/// Sign of ((b - a) x (c - a)) . (d - a): +1 when d lies on the side of triangle (a, b, c) its
/// normal points to, 0 when the four points are coplanar. Exact (the header's range).
template <class T>
int orient3d_sign(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c, const Vec<T, 3>& d) {
    const double ux = double(b[0]) - double(a[0]), uy = double(b[1]) - double(a[1]),
                 uz = double(b[2]) - double(a[2]);
    const double vx = double(c[0]) - double(a[0]), vy = double(c[1]) - double(a[1]),
                 vz = double(c[2]) - double(a[2]);
    const double wx = double(d[0]) - double(a[0]), wy = double(d[1]) - double(a[1]),
                 wz = double(d[2]) - double(a[2]);
    const double p0 = uy * vz, q0 = uz * vy, p1 = uz * vx, q1 = ux * vz, p2 = ux * vy, q2 = uy * vx;
    const double det = (p0 - q0) * wx + (p1 - q1) * wy + (p2 - q2) * wz;
    const double permanent = (std::fabs(p0) + std::fabs(q0)) * std::fabs(wx) +
                             (std::fabs(p1) + std::fabs(q1)) * std::fabs(wy) +
                             (std::fabs(p2) + std::fabs(q2)) * std::fabs(wz);
    if constexpr (std::is_same_v<T, float>) {  // nothing underflows or overflows
        const double bound = exact::orient3d_bound * permanent;
        if (det > bound) return 1;
        if (-det > bound) return -1;
        if (!std::isfinite(bound)) return 0;  // a NaN or infinite input
        return exact::orient3d_exact(Vec<double, 3>(a), Vec<double, 3>(b), Vec<double, 3>(c),
                                     Vec<double, 3>(d));
    } else {
        const double bound =
            exact::orient3d_bound * permanent +
            exact::orient3d_underflow * (std::fabs(wx) + std::fabs(wy) + std::fabs(wz) + 1);
        if (det > bound) return 1;
        if (-det > bound) return -1;
        return exact::orient3d_any(Vec<double, 3>(a), Vec<double, 3>(b), Vec<double, 3>(c),
                                   Vec<double, 3>(d));
    }
}

/// orient3d_sign(a, b, c, d[i]) for the three points d[0..2]: the plane's products are computed
/// once, by the same operations in the same order, so every sign is the one orient3d_sign gives.
template <class T>
void orient3d_signs(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c, const Vec<T, 3>* d,
                    int* out) {
    const double ux = double(b[0]) - double(a[0]), uy = double(b[1]) - double(a[1]),
                 uz = double(b[2]) - double(a[2]);
    const double vx = double(c[0]) - double(a[0]), vy = double(c[1]) - double(a[1]),
                 vz = double(c[2]) - double(a[2]);
    const double p0 = uy * vz, q0 = uz * vy, p1 = uz * vx, q1 = ux * vz, p2 = ux * vy, q2 = uy * vx;
    const double n0 = p0 - q0, n1 = p1 - q1, n2 = p2 - q2;
    const double m0 = std::fabs(p0) + std::fabs(q0), m1 = std::fabs(p1) + std::fabs(q1),
                 m2 = std::fabs(p2) + std::fabs(q2);
    for (int i = 0; i < 3; ++i) {
        const double wx = double(d[i][0]) - double(a[0]), wy = double(d[i][1]) - double(a[1]),
                     wz = double(d[i][2]) - double(a[2]);
        const double det = n0 * wx + n1 * wy + n2 * wz;
        const double permanent = m0 * std::fabs(wx) + m1 * std::fabs(wy) + m2 * std::fabs(wz);
        if constexpr (std::is_same_v<T, float>) {
            const double bound = exact::orient3d_bound * permanent;
            out[i] = det > bound    ? 1
                     : -det > bound ? -1
                     : !std::isfinite(bound)
                         ? 0  // a NaN or infinite input
                         : exact::orient3d_exact(Vec<double, 3>(a), Vec<double, 3>(b),
                                                 Vec<double, 3>(c), Vec<double, 3>(d[i]));
        } else {
            const double bound =
                exact::orient3d_bound * permanent +
                exact::orient3d_underflow * (std::fabs(wx) + std::fabs(wy) + std::fabs(wz) + 1);
            out[i] = det > bound    ? 1
                     : -det > bound ? -1
                                    : exact::orient3d_any(Vec<double, 3>(a), Vec<double, 3>(b),
                                                          Vec<double, 3>(c), Vec<double, 3>(d[i]));
        }
    }
}

}  // namespace bvhkit
