#pragma once
// TrianglePack4<T>: four triangles side by side (one array per corner and axis), and the squared
// distance from a point to all four at once: for float on x86 in SSE, with no data-dependent
// jumps; elsewhere lane by lane from the same code. A best-first nearest query tests most
// triangles only to reject them, and the branchy closest-point code (Ericson, primitives/
// closest_point.hpp) mispredicted on most of them; here a leaf's triangles cost one pass.
//
// The distance is the least of the three edges' (each the segment's closest point, clamped) and,
// when the point's projection on the plane falls inside, the distance to the plane. A misjudged
// "inside" near an edge is what rounding costs most: judged inside, the plane distance is a
// lower bound (harmless); judged outside, the edge's distance is returned, larger by up to the
// point's distance from the edge, which for a point near the plane is first order in the
// inside test's error. That error grows as 1/sin^2 of the angle at p0 near the edge p1-p2, so
// thin triangles (slivers) are flagged in `exact_lanes` for the caller to measure exactly, and
// the rest stay well within the caller's slack (see ClosestPointMesh::widened).
#include <cstdint>

#include "bvhkit/math/select.hpp"
#include "bvhkit/primitives/triangle.hpp"
#include "bvhkit/simd/simd.hpp"

namespace bvhkit {

namespace pack_detail {

using bvhkit::min_of;

template <class T>
inline T select(bool m, T a, T b) {
    return m ? a : b;
}
/// n / d clamped to [0, 1]; 0 when d is 0 (a segment of zero length).
template <class T>
inline T ratio01(T n, T d) {
    return n > T(0) ? (n < d ? n / d : T(1)) : T(0);
}

#if BVHKIT_SIMD
/// Four float lanes, so the distance below is written once for SSE and scalars (the SIMD layer's
/// operators, compares and select, and these).
using F4 = simd::Float<4>;
// As std::min / std::max: (b < a ? b : a), minps giving its first operand when the test holds.
inline F4 min_of(F4 a, F4 b) {
    return min(b, a);
}
inline F4 ratio01(F4 n, F4 d) {
    // 0 / 0 is NaN, and maxps gives its second operand (0 here) when the first is NaN.
    return min(max(n / d, F4::zero()), F4(1.0f));
}
#endif

/// What the distance below needs of a triangle alone, apart from its corners a and b: edges,
/// their products and the normal. The pack keeps them, so that a query computes only what
/// depends on the point (a third of the work it did from the corners alone).
template <class L>
struct TriangleTerms {
    L ab[3], ac[3], bc[3], n[3];
    L aa, cc, ac_ab, bc_bc, det, nn;
};

template <class L>
inline L dot3(const L* x, const L* y) {
    return x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
}

/// The terms of the triangle (a, b, c), each lane its own triangle.
template <class L>
inline TriangleTerms<L> triangle_terms(const L a[3], const L b[3], const L c[3]) {
    TriangleTerms<L> k;
    for (int i = 0; i < 3; ++i) k.ab[i] = b[i] - a[i], k.ac[i] = c[i] - a[i], k.bc[i] = c[i] - b[i];
    k.aa = dot3(k.ab, k.ab), k.cc = dot3(k.ac, k.ac), k.ac_ab = dot3(k.ab, k.ac);
    k.bc_bc = dot3(k.bc, k.bc);
    k.det = k.aa * k.cc - k.ac_ab * k.ac_ab;
    for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3, m = (i + 2) % 3;
        k.n[i] = k.ab[j] * k.ac[m] - k.ab[m] * k.ac[j];
    }
    k.nn = dot3(k.n, k.n);
    return k;
}

/// Squared distance from p to the triangle with corners a, b and terms k, each lane its own
/// triangle.
template <class L>
inline L triangle_distance_squared(const L a[3], const L b[3], const TriangleTerms<L>& k,
                                   const L p[3]) {
    L ap[3], bp[3];
    for (int i = 0; i < 3; ++i) ap[i] = p[i] - a[i], bp[i] = p[i] - b[i];
    const L d1 = dot3(k.ab, ap), d2 = dot3(k.ac, ap);
    // The closest point of the segment from `from` along `edge`, at (p - from) = `rel`.
    const auto segment = [&](const L* rel, const L* edge, L along, L length2) {
        const L t = ratio01(along, length2);
        L s = L(0);
        for (int i = 0; i < 3; ++i) {
            const L q = rel[i] - t * edge[i];
            s = s + q * q;
        }
        return s;
    };
    const L edges = min_of(min_of(segment(ap, k.ab, d1, k.aa), segment(ap, k.ac, d2, k.cc)),
                           segment(bp, k.bc, dot3(k.bc, bp), k.bc_bc));
    // The projection's barycentrics, times det (Cramer's rule on the 2x2 normal equations).
    const L u = k.cc * d1 - k.ac_ab * d2, v = k.aa * d2 - k.ac_ab * d1;
    const auto inside = (k.det > L(0)) & (u >= L(0)) & (v >= L(0)) & (u + v <= k.det);
    const L h = dot3(k.n, ap);
    const L plane = h * (h / k.nn);  // h * h could overflow where the quotient does not
    return select(inside, min_of(edges, plane), edges);
}

}  // namespace pack_detail

