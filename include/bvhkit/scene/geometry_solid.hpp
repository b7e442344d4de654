#pragma once
// The per-geometry structures of a Scene's signed distance and inside/outside queries
// (scene/signed_distance.hpp), kept apart from SceneGeometry's trees (scene/geometry.hpp) and,
// like them, built the first time a query needs each, under std::call_once, and shared by every
// instance of the geometry:
// - a SignedDistanceMesh (query/signed_distance.hpp): the pseudonormal sign, with its own
//   closest point tree, which the signed distance walk uses, so a scene asked only for signed
//   distances builds one closest point tree per geometry;
// - a WindingNumberMesh (query/winding_number.hpp), for inside/outside of open meshes;
// - whether the geometry is a closed oriented surface (query/crossings.hpp), where one ray's
//   signed crossings decide inside/outside exactly.
// Triangles with a NaN or infinite corner are left out of all three, as the trees leave them out.
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <vector>

#include "bvhkit/primitives/triangle_mesh.hpp"
#include "bvhkit/primitives/weld.hpp"
#include "bvhkit/query/crossings.hpp"
#include "bvhkit/query/signed_distance.hpp"
#include "bvhkit/query/winding_number.hpp"
#include "bvhkit/triangle_bvh.hpp"

namespace bvhkit::scene_detail {

/// The indices of the triangles with a NaN or infinite corner, ascending.
template <class T>
std::vector<std::uint32_t> non_finite_triangles(const BasicTriangleMesh<T>& mesh) {
    std::vector<std::uint32_t> out;
    for (std::uint32_t i = 0; i < mesh.triangles.size(); ++i) {
        const auto& t = mesh.triangles[i];
        if (!(is_finite(mesh.vertices[t[0]]) && is_finite(mesh.vertices[t[1]]) &&
              is_finite(mesh.vertices[t[2]])))
            out.push_back(i);
    }
    return out;
}

template <class T>
class GeometrySolid {
  public:
    const SignedDistanceMesh<T>& signed_distance_mesh(const BasicTriangleMesh<T>& mesh) const {
        std::call_once(sdf_once_, [&] {
            const std::vector<std::uint32_t> bad = non_finite_triangles(mesh);
            sdf_ =
                bad.empty()
                    ? std::make_unique<SignedDistanceMesh<T>>(mesh)
                    : std::make_unique<SignedDistanceMesh<T>>(MeshWithoutTriangles<T>(mesh, bad));
        });
        return *sdf_;
    }
    /// Over the finite triangles only: the winding number's tree and sums have no use for the
    /// triangles' indices, and a NaN corner would make every sum NaN.
    const WindingNumberMesh<T>& winding_number_mesh(const BasicTriangleMesh<T>& mesh) const {
        std::call_once(winding_once_, [&] {
            const std::vector<std::uint32_t> bad = non_finite_triangles(mesh);
            if (bad.empty()) {
                winding_ = std::make_unique<WindingNumberMesh<T>>(mesh);
                return;
            }
            BasicTriangleMesh<T> finite;
            finite.vertices = mesh.vertices;
            std::size_t next = 0;
            for (std::uint32_t i = 0; i < mesh.triangles.size(); ++i) {
                if (next < bad.size() && bad[next] == i) {
                    ++next;
                    continue;
                }
                finite.triangles.push_back(mesh.triangles[i]);
            }
            winding_ = std::make_unique<WindingNumberMesh<T>>(finite);
        });
        return *winding_;
    }
    /// Whether the finite triangles form a closed oriented surface (is_closed_surface). The
    /// crossing test also needs a watertight ray test, which the geometry's ray tree has: it is
    /// built with the default options.
    bool closed(const BasicTriangleMesh<T>& mesh) const {
        static_assert(TriangleBvhOptions{}.triangle_test == TriangleTest::Watertight);
        std::call_once(closed_once_, [&] {
            closed_ = is_closed_surface(mesh, weld_vertices(mesh), non_finite_triangles(mesh));
        });
        return closed_;
    }

  private:
    mutable std::once_flag sdf_once_, winding_once_, closed_once_;
    mutable std::unique_ptr<SignedDistanceMesh<T>> sdf_;
    mutable std::unique_ptr<WindingNumberMesh<T>> winding_;
    mutable bool closed_ = false;
};

}  // namespace bvhkit::scene_detail
