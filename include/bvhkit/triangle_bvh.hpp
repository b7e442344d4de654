#pragma once
// TriangleBvh<T>: what a raycasting user wants in one object. Build it from a triangle mesh, then
// ask closest_hit, any_hit or all_hits. It owns a Bvh and a copy of the triangles laid out in leaf
// order (edges and normal precomputed), so a leaf's triangles are contiguous in memory.
//
// Hit::primitive is the triangle's index in the mesh. Triangles with a NaN or infinite coordinate
// are left out (see BuildReport / skipped()); degenerate (zero-area) triangles stay in the tree and
// are never hit.
#include "bvhkit/build/build.hpp"
#include "bvhkit/build/refit.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"
#include "bvhkit/query/ray.hpp"

namespace bvhkit {

enum class TriangleTest {
    Fast,        // Moller-Trumbore on precomputed edges (default)
    Watertight,  // Woop, Benthin, Wald 2013: never misses through a shared edge
};

template <class T>
class TriangleBvh {
  public:
    TriangleBvh() = default;

    template <class U>
    explicit TriangleBvh(const BasicTriangleMesh<U>& mesh, const BuildOptions& options = {},
                         TriangleTest test = TriangleTest::Fast)
        : TriangleBvh(mesh_triangles<U>(mesh), options, test) {}

    explicit TriangleBvh(std::vector<Triangle<T>> triangles, const BuildOptions& options = {},
                         TriangleTest test = TriangleTest::Fast)
        : triangle_test_(test) {
        std::vector<Aabb<T, 3>> boxes(triangles.size());
        std::vector<Vec<T, 3>> centroids(triangles.size());
        for (std::size_t i = 0; i < triangles.size(); ++i) {
            boxes[i] = triangles[i].bounds();
            centroids[i] = boxes[i].centroid();
        }
        bvh_ = build_bvh<T, 3>(boxes, centroids, options, &report_);
        triangle_count_ = triangles.size();
        lay_out(triangles);
    }

    Hit<T> closest_hit(const Ray<T, 3>& ray) const { return closest_hit(ray, NoStats{}); }
    template <class Stats>
    Hit<T> closest_hit(const Ray<T, 3>& ray, Stats&& stats) const {
        if (triangle_test_ == TriangleTest::Watertight)
            return bvhkit::closest_hit(bvh_, ray, watertight_test(), stats);
        return bvhkit::closest_hit(bvh_, ray, fast_test(), stats);
    }

    bool any_hit(const Ray<T, 3>& ray) const { return any_hit(ray, NoStats{}); }
    template <class Stats>
    bool any_hit(const Ray<T, 3>& ray, Stats&& stats) const {
        if (triangle_test_ == TriangleTest::Watertight)
            return bvhkit::any_hit(bvh_, ray, watertight_test(), stats);
        return bvhkit::any_hit(bvh_, ray, fast_test(), stats);
    }

    /// on_hit(const Hit<T>&) -> bool (true to go on); hits come in no particular order.
    template <class OnHit, class Stats = NoStats>
    void all_hits(const Ray<T, 3>& ray, OnHit&& on_hit, Stats&& stats = {}) const {
        if (triangle_test_ == TriangleTest::Watertight)
            bvhkit::all_hits(bvh_, ray, watertight_test(), on_hit, stats);
        else
            bvhkit::all_hits(bvh_, ray, fast_test(), on_hit, stats);
    }

    /// After the mesh's vertices moved (same triangles, same order): refit the boxes, one pass.
    template <class U>
    void refit(const BasicTriangleMesh<U>& mesh) {
        std::vector<Triangle<T>> triangles = mesh_triangles<U>(mesh);
        if (triangles.size() != triangle_count_)
            throw Error("TriangleBvh::refit: the mesh has " + std::to_string(triangles.size()) +
                        " triangles, the tree was built over " + std::to_string(triangle_count_));
        bvhkit::refit(bvh_, [&](std::uint32_t i) { return triangles[i].bounds(); });
        lay_out(triangles);
    }

    const AabbBvh<T, 3>& bvh() const { return bvh_; }
    /// Triangles left out of the tree for non-finite coordinates, by mesh index.
    const std::vector<std::uint32_t>& skipped() const { return report_.skipped; }
    std::size_t triangle_count() const { return triangle_count_; }

    template <class U>
    static std::vector<Triangle<T>> mesh_triangles(const BasicTriangleMesh<U>& mesh) {
        std::vector<Triangle<T>> out(mesh.triangles.size());
        for (std::size_t i = 0; i < out.size(); ++i) {
            const auto& t = mesh.triangles[i];
            for (std::uint32_t k : t)
                if (k >= mesh.vertices.size())
                    throw Error("triangle " + std::to_string(i) + " names vertex " +
                                std::to_string(k) + " of " + std::to_string(mesh.vertices.size()));
            out[i] = {Vec<T, 3>(mesh.vertices[t[0]]), Vec<T, 3>(mesh.vertices[t[1]]),
                      Vec<T, 3>(mesh.vertices[t[2]])};
        }
        return out;
    }

  private:
    void lay_out(const std::vector<Triangle<T>>& triangles) {
        const auto& order = bvh_.primitive_indices;
        fast_.resize(order.size());
        for (std::size_t s = 0; s < order.size(); ++s)
            fast_[s] = PrecomputedTriangle<T>(triangles[order[s]]);
        if (triangle_test_ == TriangleTest::Watertight) {
            exact_.resize(order.size());
            for (std::size_t s = 0; s < order.size(); ++s) exact_[s] = triangles[order[s]];
        }
    }
    auto fast_test() const {
        return [tris = fast_.data()](std::uint32_t slot, const Ray<T, 3>& ray, TriangleHit<T>& h) {
            return tris[slot].intersect(ray, ray.tmax, h);
        };
    }
    auto watertight_test() const {
        return [tris = exact_.data()](std::uint32_t slot, const Ray<T, 3>& ray, TriangleHit<T>& h) {
            const auto r = tris[slot].intersect_watertight(ray);
            if (r) h = *r;
            return r.has_value();
        };
    }

    AabbBvh<T, 3> bvh_;
    std::vector<PrecomputedTriangle<T>> fast_;  // leaf-slot order
    std::vector<Triangle<T>> exact_;            // leaf-slot order, only for the watertight test
    BuildReport report_;
    std::size_t triangle_count_ = 0;
    TriangleTest triangle_test_ = TriangleTest::Fast;
};

}  // namespace bvhkit
