#pragma once
// BspTree<T, N>: a binary space partitioning tree over the triangles of a mesh (or over any convex
// polygons) in 3D, or over segments in 2D, stored flat (bsp/node.hpp). Build options in
// bsp/options.hpp, the builder in bsp/build.hpp; the queries are free functions: bsp/order.hpp
// (front-to-back and back-to-front from an eye), bsp/ray.hpp (closest hit), bsp/solid.hpp (inside
// or outside of a closed mesh).
//
// Input rules: a vertex that is NaN or infinite is a bvhkit::Error naming its triangle (segment); a
// triangle whose greatest height is at most the plane thickness (zero area, or a needle), or a
// segment no longer than it, is dropped and counted in statistics().dropped_degenerate; an empty
// mesh (or one of dropped triangles only) gives a tree of one empty leaf that every ray misses and
// that classifies every point Outside.
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "bvhkit/bsp/build.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/math/aabb.hpp"
#include "bvhkit/primitives/segment.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit {

template <class T, std::size_t N = 3>
class BspTree {
    static_assert(std::is_floating_point_v<T>);

  public:
    using Scalar = T;

    /// The default plane thickness relative to the input's diagonal (BspOptions::epsilon = 0).
    static constexpr double default_relative_epsilon = sizeof(T) >= 8 ? 1e-10 : 1e-5;

    BspTree() : BspTree(PolygonPool<T, N>{}, BspOptions{}) {}

    /// Over the triangles of `mesh`; polygon sources are triangle indices.
    template <IndexedTriangleMesh M>
    explicit BspTree(const M& mesh, const BspOptions& options = {}) requires(N == 3) {
        options.validate();
        check_triangle_indices(mesh);
        PolygonPool<T> pool;
        Aabb<T, 3> box;
        for (std::size_t i = 0; i < mesh.triangle_count(); ++i) {
            const auto t = mesh.triangle(i);
            for (int c = 0; c < 3; ++c) {
                const Vec<T, 3> p(mesh.vertex(t[std::size_t(c)]));
                if (!is_finite(p))
                    throw Error("BspTree: triangle " + std::to_string(i) +
                                " has a vertex that is NaN or infinite");
                box.grow(p);
            }
        }
        pool.source_planes.resize(mesh.triangle_count());
        const T eps = absolute_epsilon(box, options);
        std::size_t dropped = 0;
        for (std::size_t i = 0; i < mesh.triangle_count(); ++i) {
            const Triangle<T> tri = triangle_at<T>(mesh, i);
            const Vec<T, 3> v[3] = {tri.p0, tri.p1, tri.p2};
            if (is_degenerate(v, eps)) {
                ++dropped;
                continue;
            }
            pool.source_planes[i] = Plane<T>::through(v[0], v[1], v[2]);
            pool.add(std::span<const Vec<T, 3>>(v, 3), std::uint32_t(i));
        }
        adopt(build_bsp(std::move(pool), options, eps, mesh.triangle_count(), dropped));
    }

    /// Over 2D segments; polygon sources are segment indices. A segment's front is to the right of
    /// p0 -> p1 (the outside of a counter-clockwise polygon's edges), which solid.hpp relies on.
    explicit BspTree(const std::vector<Segment<T>>& segments,
                     const BspOptions& options = {}) requires(N == 2) {
        options.validate();
        Aabb<T, 2> box;
        for (std::size_t i = 0; i < segments.size(); ++i) {
            if (!is_finite(segments[i].p0) || !is_finite(segments[i].p1))
                throw Error("BspTree: segment " + std::to_string(i) +
                            " has a vertex that is NaN or infinite");
            box.grow(segments[i].p0);
            box.grow(segments[i].p1);
        }
        PolygonPool<T, 2> pool;
        pool.source_planes.resize(segments.size());
        const T eps = absolute_epsilon(box, options);
        std::size_t dropped = 0;
        for (std::size_t i = 0; i < segments.size(); ++i) {
            const Vec<T, 2> v[2] = {segments[i].p0, segments[i].p1};
            if (!(length(v[1] - v[0]) > eps)) {
                ++dropped;
                continue;
            }
            pool.source_planes[i] = Plane<T, 2>::through(v[0], v[1]);
            pool.add(std::span<const Vec<T, 2>>(v, 2), std::uint32_t(i));
        }
        adopt(build_bsp(std::move(pool), options, eps, segments.size(), dropped));
    }

    /// Over convex polygons given with their planes (source_planes indexed by polygon source),
    /// for callers that have polygons rather than a mesh. The polygons are taken as given: no
    /// degenerate ones are dropped.
    BspTree(PolygonPool<T, N> polygons, const BspOptions& options) {
        options.validate();
        for (std::size_t i = 0; i < polygons.size(); ++i) {
            const BspPolygon& p = polygons.polygons[i];
            if (p.source >= polygons.source_planes.size() || p.count < (N == 3 ? 3u : 2u) ||
                (N == 2 && p.count != 2) ||
                std::size_t(p.first) + p.count > polygons.vertices.size())
                throw Error("BspTree: polygon " + std::to_string(i) +
                            " names vertices or a source plane the pool does not have");
        }
        Aabb<T, N> box;
        for (const auto& p : polygons.vertices) {
            if (!is_finite(p)) throw Error("BspTree: a polygon vertex is NaN or infinite");
            box.grow(p);
        }
        const std::size_t n = polygons.size();
        const T eps = absolute_epsilon(box, options);
        adopt(build_bsp(std::move(polygons), options, eps, n, 0));
    }

    const std::vector<BspNode<T, N>>& nodes() const { return nodes_; }
    const BspNode<T, N>& root() const { return nodes_[0]; }
    /// The stored polygons (parts after splitting), a node's polygons one run of them.
    const PolygonPool<T, N>& polygons() const { return polygons_; }
    const BspStatistics& statistics() const { return stats_; }
    /// The absolute plane thickness the build used.
    T epsilon() const { return eps_; }
    bool is_solid() const { return stats_.solid; }

  private:
    static T absolute_epsilon(const Aabb<T, N>& box, const BspOptions& options) {
        const double rel = options.epsilon > 0 ? options.epsilon : default_relative_epsilon;
        const double diag = box.is_empty() ? 0.0 : double(length(box.max - box.min));
        return T(rel * diag);
    }
    // Zero area, or no height above its longest edge greater than the plane thickness.
    static bool is_degenerate(const Vec<T, 3> (&v)[3], T eps) {
        const T twice_area = length(cross(v[1] - v[0], v[2] - v[0]));
        const T longest = std::max({length(v[1] - v[0]), length(v[2] - v[1]), length(v[0] - v[2])});
        return !(twice_area > T(0)) || twice_area <= eps * longest;
    }
    void adopt(BspBuildResult<T, N>&& r) {
        nodes_ = std::move(r.nodes);
        polygons_ = std::move(r.polygons);
        stats_ = r.stats;
        eps_ = T(stats_.epsilon);
    }

    std::vector<BspNode<T, N>> nodes_;
    PolygonPool<T, N> polygons_;
    BspStatistics stats_;
    T eps_ = 0;
};

}  // namespace bvhkit
