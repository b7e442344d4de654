#pragma once
// SolidModel<V>: a closed, outward-oriented triangle mesh as a solid, ready for the penetration
// depth and signed distance between two solids (query/mesh_penetration.hpp). It holds what those
// queries ask besides the collision tree: a winding-number tree for the inside test (one interior
// may hold the other with no faces meeting), the convex hull of the vertices (the support function
// that brackets a translation, and EPA when both solids are convex), and whether the mesh is
// convex.
//
// Built once per mesh, since the checks cost more than a query: closedness (every edge, after
// welding equal corners, used as often in one direction as in the other; crossings.hpp) is an
// Error when it fails, as the interior of an open mesh is not defined. Convexity: closed, one
// connected piece of Euler characteristic 2, and every edge convex (the far corner of the
// neighbour across an edge lies on or behind the triangle's plane, within 1e-9 of the diagonal
// per unit normal: a flat face split in two still counts).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "bvhkit/convex/convex_shape.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/primitives/weld.hpp"
#include "bvhkit/query/collision_model.hpp"
#include "bvhkit/query/crossings.hpp"
#include "bvhkit/query/winding_number.hpp"

namespace bvhkit {

namespace solid_detail {

/// Whether a closed mesh (welded ids `weld`, `pieces` connected pieces: piece_probes) is convex:
/// one piece, Euler characteristic 2, every edge shared by exactly two triangles and convex (see
/// the header comment).
template <IndexedTriangleMesh M>
bool closed_mesh_is_convex(const M& mesh, const std::vector<std::uint32_t>& weld,
                           std::size_t pieces) {
    if (pieces != 1) return false;
    using D = Vec<double, 3>;
    const std::size_t nt = mesh.triangle_count();
    // Directed edges (from, to) -> triangle, sorted for the twin's look-up.
    std::vector<std::pair<std::uint64_t, std::uint32_t>> edges;
    edges.reserve(3 * nt);
    Aabb<double, 3> box;
    std::uint32_t ids = 0;
    for (std::uint32_t i = 0; i < nt; ++i) {
        const auto& t = mesh.triangle(i);
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = weld[t[k]], b = weld[t[(k + 1) % 3]];
            if (a == b) return false;  // a degenerate corner: not a plain convex polyhedron
            edges.emplace_back((std::uint64_t(a) << 32) | b, i);
            box.grow(D(mesh.vertex(t[k])));
            ids = std::max(ids, a + 1);
        }
    }
    std::sort(edges.begin(), edges.end());
    for (std::size_t k = 1; k < edges.size(); ++k)
        if (edges[k].first == edges[k - 1].first) return false;  // an edge used twice one way
    std::vector<char> used(ids, 0);
    const double diagonal = length(box.max - box.min);
    for (const auto& [key, tri] : edges) {
        const std::uint32_t a = std::uint32_t(key >> 32), b = std::uint32_t(key);
        used[a] = used[b] = 1;
        const std::uint64_t twin_key = (std::uint64_t(b) << 32) | a;
        const auto twin = std::lower_bound(edges.begin(), edges.end(),
                                           std::pair<std::uint64_t, std::uint32_t>(twin_key, 0));
        if (twin == edges.end() || twin->first != twin_key) return false;
        const auto& t = mesh.triangle(tri);
        const auto& u = mesh.triangle(twin->second);
        const D p0(mesh.vertex(t[0])), p1(mesh.vertex(t[1])), p2(mesh.vertex(t[2]));
        const D n = cross(p1 - p0, p2 - p0);
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t w = weld[u[k]];
            if (w == a || w == b) continue;
            if (dot(n, D(mesh.vertex(u[k])) - p0) > 1e-9 * diagonal * length(n)) return false;
        }
    }
    const auto vertices = std::int64_t(std::count(used.begin(), used.end(), char(1)));
    return vertices - std::int64_t(edges.size() / 2) + std::int64_t(nt) == 2;
}

