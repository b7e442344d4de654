#pragma once
// Exact references under a pose, sharing no arithmetic with the library: B's corners carried into
// A's frame as R x + t in exact integers (support/exact_int.hpp: the file's doubles or floats are
// dyadic rationals, so one common power of two makes every coordinate, entry of R, entry of t and
// product R_ij x_j an integer), then exact_reference.hpp's Caratheodory test.
#include <algorithm>
#include <cmath>
#include <vector>

#include "bvhkit/math/transform.hpp"
#include "collision_support.hpp"
#include "exact_reference.hpp"

namespace bvhkit::test {

/// a's corners and b's carried by `pose`, exactly, as integers at one scale (for
/// exact_integer_triangles_meet).
template <class T>
std::vector<IVec> posed_integers(const Triangle<T>& a, const Triangle<T>& b,
                                 const Transform<T>& pose) {
    const Vec<T, 3> pa[3] = {a.p0, a.p1, a.p2}, pb[3] = {b.p0, b.p1, b.p2};
    int s_a = -100000, s_r = -100000, s_x = -100000;
    for (int k = 0; k < 3; ++k) {
        s_a = std::max(s_a, ExactInt::shift_needed(double(pose.translation[k])));
        for (int i = 0; i < 3; ++i) {
            s_a = std::max(s_a, ExactInt::shift_needed(double(pa[i][k])));
            s_x = std::max(s_x, ExactInt::shift_needed(double(pb[i][k])));
            s_r = std::max(s_r, ExactInt::shift_needed(double(pose.rotation[i][k])));
        }
    }
    // Zero entries need no bits; keep the shifts near the others so that nothing is shifted far.
    if (s_x == -100000) s_x = 0;
    if (s_r == -100000) s_r = 0;
    const int s = std::max(s_a, s_r + s_x);
    std::vector<IVec> out;
    for (int i = 0; i < 3; ++i)
        out.push_back({ExactInt::scaled(double(pa[i][0]), s), ExactInt::scaled(double(pa[i][1]), s),
                       ExactInt::scaled(double(pa[i][2]), s)});
    for (int i = 0; i < 3; ++i) {
        IVec c;
        for (int k = 0; k < 3; ++k) {
            ExactInt v = ExactInt::scaled(double(pose.translation[k]), s);
            for (int j = 0; j < 3; ++j)
                v = v + ExactInt::scaled(double(pose.rotation[k][j]), s_r) *
                            ExactInt::scaled(double(pb[i][j]), s - s_r);
            c[k] = v;
        }
        out.push_back(c);
    }
    return out;
}

/// Whether a meets b carried by `pose`, exactly.
template <class T>
bool exact_posed_meet(const Triangle<T>& a, const Triangle<T>& b, const Transform<T>& pose) {
    return exact_integer_triangles_meet(posed_integers(a, b, pose));
}

/// Every pair (i in a, j in b) that meets with b carried by `pose` exactly. The box prefilter is in
/// long double, widened far beyond its rounding (1e-12 of the coordinates' magnitudes).
template <class T>
PairSet exact_posed_pairs(const std::vector<Triangle<T>>& a, const std::vector<Triangle<T>>& b,
                          const Transform<T>& pose) {
    using L = long double;
    std::vector<Aabb<L, 3>> ba(a.size()), bb(b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        for (const auto& p : {a[i].p0, a[i].p1, a[i].p2}) ba[i].grow(Vec<L, 3>(p));
        const L pad = 1e-12L * max_component(bvhkit::max(ba[i].max, -ba[i].min));
        ba[i].min = ba[i].min - Vec<L, 3>(pad);
        ba[i].max = ba[i].max + Vec<L, 3>(pad);
    }
    for (std::size_t j = 0; j < b.size(); ++j) {
        L size = 0;
        for (const auto& p : {b[j].p0, b[j].p1, b[j].p2}) {
            Vec<L, 3> q;
            for (int k = 0; k < 3; ++k) {
                q[k] = L(pose.translation[k]);
                size = std::max(size, std::fabs(L(pose.translation[k])));
                for (int m = 0; m < 3; ++m) {
                    q[k] += L(pose.rotation[k][m]) * L(p[m]);
                    size = std::max(size, std::fabs(L(pose.rotation[k][m]) * L(p[m])));
                }
            }
            bb[j].grow(q);
        }
        const L pad = 1e-12L * size;
        bb[j].min = bb[j].min - Vec<L, 3>(pad);
        bb[j].max = bb[j].max + Vec<L, 3>(pad);
    }
    PairSet out;
    for_each_box_pair(ba, bb, [&](std::uint32_t i, std::uint32_t j) {
        if (exact_posed_meet(a[i], b[j], pose)) out.insert({i, j});
    });
    return out;
}

}  // namespace bvhkit::test
