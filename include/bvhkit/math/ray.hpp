#pragma once
// Ray<T, N> and the ray-box slab test.
//
// The slab test follows Ize 2013, "Robust BVH Ray Traversal": the reciprocal direction is the plain
// IEEE 1/d, so a +0 or -0 component gives +inf or -inf, and a plane distance (b - o) * inv that is
// 0 * inf (the origin exactly on a slab plane of an axis the ray does not move along) comes out
// NaN. Every min/max below is written `a < b ? a : b` with the fresh value first, which discards a
// NaN operand, so such a plane simply does not restrict the interval: a ray lying in a box face
// hits the box, as the closed-box rule wants, and no NaN ever reaches the result. The far distance
// is scaled by 1 + 2 gamma(3) so that rounding never makes a true hit miss (the test is
// conservative).
#include <limits>
#include <type_traits>
#include <utility>

#include "bvhkit/math/aabb.hpp"

namespace bvhkit {

/// gamma(n) = n eps / (1 - n eps), the rounding bound of Pharr, Jakob, Humphreys (PBRT 3, 3.9).
template <class T>
constexpr T rounding_gamma(int n) {
    constexpr T eps = std::numeric_limits<T>::epsilon() * T(0.5);
    return (T(n) * eps) / (T(1) - T(n) * eps);
}

template <class T, std::size_t N>
struct Ray {
    using Scalar = T;
    using VecT = Vec<T, N>;
    static constexpr std::size_t dimension = N;

    VecT origin;
    VecT direction;
    T tmin = T(0);
    T tmax = std::numeric_limits<T>::infinity();

    constexpr Ray() = default;
    constexpr Ray(const VecT& o, const VecT& d, T t0 = T(0),
                  T t1 = std::numeric_limits<T>::infinity())
        : origin(o), direction(d), tmin(t0), tmax(t1) {}

    constexpr VecT at(T t) const { return origin + direction * t; }
};

/// Whether a ray can be traced: a finite origin, a finite direction that is not zero, and an
/// interval with tmin <= tmax (neither NaN). Every ray query gives any other ray a miss at once,
/// without visiting a node: a NaN would otherwise pass every box test (see below) and walk the
/// whole tree.
template <class T, std::size_t N>
bool is_traceable(const Ray<T, N>& ray) {
    bool finite = ray.tmin <= ray.tmax, moves = false;
    for (std::size_t i = 0; i < N; ++i) {
        finite = finite && std::isfinite(ray.origin[i]) && std::isfinite(ray.direction[i]);
        moves = moves || ray.direction[i] != T(0);
    }
    return finite && moves;
}

/// Per-ray values the slab test reuses for every box: reciprocal direction and the ray's octant,
/// bit i set when the ray goes towards negative values on axis i (then the box's max is the near
/// plane). -0 counts as negative, so that its -inf reciprocal meets the planes in the right order.
template <class T, std::size_t N>
struct RaySlabData {
    Vec<T, N> origin;
    Vec<T, N> inv_direction;
    unsigned octant = 0;

    explicit RaySlabData(const Ray<T, N>& ray) : origin(ray.origin) {
        for (std::size_t i = 0; i < N; ++i) {
            const T d = ray.direction[i];
            inv_direction[i] = T(1) / d;
            // A subnormal d has no finite reciprocal; as +-inf it would place the planes of this
            // axis wrongly (a box reached at t = 7 would seem reached at inf). NaN makes every
            // plane distance NaN, which the test drops: the axis then does not restrict the
            // interval, which is conservative.
            if (d != T(0) && !std::isfinite(inv_direction[i]))
                inv_direction[i] = std::numeric_limits<T>::quiet_NaN();
            if (std::signbit(d)) octant |= 1u << i;
        }
    }

    /// Clips [tmin, tmax] to the box; true on a hit, and then tmin is the entry distance. `Octant`
    /// is this ray's octant, known at compile time so the near/far planes cost nothing to choose.
    template <unsigned Octant>
    bool clip(const Aabb<T, N>& box, T& tmin, T& tmax) const {
        constexpr T far_scale = T(1) + T(2) * rounding_gamma<T>(3);
        for (std::size_t i = 0; i < N; ++i) {
            constexpr unsigned one = 1;
            const bool negative = (Octant >> i) & one;
            const T t_near = ((negative ? box.max[i] : box.min[i]) - origin[i]) * inv_direction[i];
            const T t_far =
                ((negative ? box.min[i] : box.max[i]) - origin[i]) * inv_direction[i] * far_scale;
            tmin = t_near > tmin ? t_near : tmin;  // a NaN t_near leaves tmin as it was
            tmax = t_far < tmax ? t_far : tmax;
        }
        return tmin <= tmax;
    }

    /// The same with the octant chosen at run time.
    bool clip(const Aabb<T, N>& box, T& tmin, T& tmax) const {
        return with_octant([&](auto o) { return clip<decltype(o)::value>(box, tmin, tmax); });
    }

    /// Calls f(std::integral_constant<unsigned, octant>{}): one instantiation of f per octant.
    template <class F>
    decltype(auto) with_octant(F&& f) const {
        return dispatch(f, std::make_integer_sequence<unsigned, (1u << N)>{});
    }

  private:
    template <class F, unsigned... O>
    decltype(auto) dispatch(F& f, std::integer_sequence<unsigned, O...>) const {
        using R = decltype(f(std::integral_constant<unsigned, 0>{}));
        if constexpr (std::is_void_v<R>) {
            (void)((octant == O ? (f(std::integral_constant<unsigned, O>{}), true) : false) || ...);
        } else {
            R r{};
            (void)((octant == O ? (r = f(std::integral_constant<unsigned, O>{}), true) : false) ||
                   ...);
            return r;
        }
    }
};

/// Entry and exit distances of a ray through a box (both inside [ray.tmin, ray.tmax]), if it hits.
template <class T, std::size_t N>
bool intersect(const Ray<T, N>& ray, const Aabb<T, N>& box, T& t_entry, T& t_exit) {
    t_entry = ray.tmin;
    t_exit = ray.tmax;
    return RaySlabData<T, N>(ray).clip(box, t_entry, t_exit);
}

using Ray2f = Ray<float, 2>;
using Ray3f = Ray<float, 3>;
using Ray2d = Ray<double, 2>;
using Ray3d = Ray<double, 3>;

}  // namespace bvhkit