/// One corner of a triangle of each connected piece (triangles joined through welded corners),
/// in the order the pieces first appear: once the surfaces do not meet, a piece is inside the
/// other solid exactly when its corner is, and each piece must be asked on its own.
template <IndexedTriangleMesh M>
std::vector<Vec<typename M::Scalar, 3>> piece_probes(const M& mesh,
                                                     const std::vector<std::uint32_t>& weld) {
    std::uint32_t ids = 0;
    for (const std::uint32_t w : weld) ids = std::max(ids, w + 1);
    std::vector<std::uint32_t> parent(ids);
    std::iota(parent.begin(), parent.end(), 0u);
    const auto root = [&](std::uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    };
    const std::size_t nt = mesh.triangle_count();
    for (std::size_t i = 0; i < nt; ++i) {
        const auto& t = mesh.triangle(i);
        parent[root(weld[t[0]])] = root(weld[t[1]]);
        parent[root(weld[t[1]])] = root(weld[t[2]]);
    }
    std::vector<char> seen(ids, 0);
    std::vector<Vec<typename M::Scalar, 3>> probes;
    for (std::size_t i = 0; i < nt; ++i) {
        const auto& t = mesh.triangle(i);
        const std::uint32_t r = root(weld[t[0]]);
        if (seen[r]) continue;
        seen[r] = 1;
        probes.push_back(mesh.vertex(t[0]));
    }
    return probes;
}

}  // namespace solid_detail

template <BoundingVolume V>
class SolidModel {
  public:
    using T = typename V::Scalar;
    using Volume = V;

    /// Error if the mesh is empty, has a non-finite coordinate, or is not closed.
    template <IndexedTriangleMesh M>
    explicit SolidModel(const M& mesh, const BuildOptions& options = collision_build_options())
        : collision_(mesh, options), winding_(mesh), hull_(hull_of(mesh)) {
        if (mesh.triangle_count() == 0) throw Error("SolidModel: the mesh has no triangles");
        if (!collision_.skipped().empty())
            throw Error("SolidModel: triangle " + std::to_string(collision_.skipped()[0]) +
                        " has a non-finite coordinate");
        const std::vector<std::uint32_t> weld = weld_vertices(mesh);
        if (!is_closed_surface(mesh, weld))
            throw Error(
                "SolidModel: the mesh is not closed (an edge, after welding equal corners, is not "
                "used as often in one direction as in the other); its interior is undefined");
        for (const auto& p : solid_detail::piece_probes(mesh, weld))
            probes_.push_back(Vec<T, 3>(p));
        convex_ = solid_detail::closed_mesh_is_convex(mesh, weld, probes_.size());
    }

    const CollisionModel<V>& collision() const { return collision_; }
    const ConvexShape<T>& hull() const { return hull_; }
    /// Whether the mesh is convex (then it is its own hull).
    bool convex() const { return convex_; }
    /// A vertex of each connected piece of the mesh: once the surfaces do not meet, a piece is
    /// inside the other solid exactly when its vertex is.
    std::span<const Vec<T, 3>> probes() const { return probes_; }

    /// Whether q (not on the surface) is inside: the winding number, which is an integer for a
    /// closed mesh. The fast expansion is trusted where it is near an integer; otherwise (q very
    /// near the surface) the exact sum of solid angles decides.
    bool contains(const Vec<T, 3>& q) const {
        const T w = winding_.fast(q);
        if (std::abs(w - std::round(w)) < T(0.2)) return std::lround(w) != 0;
        return std::lround(winding_.exact(q)) != 0;
    }

  private:
    template <IndexedTriangleMesh M>
    static ConvexShape<T> hull_of(const M& mesh) {
        std::vector<Vec<T, 3>> points(mesh.vertex_count());
        for (std::size_t i = 0; i < points.size(); ++i) points[i] = Vec<T, 3>(mesh.vertex(i));
        if (points.empty()) throw Error("SolidModel: the mesh has no vertices");
        return ConvexShape<T>(ConvexPolytope<T>(std::span<const Vec<T, 3>>(points)));
    }

    CollisionModel<V> collision_;
    WindingNumberMesh<T> winding_;
    ConvexShape<T> hull_;
    bool convex_ = false;
    std::vector<Vec<T, 3>> probes_;
};

}  // namespace bvhkit
