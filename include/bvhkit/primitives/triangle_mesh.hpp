#pragma once
// TriangleMesh: shared vertices and index triples, the form mesh files arrive in. A triangle's
// index is its position in `triangles` (for files: after polygons are split into fans, in file
// order).
#include <array>
#include <cstdint>
#include <vector>

#include "bvhkit/math/aabb.hpp"

namespace bvhkit {

template <class T>
struct BasicTriangleMesh {
    std::vector<Vec<T, 3>> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;

    std::size_t triangle_count() const { return triangles.size(); }
    Aabb<T, 3> bounds() const {
        Aabb<T, 3> b;
        for (const auto& v : vertices) b.grow(v);
        return b;
    }
};

using TriangleMesh = BasicTriangleMesh<float>;

}  // namespace bvhkit
