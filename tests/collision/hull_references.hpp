#pragma once
// References for the convex-hull tests that share none of the code's arithmetic: exact support
// comparisons (floating-point expansions), long-double point-triangle distances, exact
// point-in-tetrahedron and facet-plane bounds; and the hard point sets the tests use.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "bvhkit/math/predicates.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/volumes/convex_hull.hpp"

namespace bvhkit::test {

using Points = std::vector<Vec3f>;

/// Sign of d.p - d.q, exactly: each term d_i (p_i - q_i) as a floating-point expansion.
inline int compare_along(const Vec3d& d, const Vec3f& p, const Vec3f& q) {
    exact::Expansion<4> t[3];
    for (int i = 0; i < 3; ++i) exact::scale(exact::difference(p[i], q[i]), d[i], t[i]);
    exact::Expansion<8> two;
    exact::sum(t[0], t[1], two);
    exact::Expansion<12> all;
    exact::sum(two, t[2], all);
    return exact::sign(all);
}

/// Every direction's extreme point of the whole set is matched by a hull vertex, exactly.
inline void expect_supports_match(const Points& sorted, const std::vector<std::uint32_t>& hull,
                                  SplitMix64& rng, const char* what) {
    ASSERT_FALSE(hull.empty()) << what;
    for (int k = 0; k < 200; ++k) {
        Vec3d d;
        for (int i = 0; i < 3; ++i) d[i] = rng.uniform(-1, 1);
        if (k < 6) {  // the axes first
            d = Vec3d(0.0);
            d[k % 3] = k < 3 ? 1 : -1;
        }
        Vec3f all = sorted[0], kept = sorted[hull[0]];
        for (const Vec3f& p : sorted)
            if (compare_along(d, p, all) > 0) all = p;
        for (std::uint32_t i : hull)
            if (compare_along(d, sorted[i], kept) > 0) kept = sorted[i];
        ASSERT_EQ(compare_along(d, all, kept), 0) << what << ": direction " << k;
    }
}

inline Points sorted_unique(Points p) {
    return hull_detail::sorted_unique(std::move(p));
}

inline Points cube_grid(int n, Vec3f origin, float step) {
    Points p;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            for (int k = 0; k < n; ++k)
                p.push_back(origin + Vec3f(float(i), float(j), float(k)) * step);
    return p;
}

/// Distance from p to triangle (a, b, c) in long double, by the plane when p projects inside and
/// by the three edges otherwise.
inline long double point_triangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    using L = long double;
    auto seg = [&](const Vec3d& s, const Vec3d& e) {
        L t = 0, len2 = 0;
        for (int i = 0; i < 3; ++i) {
            t += (L(p[i]) - s[i]) * (L(e[i]) - s[i]);
            len2 += (L(e[i]) - s[i]) * (L(e[i]) - s[i]);
        }
        t = len2 > 0 ? std::clamp(t / len2, L(0), L(1)) : L(0);
        L d2 = 0;
        for (int i = 0; i < 3; ++i) {
            const L x = L(s[i]) + t * (L(e[i]) - s[i]) - p[i];
            d2 += x * x;
        }
        return std::sqrt(d2);
    };
    L best = std::min({seg(a, b), seg(b, c), seg(c, a)});
    L ab[3], ac[3], ap[3], n[3];
    for (int i = 0; i < 3; ++i) {
        ab[i] = L(b[i]) - a[i];
        ac[i] = L(c[i]) - a[i];
        ap[i] = L(p[i]) - a[i];
    }
    n[0] = ab[1] * ac[2] - ab[2] * ac[1];
    n[1] = ab[2] * ac[0] - ab[0] * ac[2];
    n[2] = ab[0] * ac[1] - ab[1] * ac[0];
    const L n2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (n2 > 0) {
        // Barycentrics of the projection, by the sub-triangle normals.
        auto side = [&](const L* e0, const L* e1) {
            const L m[3] = {e0[1] * e1[2] - e0[2] * e1[1], e0[2] * e1[0] - e0[0] * e1[2],
                            e0[0] * e1[1] - e0[1] * e1[0]};
            return m[0] * n[0] + m[1] * n[1] + m[2] * n[2];
        };
        L bp[3], bc[3], cp[3], ca[3];
        for (int i = 0; i < 3; ++i) {
            bp[i] = L(p[i]) - b[i];
            bc[i] = L(c[i]) - b[i];
            cp[i] = L(p[i]) - c[i];
            ca[i] = L(a[i]) - c[i];
        }
        if (side(ab, ap) >= 0 && side(bc, bp) >= 0 && side(ca, cp) >= 0)
            best = std::min(best,
                            std::fabs(ap[0] * n[0] + ap[1] * n[1] + ap[2] * n[2]) / std::sqrt(n2));
    }
    return best;
}

/// p lies in the hull of s when it lies in a tetrahedron of four of its points (Caratheodory),
/// decided by exact orientations.
inline bool inside_some_tetrahedron(const Vec3d& p, const std::vector<Vec3d>& s) {
    const std::size_t n = s.size();
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j)
            for (std::size_t k = j + 1; k < n; ++k)
                for (std::size_t l = k + 1; l < n; ++l) {
                    const Vec3d c[4] = {s[i], s[j], s[k], s[l]};
                    const int whole = orient3d_sign(c[0], c[1], c[2], c[3]);
                    if (whole == 0) continue;
                    bool in = true;
                    for (int f = 0; f < 4 && in; ++f) {
                        Vec3d q[4] = {c[0], c[1], c[2], c[3]};
                        q[f] = p;  // p in place of one corner: same orientation or flat
                        const int o = orient3d_sign(q[0], q[1], q[2], q[3]);
                        in = o == 0 || o == whole;
                    }
                    if (in) return true;
                }
    return false;
}

/// A lower bound of the distance from p to conv(s): the largest signed distance to a plane of a
/// facet of conv(s) (facets found exactly; the plane's distance in long double, less a bound on
/// its rounding).
template <class T>
inline long double facet_distance_lower_bound(const Vec<T, 3>& p, std::span<const Vec<T, 3>> s) {
    using L = long double;
    using VL = Vec<L, 3>;
    auto to_l = [](const Vec<T, 3>& x) { return VL(L(x[0]), L(x[1]), L(x[2])); };
    L best = 0;
    for (std::size_t i = 0; i < s.size(); ++i)
        for (std::size_t j = i + 1; j < s.size(); ++j)
            for (std::size_t k = j + 1; k < s.size(); ++k) {
                int above = 0, below = 0;
                for (const auto& x : s) {
                    const int o = orient3d_sign(s[i], s[j], s[k], x);
                    above += o > 0;
                    below += o < 0;
                }
                if (above && below) continue;
                const VL e1 = to_l(s[j]) - to_l(s[i]), e2 = to_l(s[k]) - to_l(s[i]);
                const VL dp = to_l(p) - to_l(s[i]), n = cross(e1, e2);
                const L len = length(n);
                if (!(len > 0)) continue;
                const L err =
                    8e-19L * length(e1) * length(e2) * length(dp) / len + 8e-19L * length(dp);
                L h = dot(n, dp) / len;
                h = !above && !below ? std::fabs(h) : above ? -h : h;
                best = std::max(best, h - err);
            }
    return best;
}

}  // namespace bvhkit::test
