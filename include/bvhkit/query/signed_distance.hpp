#pragma once
// Signed distance to a closed triangle mesh, and inside/outside: the distance from the closest
// point (ClosestPointMesh), the sign from the angle-weighted pseudonormal of the feature the
// closest point lies on (Baerentzen and Aanaes 2005, "Signed distance computation using the angle
// weighted pseudonormal"): the face normal inside a face, the sum of the two face normals on an
// edge, the sum of the incident face normals weighted by their angles at a vertex. The point is
// outside (positive) when it lies on the side the pseudonormal points to.
//
// The sign is exact for a closed, consistently oriented (outward, counter-clockwise) manifold
// mesh; for a mesh with holes or flipped triangles use the winding number (winding_number.hpp).
// Corners that sit at the same position are welded first (many files split vertices at seams),
// so the edges and vertices of the pseudonormals are the geometric ones.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <string>

#include "bvhkit/primitives/weld.hpp"
#include "bvhkit/query/closest_point_mesh.hpp"

namespace bvhkit {

namespace serial_detail {
struct SignedDistanceMeshAccess;  // io/signed_distance_mesh_file.hpp: saves and loads the arrays
}

template <class T>
struct SignedDistance {
    T distance = 0;  // negative inside
    MeshPoint<T> closest;
};

template <class T>
class SignedDistanceMesh {
  public:
    template <IndexedTriangleMesh M>
    explicit SignedDistanceMesh(const M& mesh, const BuildOptions& options = {})
        : closest_(mesh, options) {
        const std::size_t nt = mesh.triangle_count();
        const std::vector<std::uint32_t> weld = weld_vertices(mesh);
        const std::uint32_t ids = weld.empty() ? 0 : *std::max_element(weld.begin(), weld.end());
        vertex_normals_.assign((mesh.vertex_count() == 0) ? 0 : ids + 1, Vec<T, 3>{});
        face_normals_.resize(nt);
        corners_.resize(nt);
        // Edge pseudonormals: the sum of the unit normals of the faces on each (welded) edge,
        // found by sorting the 3 nt directed edges by their undirected key.
        struct EdgeRef {
            std::uint64_t key;
            std::uint32_t face;
            std::uint8_t edge;  // 0: p0-p1, 1: p1-p2, 2: p2-p0
        };
        std::vector<EdgeRef> edges;
        edges.reserve(3 * nt);
        for (std::uint32_t f = 0; f < nt; ++f) {
            const auto t = mesh.triangle(f);
            const std::array<std::uint32_t, 3> c{weld[t[0]], weld[t[1]], weld[t[2]]};
            corners_[f] = c;
            const Vec<double, 3> p[3] = {Vec<double, 3>(mesh.vertex(t[0])),
                                         Vec<double, 3>(mesh.vertex(t[1])),
                                         Vec<double, 3>(mesh.vertex(t[2]))};
            // Edges made unit before any product: products of lengths would overflow or sink
            // to zero for a double mesh near the ends of its range (1e300 or 1e-300 across).
            const auto unit_of = [](const Vec<double, 3>& v) {
                const double l = std::hypot(v[0], v[1], v[2]);
                return l > 0 && std::isfinite(l) ? v / l : Vec<double, 3>{};
            };
            const Vec<double, 3> unit = unit_of(cross(unit_of(p[1] - p[0]), unit_of(p[2] - p[0])));
            face_normals_[f] = Vec<T, 3>(unit);
            for (int k = 0; k < 3; ++k) {
                const Vec<double, 3> a = unit_of(p[(k + 1) % 3] - p[k]),
                                     b = unit_of(p[(k + 2) % 3] - p[k]);
                const bool both = length_squared(a) > 0 && length_squared(b) > 0;
                const double angle = both ? std::acos(std::clamp(dot(a, b), -1.0, 1.0)) : 0.0;
                vertex_normals_[c[k]] += Vec<T, 3>(unit * angle);
                const std::uint32_t lo = std::min(c[k], c[(k + 1) % 3]);
                const std::uint32_t hi = std::max(c[k], c[(k + 1) % 3]);
                edges.push_back({std::uint64_t(lo) << 32 | hi, f, std::uint8_t(k)});
            }
        }
        std::sort(edges.begin(), edges.end(),
                  [](const EdgeRef& a, const EdgeRef& b) { return a.key < b.key; });
        edge_normals_.assign(nt, {});
        for (std::size_t b = 0; b < edges.size();) {
            std::size_t e = b;
            Vec<T, 3> sum{};
            while (e < edges.size() && edges[e].key == edges[b].key)
                sum += face_normals_[edges[e++].face];
            for (std::size_t k = b; k < e; ++k) edge_normals_[edges[k].face][edges[k].edge] = sum;
            b = e;
        }
    }

