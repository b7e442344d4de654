#pragma once
// An independent reference for ray-triangle decisions: long double triple products with a proved
// error bound, not the code's sheared edge functions. For a ray o + t d and a triangle (p0, p1, p2)
// with a_i = p_i - o, the ray meets the triangle when E0 = d.(a1 x a2), E1 = d.(a2 x a0) and
// E2 = d.(a0 x a1) share a sign, and then t = det(a0, a1, a2) / (E0 + E1 + E2).
//
// Each E_i computed in long double is within gamma(10) * P_i of its exact value, where P_i is the
// same sum of products taken in absolute values (Higham 2002, 3.1: the subtraction a_i = p_i - o,
// the cross product and the dot product each add at most a few roundings of unit u). The code under
// test decides exactly on sheared coordinates that carry rounding errors of a few ulps of T
// (Woop et al. 2013): that is as if each vertex moved by up to c eps_T |a|_inf across the ray,
// which moves E_i by up to `code_margin`. Inside that band either answer is accepted ("ambiguous");
// outside it the code must agree with the reference.
#include <algorithm>
#include <cmath>
#include <limits>

#include "bvhkit/math/ray.hpp"
#include "bvhkit/primitives/triangle.hpp"

namespace bvhkit::test {

enum class RefClass { Hit, Miss, Ambiguous };

struct RefResult {
    RefClass cls = RefClass::Miss;
    long double t = 0;      // when E0 + E1 + E2 != 0
    long double t_tol = 0;  // allowed |t_code - t| for the code's rounding
};

template <class T>
RefResult reference_intersect(const Ray<T, 3>& ray, const Triangle<T>& tri) {
    using L = long double;
    constexpr L u = std::numeric_limits<L>::epsilon() / 2;
    constexpr L gamma10 = 10 * u / (1 - 10 * u);
    // The code's stated bound (docs/rays.md): edge functions as if each vertex moved by 8 eps_T
    // times its largest coordinate relative to the origin; the factor 64 covers the products.
    constexpr L code_eps = 64 * L(std::numeric_limits<T>::epsilon());
    const Vec<T, 3>* p[3] = {&tri.p0, &tri.p1, &tri.p2};
    L a[3][3], d[3], amax[3];
    L dmax = 0;
    for (int k = 0; k < 3; ++k) {
        d[k] = L(ray.direction[k]);
        dmax = std::max(dmax, std::fabs(d[k]));
    }
    for (int i = 0; i < 3; ++i) {
        amax[i] = 0;
        for (int k = 0; k < 3; ++k) {
            a[i][k] = L((*p[i])[k]) - L(ray.origin[k]);
            amax[i] = std::max(amax[i], std::fabs(a[i][k]));
        }
    }
    // E_i = d . (a_j x a_k) and its absolute-value twin P_i.
    L e[3], margin[3];
    for (int i = 0; i < 3; ++i) {
        const L* x = a[(i + 1) % 3];
        const L* y = a[(i + 2) % 3];
        L sum = 0, abs_sum = 0;
        for (int k = 0; k < 3; ++k) {
            const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
            sum += d[k] * (x[k1] * y[k2] - x[k2] * y[k1]);
            abs_sum += std::fabs(d[k]) * (std::fabs(x[k1] * y[k2]) + std::fabs(x[k2] * y[k1]));
        }
        e[i] = sum;
        margin[i] = gamma10 * abs_sum * (1 + gamma10) +
                    code_eps * dmax * amax[(i + 1) % 3] * amax[(i + 2) % 3];
    }
    RefResult r;
    bool neg = false, pos = false, unsure = false;
    for (int i = 0; i < 3; ++i) {
        if (e[i] > margin[i])
            pos = true;
        else if (e[i] < -margin[i])
            neg = true;
        else
            unsure = true;
    }
    if (pos && neg) return r;  // certainly outside one edge line and inside another: a miss
    const L den = e[0] + e[1] + e[2];
    if (den == 0) {
        r.cls = RefClass::Ambiguous;  // degenerate or in the plane: the code misses or grazes
        r.t = std::numeric_limits<L>::infinity();
        return r;
    }
    const L num = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                  a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                  a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    r.t = num / den;
    // Moving the vertices by delta = code_eps |a|_inf moves the plane by delta and turns it by up
    // to 4 delta l / |n| (l the longest edge) about a point at most l from the hit point; along the
    // ray that is |dt| <= delta (|n| + 4 l^2) / |d . n| (d . n = den).
    L n[3], e1[3], e2[3];
    for (int k = 0; k < 3; ++k) e1[k] = a[1][k] - a[0][k], e2[k] = a[2][k] - a[0][k];
    for (int k = 0; k < 3; ++k)
        n[k] = e1[(k + 1) % 3] * e2[(k + 2) % 3] - e1[(k + 2) % 3] * e2[(k + 1) % 3];
    const L n_length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const L amax_all = std::max({amax[0], amax[1], amax[2]});
    L l2 = 0;
    for (int i = 0; i < 3; ++i) {
        L s2 = 0;
        for (int k = 0; k < 3; ++k)
            s2 += (a[(i + 1) % 3][k] - a[i][k]) * (a[(i + 1) % 3][k] - a[i][k]);
        l2 = std::max(l2, s2);
    }
    r.t_tol = code_eps * (std::fabs(r.t) + amax_all * (n_length + 4 * l2) / std::fabs(den));
    const bool in_range = r.t >= L(ray.tmin) + r.t_tol && r.t <= L(ray.tmax) - r.t_tol;
    const bool out_range = r.t < L(ray.tmin) - r.t_tol || r.t > L(ray.tmax) + r.t_tol;
    if (out_range) return r;
    r.cls = (unsure || !in_range) ? RefClass::Ambiguous : RefClass::Hit;
    return r;
}

}  // namespace bvhkit::test
