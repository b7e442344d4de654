#pragma once
// TriangleMesh: shared vertices and index triples, the form mesh files arrive in. A triangle's
// index is its position in `triangles` (for files: after polygons are split into fans, in file
// order).
#include <array>
#include <cstdint>
#include <vector>

#include <string>
#include <type_traits>

#include "bvhkit/error.hpp"
#include "bvhkit/math/aabb.hpp"
#include "bvhkit/primitives/triangle.hpp"

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

/// Throws bvhkit::Error naming the first triangle that names a vertex the mesh does not have.
template <class U>
void check_triangle_indices(const BasicTriangleMesh<U>& mesh) {
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
        for (std::uint32_t k : mesh.triangles[i])
            if (k >= mesh.vertices.size())
                throw Error("triangle " + std::to_string(i) + " names vertex " + std::to_string(k) +
                            " of " + std::to_string(mesh.vertices.size()));
}

/// Triangle i of the mesh in scalar type T (indices unchecked: see check_triangle_indices).
template <class T, class U>
Triangle<T> triangle_at(const BasicTriangleMesh<U>& mesh, std::size_t i) {
    const auto& t = mesh.triangles[i];
    return {Vec<T, 3>(mesh.vertices[t[0]]), Vec<T, 3>(mesh.vertices[t[1]]),
            Vec<T, 3>(mesh.vertices[t[2]])};
}

/// Every triangle of the mesh, in order, in scalar type T (the mesh's own by default); throws
/// bvhkit::Error for an index out of range.
template <class T = void, class U>
auto mesh_triangles(const BasicTriangleMesh<U>& mesh) {
    using R = std::conditional_t<std::is_void_v<T>, U, T>;
    check_triangle_indices(mesh);
    std::vector<Triangle<R>> out;
    out.reserve(mesh.triangles.size());
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) out.push_back(triangle_at<R>(mesh, i));
    return out;
}

}  // namespace bvhkit