    /// Signed distance: negative inside. The sign is decided by the pseudonormal at the closest
    /// point (see above).
    SignedDistance<T> signed_distance(const Vec<T, 3>& p, NearestScratch<T>& scratch) const {
        return signed_distance(p, MeshPoint<T>{}, scratch);
    }
    /// The same answer, found sooner when `near` is the closest point of a point close to p
    /// (see ClosestPointMesh::closest_point).
    SignedDistance<T> signed_distance(const Vec<T, 3>& p, const MeshPoint<T>& near,
                                      NearestScratch<T>& scratch) const {
        return signed_distance_at(p, closest_.closest_point(p, near, scratch));
    }
    /// The signed distance of p given `closest`, p's closest point on closest_point_mesh() (found
    /// by the caller's own walk, as a scene's nearest walk over many meshes finds it): its
    /// distance, negative where p lies behind the pseudonormal there. inf for none.
    SignedDistance<T> signed_distance_at(const Vec<T, 3>& p, const MeshPoint<T>& closest) const {
        SignedDistance<T> r;
        r.closest = closest;
        if (!r.closest) return {std::numeric_limits<T>::infinity(), r.closest};
        const T d = r.closest.distance;
        // In W: p - point and the products would overflow T for a point near T's maximum.
        using V = Vec<AccurateScalar<T>, 3>;
        r.distance = dot(V(p) - V(r.closest.point), V(pseudonormal(r.closest))) < 0 ? -d : d;
        return r;
    }
    SignedDistance<T> signed_distance(const Vec<T, 3>& p) const {
        thread_local NearestScratch<T> scratch;
        return signed_distance(p, scratch);
    }
    bool inside(const Vec<T, 3>& p) const { return signed_distance(p).distance < T(0); }

    /// signed_distance for every point, on `threads` threads (0 = all; see exec/executor.hpp):
    /// the same answers as one at a time, for any thread count. Safe to call from many threads
    /// on one const mesh.
    void signed_distances(std::span<const Vec<T, 3>> points, std::span<SignedDistance<T>> out,
                          unsigned threads = 0) const {
        signed_distances(points, out, Executor(threads));
    }
    /// signed_distance for every point, on `exec`.
    void signed_distances(std::span<const Vec<T, 3>> points, std::span<SignedDistance<T>> out,
                          const Executor& exec) const {
        if (out.size() < points.size())
            throw Error("SignedDistanceMesh::signed_distances: " + std::to_string(points.size()) +
                        " points but room for " + std::to_string(out.size()));
        for_point_chunks(points, exec, 1024, [&](std::span<const std::uint32_t> chunk) {
            NearestScratch<T> scratch;
            MeshPoint<T> previous;  // each walk starts from its neighbour's closest point
            for (const std::uint32_t i : chunk) {
                out[i] = signed_distance(points[i], previous, scratch);
                previous = out[i].closest;
            }
        });
    }

    const ClosestPointMesh<T>& closest_point_mesh() const { return closest_; }

  private:
    friend struct serial_detail::SignedDistanceMeshAccess;
    SignedDistanceMesh() = default;  // for the loader, which fills every member

    /// The pseudonormal of the feature (face, edge or vertex) the closest point lies on, told by
    /// which barycentric coordinates vanish (closest_point returns them exactly 0 or 1 in the
    /// vertex and edge regions; the p1-p2 edge's third weight is 1 - u - v, so a tolerance).
    Vec<T, 3> pseudonormal(const MeshPoint<T>& c) const {
        const std::uint32_t f = c.triangle;
        const T eps = T(16) * std::numeric_limits<T>::epsilon();
        const T w0 = T(1) - c.u - c.v;
        const bool z0 = w0 <= eps, z1 = c.u <= eps, z2 = c.v <= eps;
        const auto& corner = corners_[f];
        if (z1 && z2) return vertex_normals_[corner[0]];
        if (z0 && z2) return vertex_normals_[corner[1]];
        if (z0 && z1) return vertex_normals_[corner[2]];
        if (z2) return edge_normals_[f][0];  // p0-p1
        if (z0) return edge_normals_[f][1];  // p1-p2
        if (z1) return edge_normals_[f][2];  // p2-p0
        return face_normals_[f];
    }

    ClosestPointMesh<T> closest_;
    std::vector<Vec<T, 3>> face_normals_;                 // unit, by mesh triangle
    std::vector<std::array<Vec<T, 3>, 3>> edge_normals_;  // by triangle, edges p0p1 p1p2 p2p0
    std::vector<Vec<T, 3>> vertex_normals_;               // by welded vertex
    std::vector<std::array<std::uint32_t, 3>> corners_;   // welded vertex ids by triangle
};

}  // namespace bvhkit
