#pragma once
// Indexed triangle meshes: shared vertices and index triples, the form mesh files arrive in. A
// triangle's index is its position in the index list (for files: after polygons are split into
// fans, in file order).
//
// Two types give the same reading interface (vertex_count, triangle_count, vertex(k), triangle(i),
// bounds; the IndexedTriangleMesh concept), and every structure that builds from a mesh takes
// either:
// - BasicTriangleMesh<T> owns its vertices and triples (what the readers and generators return);
// - TriangleMeshView<T, Index> reads the caller's own buffers in place (xyz per vertex, three
//   indices per triangle, any integer type), so a mesh need not be copied to build a tree over it.
#include <array>
#include <concepts>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "bvhkit/error.hpp"
#include "bvhkit/math/aabb.hpp"
#include "bvhkit/primitives/triangle.hpp"

namespace bvhkit {

template <class T>
struct BasicTriangleMesh {
    using Scalar = T;
    std::vector<Vec<T, 3>> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;

    std::size_t vertex_count() const { return vertices.size(); }
    std::size_t triangle_count() const { return triangles.size(); }
    const Vec<T, 3>& vertex(std::size_t k) const { return vertices[k]; }
    const std::array<std::uint32_t, 3>& triangle(std::size_t i) const { return triangles[i]; }
    Aabb<T, 3> bounds() const {
        Aabb<T, 3> b;
        for (const auto& v : vertices) b.grow(v);
        return b;
    }
};

using TriangleMesh = BasicTriangleMesh<float>;

/// A mesh in the caller's buffers, read in place: `vertex_xyz` holds x y z of each vertex
/// (3 * vertex_count scalars), `triangle_ids` three vertex indices per triangle. The buffers must
/// outlive the view and every structure built from it that keeps reading it (the builders copy what
/// they need: a tree built from a view does not refer to it afterwards). Indices are checked by
/// the structures built over it (check_triangle_indices): negative or too large is an Error.
template <class T, class Index = std::uint32_t>
class TriangleMeshView {
    static_assert(std::is_floating_point_v<T> && std::is_integral_v<Index>);

  public:
    using Scalar = T;
    TriangleMeshView() = default;
    TriangleMeshView(const T* vertex_xyz, std::size_t vertex_count, const Index* triangle_ids,
                     std::size_t triangle_count)
        : xyz_(vertex_xyz),
          ids_(triangle_ids),
          vertex_count_(vertex_count),
          triangle_count_(triangle_count) {
        if ((vertex_count && !vertex_xyz) || (triangle_count && !triangle_ids))
            throw Error("TriangleMeshView: a null buffer with a non-zero count");
    }
    /// A view of an owning mesh of the same scalar type.
    explicit TriangleMeshView(
        const BasicTriangleMesh<T>& mesh) requires std::same_as<Index, std::uint32_t>
        : TriangleMeshView(mesh.vertices.empty() ? nullptr : &mesh.vertices[0][0],
                           mesh.vertices.size(),
                           mesh.triangles.empty() ? nullptr : mesh.triangles[0].data(),
                           mesh.triangles.size()) {}

    std::size_t vertex_count() const { return vertex_count_; }
    std::size_t triangle_count() const { return triangle_count_; }
    Vec<T, 3> vertex(std::size_t k) const {
        return {xyz_[3 * k], xyz_[3 * k + 1], xyz_[3 * k + 2]};
    }
    /// The triangle's vertex indices (unchecked: see check_triangle_indices).
    std::array<std::uint32_t, 3> triangle(std::size_t i) const {
        return {std::uint32_t(ids_[3 * i]), std::uint32_t(ids_[3 * i + 1]),
                std::uint32_t(ids_[3 * i + 2])};
    }
    /// The raw index of corner c of triangle i, in the caller's type.
    Index raw_index(std::size_t i, int c) const { return ids_[3 * i + std::size_t(c)]; }
    Aabb<T, 3> bounds() const {
        Aabb<T, 3> b;
        for (std::size_t k = 0; k < vertex_count_; ++k) b.grow(vertex(k));
        return b;
    }