template <class T>
struct alignas(16) TrianglePack4 {
    T corner[3][3][4];  // corner[vertex][axis][lane]
    // pack_detail::TriangleTerms of each lane, made by set(): the edges ab, ac, bc and the normal
    // n (vector[0..11][lane]: ab x, y, z, ac, bc, n), then aa, cc, ac_ab, bc_bc, det, nn.
    T vector[12][4];
    T scalar[6][4];
    std::uint32_t slot[4];  // the caller's index of each lane's triangle; invalid_index: empty
    std::uint32_t exact_lanes = 0;  // bit per lane: to be measured exactly by the caller (set())

    TrianglePack4() {
        for (auto& v : corner)
            for (auto& a : v)
                for (T& x : a) x = T(0);
        for (auto& v : vector)
            for (T& x : v) x = T(0);
        for (auto& v : scalar)
            for (T& x : v) x = T(0);
        for (auto& s : slot) s = invalid_index;
    }

    void set(int lane, const Triangle<T>& t, std::uint32_t s) {
        const Vec<T, 3>* v[3] = {&t.p0, &t.p1, &t.p2};
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a) corner[k][a][lane] = (*v[k])[a];
        slot[lane] = s;
        const T c0[3] = {t.p0[0], t.p0[1], t.p0[2]}, c1[3] = {t.p1[0], t.p1[1], t.p1[2]},
                c2[3] = {t.p2[0], t.p2[1], t.p2[2]};
        const pack_detail::TriangleTerms<T> terms = pack_detail::triangle_terms<T>(c0, c1, c2);
        for (int a = 0; a < 3; ++a) {
            vector[a][lane] = terms.ab[a], vector[3 + a][lane] = terms.ac[a];
            vector[6 + a][lane] = terms.bc[a], vector[9 + a][lane] = terms.n[a];
        }
        const T scalars[6] = {terms.aa, terms.cc, terms.ac_ab, terms.bc_bc, terms.det, terms.nn};
        for (int i = 0; i < 6; ++i) scalar[i][lane] = scalars[i];
        // Measured exactly by the caller: a sliver (sin^2 of its angle at p0 below 1e-2: the
        // inside test's rounding grows as 1/sin^2 near the edge p1-p2, past the caller's slack
        // below 1e-3; 0.02% of igea's triangles, 0.08% of the dragon's are flagged), and a
        // triangle whose products of four lengths (det below) would near T's overflow or
        // denormals. Measured in double.
        const Vec<double, 3> p0(t.p0), ab = Vec<double, 3>(t.p1) - p0,
                                       ac = Vec<double, 3>(t.p2) - p0;
        const double aa = dot(ab, ab), cc = dot(ac, ac), m = dot(ab, ac);
        const double low = double(std::numeric_limits<T>::min()) * 1e8;
        const double high = double(std::numeric_limits<T>::max()) * 1e-8;
        const bool sliver = !(aa * cc - m * m > 1e-2 * aa * cc);
        const bool out_of_range = !(aa * cc >= low && aa * cc <= high);
        if (sliver || out_of_range) exact_lanes |= 1u << lane;
    }

    /// Bit per lane that holds a triangle.
    unsigned used_lanes() const { return 15u & ~lanes_equal(slot, invalid_index); }

    /// Bit per lane: a triangle whose squared distance from p is at most `bound`, or a sliver.
    unsigned lanes_within(const Vec<T, 3>& p, T bound) const {
        T d[4];
        return lanes_within(p, bound, d);
    }
    /// The same, with each lane's squared distance by the pack's formula in `d` (meaningless for
    /// the lanes in exact_lanes).
    unsigned lanes_within(const Vec<T, 3>& p, T bound, T (&d)[4]) const {
        const unsigned used = used_lanes();
#if BVHKIT_SIMD
        if constexpr (std::is_same_v<T, float>) {
            using pack_detail::F4;
            F4 a[3], b[3], q[3];
            pack_detail::TriangleTerms<F4> k;
            for (int i = 0; i < 3; ++i) {
                a[i] = F4::load(corner[0][i]), b[i] = F4::load(corner[1][i]);
                q[i] = F4(p[i]);
                k.ab[i] = F4::load(vector[i]), k.ac[i] = F4::load(vector[3 + i]);
                k.bc[i] = F4::load(vector[6 + i]), k.n[i] = F4::load(vector[9 + i]);
            }
            k.aa = F4::load(scalar[0]), k.cc = F4::load(scalar[1]);
            k.ac_ab = F4::load(scalar[2]), k.bc_bc = F4::load(scalar[3]);
            k.det = F4::load(scalar[4]), k.nn = F4::load(scalar[5]);
            const F4 dist = pack_detail::triangle_distance_squared(a, b, k, q);
            dist.store_unaligned(d);
            const unsigned near = (dist <= F4(bound)).bits();
            return (near | exact_lanes) & used;
        }
#endif
        unsigned near = 0;
        for (int l = 0; l < 4; ++l) {
            d[l] = distance_squared(l, p);
            near |= unsigned(d[l] <= bound) << l;
        }
        return (near | exact_lanes) & used;
    }

    /// One lane's triangle, times `scale`.
    Triangle<T> triangle(int lane, T scale = T(1)) const {
        Triangle<T> t;
        for (int i = 0; i < 3; ++i) {
            t.p0[i] = corner[0][i][lane] * scale;
            t.p1[i] = corner[1][i][lane] * scale;
            t.p2[i] = corner[2][i][lane] * scale;
        }
        return t;
    }

    /// The squared distance of one lane's triangle from p, by the same formula, lane alone.
    T distance_squared(int lane, const Vec<T, 3>& p) const {
        T a[3], b[3], q[3];
        pack_detail::TriangleTerms<T> k;
        for (int i = 0; i < 3; ++i) {
            a[i] = corner[0][i][lane], b[i] = corner[1][i][lane], q[i] = p[i];
            k.ab[i] = vector[i][lane], k.ac[i] = vector[3 + i][lane];
            k.bc[i] = vector[6 + i][lane], k.n[i] = vector[9 + i][lane];
        }
        k.aa = scalar[0][lane], k.cc = scalar[1][lane], k.ac_ab = scalar[2][lane];
        k.bc_bc = scalar[3][lane], k.det = scalar[4][lane], k.nn = scalar[5][lane];
        return pack_detail::triangle_distance_squared(a, b, k, q);
    }
};

}  // namespace bvhkit
