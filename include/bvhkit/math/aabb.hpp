#pragma once
// Aabb<T, N>: an axis-aligned box, min and max corners. The empty box has min = +inf, max = -inf so
// that growing it by anything gives that thing; all of its measures (extent, area) are zero.
#include "bvhkit/math/vec.hpp"

namespace bvhkit {

template <class T, std::size_t N>
struct Aabb {
    using Scalar = T;
    using VecT = Vec<T, N>;
    static constexpr std::size_t dimension = N;

    VecT min{std::numeric_limits<T>::infinity()};
    VecT max{-std::numeric_limits<T>::infinity()};

    constexpr Aabb() = default;
    constexpr Aabb(const VecT& lo, const VecT& hi) : min(lo), max(hi) {}
    static constexpr Aabb empty() { return {}; }
    static constexpr Aabb from_point(const VecT& p) { return {p, p}; }

    constexpr bool is_empty() const {
        for (std::size_t i = 0; i < N; ++i)
            if (!(min[i] <= max[i])) return true;
        return false;
    }
    constexpr Aabb& grow(const VecT& p) {
        min = bvhkit::min(min, p);
        max = bvhkit::max(max, p);
        return *this;
    }
    constexpr Aabb& grow(const Aabb& b) {
        min = bvhkit::min(min, b.min);
        max = bvhkit::max(max, b.max);
        return *this;
    }
    /// Extent per axis, zero for an empty box.
    constexpr VecT extent() const { return bvhkit::max(max - min, VecT(T(0))); }
    constexpr VecT centroid() const { return (min + max) * T(0.5); }
    constexpr std::size_t largest_axis() const { return bvhkit::largest_axis(extent()); }

    /// The SAH measure: surface area in 3D, perimeter in 2D (the SAH's "SA" term); 0 when empty.
    constexpr T area() const {
        const VecT e = extent();
        if constexpr (N == 2) {
            return T(2) * (e[0] + e[1]);
        } else if constexpr (N == 3) {
            return T(2) * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]);
        } else {
            static_assert(N == 2 || N == 3, "area() is defined for 2D and 3D boxes");
        }
    }

    /// Closed-interval overlap: boxes that touch overlap.
    constexpr bool overlaps(const Aabb& b) const {
        for (std::size_t i = 0; i < N; ++i)
            if (min[i] > b.max[i] || b.min[i] > max[i]) return false;
        return true;
    }
    constexpr bool contains(const VecT& p) const {
        for (std::size_t i = 0; i < N; ++i)
            if (!(p[i] >= min[i] && p[i] <= max[i])) return false;
        return true;
    }
    constexpr bool contains(const Aabb& b) const {
        for (std::size_t i = 0; i < N; ++i)
            if (!(b.min[i] >= min[i] && b.max[i] <= max[i])) return false;
        return true;
    }
    /// Squared distance from p to the box (0 inside).
    constexpr T distance_squared(const VecT& p) const {
        T d = 0;
        for (std::size_t i = 0; i < N; ++i) {
            const T below = min[i] - p[i], above = p[i] - max[i];
            const T g = below > above ? below : above;
            if (g > 0) d += g * g;
        }
        return d;
    }
    bool is_finite() const { return bvhkit::is_finite(min) && bvhkit::is_finite(max); }

    /// The box of some points; if any point has a NaN or infinite coordinate the box is marked
    /// non-finite (grow() alone would let a NaN slip away, as min/max ignore one NaN operand).
    template <class... P>
    static Aabb of_points(const P&... points) {
        Aabb b;
        (b.grow(points), ...);
        if (!(bvhkit::is_finite(points) && ...)) b.min[0] = std::numeric_limits<T>::quiet_NaN();
        return b;
    }

    friend constexpr bool operator==(const Aabb&, const Aabb&) = default;
};

template <class T, std::size_t N>
constexpr Aabb<T, N> unite(const Aabb<T, N>& a, const Aabb<T, N>& b) {
    return {min(a.min, b.min), max(a.max, b.max)};
}
template <class T, std::size_t N>
constexpr Aabb<T, N> intersect(const Aabb<T, N>& a, const Aabb<T, N>& b) {
    return {max(a.min, b.min), min(a.max, b.max)};
}

using Aabb2f = Aabb<float, 2>;
using Aabb3f = Aabb<float, 3>;
using Aabb2d = Aabb<double, 2>;
using Aabb3d = Aabb<double, 3>;

}  // namespace bvhkit
