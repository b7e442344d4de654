#pragma once
// What a ray query reports: the distance t along the ray, the primitive, barycentric coordinates
// (u, v) of the hit point, which is (1 - u - v) p0 + u p1 + v p2 for a triangle (p0, p1, p2), and
// the geometric normal.
#include <cstdint>
#include <limits>

#include "bvhkit/math/vec.hpp"

namespace bvhkit {

inline constexpr std::uint32_t invalid_index = 0xFFFFFFFFu;

template <class T, std::size_t N = 3>
struct Hit {
    T t = std::numeric_limits<T>::infinity();
    std::uint32_t primitive = invalid_index;
    T u = 0, v = 0;
    /// The geometric normal, not normalized: (p1 - p0) x (p2 - p0) for a triangle (as Embree's Ng),
    /// so it faces the side from which p0, p1, p2 run counterclockwise, whichever side the ray
    /// came from, and its length is twice the triangle's area. Zero for primitives whose ray test
    /// supplies no normal (see query/ray.hpp) and on a miss.
    Vec<T, N> normal{};

    constexpr explicit operator bool() const { return primitive != invalid_index; }
};

}  // namespace bvhkit