  private:
    const T* xyz_ = nullptr;
    const Index* ids_ = nullptr;
    std::size_t vertex_count_ = 0, triangle_count_ = 0;
};

/// What the structures that build from a mesh read of it.
template <class M>
concept IndexedTriangleMesh = requires(const M& m, std::size_t i) {
    typename M::Scalar;
    { m.vertex_count() } -> std::convertible_to<std::size_t>;
    { m.triangle_count() } -> std::convertible_to<std::size_t>;
    { m.vertex(i) } -> std::convertible_to<Vec<typename M::Scalar, 3>>;
    { m.triangle(i) } -> std::convertible_to<std::array<std::uint32_t, 3>>;
};

/// Throws bvhkit::Error naming the first triangle that names a vertex the mesh does not have
/// (including, for a view with signed indices, a negative one).
template <IndexedTriangleMesh M>
void check_triangle_indices(const M& mesh) {
    const std::size_t n = mesh.vertex_count();
    if (n > std::size_t(std::numeric_limits<std::uint32_t>::max()))
        throw Error("a mesh may have at most 2^32 - 1 vertices, this one has " + std::to_string(n));
    for (std::size_t i = 0; i < mesh.triangle_count(); ++i)
        for (int c = 0; c < 3; ++c) {
            long long k;  // every index type's values fit, but for uint64 above 2^63 (caught too)
            if constexpr (requires { mesh.raw_index(i, c); })
                k = static_cast<long long>(mesh.raw_index(i, c));
            else
                k = static_cast<long long>(mesh.triangle(i)[std::size_t(c)]);
            if (k < 0 || std::uint64_t(k) >= n)
                throw Error("triangle " + std::to_string(i) + " names vertex " + std::to_string(k) +
                            " of " + std::to_string(n));
        }
}

/// Triangle i of the mesh in scalar type T (indices unchecked: see check_triangle_indices).
template <class T, IndexedTriangleMesh M>
Triangle<T> triangle_at(const M& mesh, std::size_t i) {
    const auto t = mesh.triangle(i);
    return {Vec<T, 3>(mesh.vertex(t[0])), Vec<T, 3>(mesh.vertex(t[1])),
            Vec<T, 3>(mesh.vertex(t[2]))};
}

/// Every triangle of the mesh, in order, in scalar type T (the mesh's own by default); throws
/// bvhkit::Error for an index out of range.
template <class T = void, IndexedTriangleMesh M>
auto mesh_triangles(const M& mesh) {
    using R = std::conditional_t<std::is_void_v<T>, typename M::Scalar, T>;
    check_triangle_indices(mesh);
    std::vector<Triangle<R>> out;
    out.reserve(mesh.triangle_count());
    for (std::size_t i = 0; i < mesh.triangle_count(); ++i) out.push_back(triangle_at<R>(mesh, i));
    return out;
}

/// A mesh seen with some triangles left out, every triangle keeping its index: each listed
/// triangle's corners are one extra vertex at NaN, which the builders skip (and which shares no
/// edge with a kept triangle, so it adds nothing to their pseudonormals). For structures rebuilt
/// over the finite triangles of a mesh whose answers must still name the mesh's own faces.
template <class T>
struct MeshWithoutTriangles {
    using Scalar = T;
    const BasicTriangleMesh<T>& mesh;
    std::vector<std::uint8_t> dropped;  // per triangle

    MeshWithoutTriangles(const BasicTriangleMesh<T>& m, std::span<const std::uint32_t> which)
        : mesh(m), dropped(m.triangles.size(), 0) {
        for (const std::uint32_t f : which) dropped[f] = 1;
    }
    std::size_t vertex_count() const { return mesh.vertices.size() + 1; }
    std::size_t triangle_count() const { return mesh.triangles.size(); }
    Vec<T, 3> vertex(std::size_t k) const {
        const T nan = std::numeric_limits<T>::quiet_NaN();
        return k < mesh.vertices.size() ? mesh.vertices[k] : Vec<T, 3>{nan, nan, nan};
    }
    std::array<std::uint32_t, 3> triangle(std::size_t i) const {
        const auto extra = std::uint32_t(mesh.vertices.size());
        return dropped[i] ? std::array<std::uint32_t, 3>{extra, extra, extra} : mesh.triangles[i];
    }
};

}  // namespace bvhkit
