#pragma once
// What a ray query reports: the distance t along the ray, the primitive, and barycentric
// coordinates (u, v) of the hit point, which is (1 - u - v) p0 + u p1 + v p2 for a triangle (p0,
// p1, p2).
#include <cstdint>
#include <limits>

namespace bvhkit {

inline constexpr std::uint32_t invalid_index = 0xFFFFFFFFu;

template <class T>
struct Hit {
    T t = std::numeric_limits<T>::infinity();
    std::uint32_t primitive = invalid_index;
    T u = 0, v = 0;

    constexpr explicit operator bool() const { return primitive != invalid_index; }
};

}  // namespace bvhkit
