#pragma once
// ContactMesh<T>: what contact_manifold (query/contact_manifold.hpp) needs of a mesh beyond its
// CollisionModel: the welded vertices and the faces around each (to walk from the intersection
// curve to the vertices that lie inside the other mesh), unit face normals, and a
// SignedDistanceMesh (whether a vertex is inside the other mesh, how deep, and towards where).
// Build it from the same mesh as the CollisionModel it goes with; the query checks the face count.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "bvhkit/primitives/triangle_mesh.hpp"
#include "bvhkit/primitives/weld.hpp"
#include "bvhkit/query/signed_distance.hpp"

namespace bvhkit {

template <class T>
class ContactMesh {
  public:
    ContactMesh() = delete;
    template <IndexedTriangleMesh M>
    explicit ContactMesh(const M& mesh, const BuildOptions& options = {})
        : surface_(mesh, options) {
        check_triangle_indices(mesh);
        const std::size_t nt = mesh.triangle_count();
        const std::vector<std::uint32_t> weld = weld_vertices(mesh);
        const std::size_t nv =
            weld.empty() ? 0 : std::size_t(*std::max_element(weld.begin(), weld.end())) + 1;
        vertices_.resize(nv);
        for (std::size_t i = 0; i < weld.size(); ++i)
            vertices_[weld[i]] = Vec<T, 3>(mesh.vertex(std::uint32_t(i)));
        corners_.resize(nt);
        normals_.resize(nt);
        face_offsets_.assign(nv + 1, 0);
        for (std::uint32_t f = 0; f < nt; ++f) {
            const auto t = mesh.triangle(f);
            corners_[f] = {weld[t[0]], weld[t[1]], weld[t[2]]};
            for (int k = 0; k < 3; ++k)
                if (k == 0 || (corners_[f][k] != corners_[f][0] &&
                               (k == 1 || corners_[f][2] != corners_[f][1])))
                    ++face_offsets_[corners_[f][k] + 1];
            // Unit edges before the cross product: no product of lengths overflows or sinks.
            const Vec<double, 3> p0(vertices_[corners_[f][0]]), p1(vertices_[corners_[f][1]]),
                p2(vertices_[corners_[f][2]]);
            normals_[f] = unit_or_zero(cross(unit_or_zero(p1 - p0), unit_or_zero(p2 - p0)));
        }
        for (std::size_t v = 0; v < nv; ++v) face_offsets_[v + 1] += face_offsets_[v];
        vertex_faces_.resize(face_offsets_[nv]);
        std::vector<std::uint32_t> fill(face_offsets_.begin(), face_offsets_.end() - 1);
        for (std::uint32_t f = 0; f < nt; ++f) {
            const auto& c = corners_[f];
            for (int k = 0; k < 3; ++k)
                if (k == 0 || (c[k] != c[0] && (k == 1 || c[2] != c[1])))
                    vertex_faces_[fill[c[k]]++] = f;
        }
    }

    std::size_t triangle_count() const { return corners_.size(); }
    std::size_t vertex_count() const { return vertices_.size(); }
    /// Welded vertex v (vertices at exactly one position share an id, primitives/weld.hpp).
    const Vec<T, 3>& vertex(std::uint32_t v) const { return vertices_[v]; }
    /// Welded vertex ids of mesh triangle f.
    const std::array<std::uint32_t, 3>& corners(std::uint32_t f) const { return corners_[f]; }
    /// Unit normal of mesh triangle f (right-handed on its corner order), zero for a zero-area one.
    const Vec<double, 3>& normal(std::uint32_t f) const { return normals_[f]; }
    /// The mesh triangles that have welded vertex v as a corner, ascending.
    std::span<const std::uint32_t> faces_at(std::uint32_t v) const {
        return {vertex_faces_.data() + face_offsets_[v], face_offsets_[v + 1] - face_offsets_[v]};
    }
    const SignedDistanceMesh<T>& surface() const { return surface_; }

  private:
    static Vec<double, 3> unit_or_zero(const Vec<double, 3>& v) {
        const double l = std::hypot(v[0], v[1], v[2]);
        return l > 0 && std::isfinite(l) ? v / l : Vec<double, 3>{};
    }

    SignedDistanceMesh<T> surface_;
    std::vector<Vec<T, 3>> vertices_;
    std::vector<std::array<std::uint32_t, 3>> corners_;
    std::vector<Vec<double, 3>> normals_;
    std::vector<std::uint32_t> face_offsets_, vertex_faces_;
};

}  // namespace bvhkit
