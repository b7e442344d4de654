#pragma once
// Exact orientation predicates: the sign of a 2x2 or 3x3 determinant of coordinate differences,
// decided without error for float and double input. A double evaluation decides when its value
// exceeds a proved bound on its rounding error (the filter of Shewchuk 1997, "Adaptive precision
// floating-point arithmetic and fast robust geometric predicates", bounds A); otherwise the
// determinant is evaluated exactly as a floating-point expansion (same paper: sums and products of
// doubles kept as lists of non-overlapping doubles) and the sign is read off its largest term.
//
// Range: float input is exact for every finite coordinate (converted to double, differences are
// below 2^129 and products of three below 2^390; the smallest product error term is above 2^-600,
// so nothing overflows or underflows). Double input is exact while every coordinate difference is
// zero or of magnitude in [2^-300, 2^300] (nothing overflows, no error term underflows).
// Outside the range, a NaN or infinite coordinate, or products that overflow, the sign is 0: a
// defined answer where no exact one exists (the expansions must never see a NaN or an infinity).
#include <array>
#include <cmath>
#include <cstddef>

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

}  // namespace bvhkit::exact

namespace bvhkit {

/// Sign of (b - a) x (c - a) in the plane: +1 when a, b, c turn counterclockwise, 0 when they
/// are collinear, -1 otherwise. Exact (the header's range).
inline int orient2d_sign(double ax, double ay, double bx, double by, double cx, double cy) {
    const double l = (bx - ax) * (cy - ay), r = (by - ay) * (cx - ax);
    const double det = l - r;
    const double bound = exact::orient2d_bound * (std::fabs(l) + std::fabs(r));
    if (det > bound) return 1;
    if (-det > bound) return -1;
    if (!std::isfinite(bound)) return 0;  // a NaN or infinite input, or an overflow
    return exact::orient2d_exact(ax, ay, bx, by, cx, cy);
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
    const double bound = exact::orient3d_bound * permanent;
    if (det > bound) return 1;
    if (-det > bound) return -1;
    if (!std::isfinite(bound)) return 0;  // a NaN or infinite input, or an overflow
    return exact::orient3d_exact(Vec<double, 3>(a), Vec<double, 3>(b), Vec<double, 3>(c),
                                 Vec<double, 3>(d));
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
        const double bound =
            exact::orient3d_bound * (m0 * std::fabs(wx) + m1 * std::fabs(wy) + m2 * std::fabs(wz));
        out[i] = det > bound    ? 1
                 : -det > bound ? -1
                 : !std::isfinite(bound)
                     ? 0  // a NaN or infinite input, or an overflow
                     : exact::orient3d_exact(Vec<double, 3>(a), Vec<double, 3>(b),
                                             Vec<double, 3>(c), Vec<double, 3>(d[i]));
    }
}

}  // namespace bvhkit
