#pragma once
// CollisionModel<V>: a triangle mesh ready for collision and distance queries with any bounding
// volume type V (Aabb<T, 3>, Sphere<T>, Obb<T>, Kdop<T, K>). The tree's shape comes from the AABB
// builders (build_bvh); its volumes are fitted per node (build/fit_volumes.hpp). The triangles are
// kept in leaf-slot order, so a leaf's triangles are contiguous. The queries on two models are in
// query/pairs_model.hpp (collide, collides) and query/distance.hpp.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/build/build.hpp"
#include "bvhkit/build/fit_volumes.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/math/wide_length.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

namespace serial_detail {
struct CollisionModelAccess;  // io/collision_model_file.hpp: saves and loads the private arrays
}

/// Build options for collision trees: small leaves, as a leaf pair costs count_a * count_b
/// triangle tests.
inline BuildOptions collision_build_options() {
    BuildOptions o;
    o.max_leaf_size = tuning::collision_max_leaf_size;
    return o;
}

template <BoundingVolume V>
class CollisionModel {
  public:
    using T = typename V::Scalar;
    using Volume = V;

    CollisionModel() = default;
    template <IndexedTriangleMesh M>
    explicit CollisionModel(const M& mesh,
                            const BuildOptions& options = collision_build_options()) {
        check_triangle_indices(mesh);
        std::vector<Aabb<T, 3>> boxes(mesh.triangle_count());
        std::vector<Vec<T, 3>> centroids(mesh.triangle_count());
        for (std::size_t i = 0; i < boxes.size(); ++i) {
            boxes[i] = triangle_at<T>(mesh, i).bounds();
            centroids[i] = boxes[i].centroid();
        }
        const AabbBvh<T, 3> topology = build_bvh<T, 3>(boxes, centroids, options, &report_);
        triangle_count_ = mesh.triangle_count();
        lay_out(mesh, topology.primitive_indices);
        bvh_ = fit_volumes<V>(topology, std::span<const Triangle<T>>(slot_triangles_));
    }

    /// After the mesh's vertices moved (same triangles in the same order): new triangles, every
    /// volume refitted in one pass, same tree shape. A triangle of the tree with a NaN or infinite
    /// coordinate is an Error (the model is left unchanged); triangles left out at the build stay
    /// out.
    template <IndexedTriangleMesh M>
    void refit(const M& mesh) {
        if (mesh.triangle_count() != triangle_count_)
            throw Error("CollisionModel::refit: the mesh has " +
                        std::to_string(mesh.triangle_count()) +
                        " triangles, the model was built over " + std::to_string(triangle_count_));
        check_triangle_indices(mesh);
        // The tree's shape is kept, so a triangle in it cannot be left out as a build would leave
        // it: an Error, and the model stays as it was.
        for (const std::uint32_t t : bvh_.primitive_indices)
            if (!triangle_at<T>(mesh, t).bounds().is_finite())
                throw Error("CollisionModel::refit: triangle " + std::to_string(t) +
                            " has a non-finite coordinate (a new model would leave it out)");
        lay_out(mesh, bvh_.primitive_indices);
        refit_volumes(bvh_, std::span<const Triangle<T>>(slot_triangles_));
    }

    const Bvh<V>& bvh() const { return bvh_; }
    /// Triangle in leaf slot s; its index in the mesh is bvh().primitive_indices[s].
    std::span<const Triangle<T>> slot_triangles() const { return slot_triangles_; }
    std::span<const std::array<std::uint32_t, 3>> slot_vertex_ids() const {
        return slot_vertex_ids_;
    }
    std::uint32_t triangle_id(std::uint32_t slot) const { return bvh_.primitive_indices[slot]; }
    std::size_t triangle_count() const { return triangle_count_; }
    /// Triangles left out for non-finite coordinates.
    const std::vector<std::uint32_t>& skipped() const { return report_.skipped; }
    /// Largest |coordinate| of the model plus its box diagonal: the scale of its rounding errors.
    T scale() const { return scale_; }
    /// scale() of a model with these slot triangles.
    /// The diagonal's length is taken without squaring through T's range (a float model at 1e19
    /// would get an infinite scale, at 1e-25 lose the diagonal); the sum is inf only beyond T's
    /// largest finite value. Where the squares stay normal it is the sum in T, as it always was.
    static T scale_of(std::span<const Triangle<T>> triangles) {
        Aabb<T, 3> box;
        for (const Triangle<T>& t : triangles) box.grow(t.p0).grow(t.p1).grow(t.p2);
        if (box.is_empty()) return T(0);
        const T largest = max_component(bvhkit::max(box.max, -box.min));
        const Vec<T, 3> diagonal = box.max - box.min;
        const T d2 = length_squared(diagonal);
        if (std::isfinite(d2) && (d2 >= std::numeric_limits<T>::min() || box.max == box.min))
            return largest + std::sqrt(d2);
        return narrow_or_inf<T>(double(largest) +
                                wide_length(Vec<double, 3>(box.max) - Vec<double, 3>(box.min)));
    }

  private:
    friend struct serial_detail::CollisionModelAccess;

    template <IndexedTriangleMesh M>
    void lay_out(const M& mesh, const std::vector<std::uint32_t>& order) {
        slot_triangles_.resize(order.size());
        slot_vertex_ids_.resize(order.size());
        for (std::size_t s = 0; s < order.size(); ++s) {
            slot_triangles_[s] = triangle_at<T>(mesh, order[s]);
            slot_vertex_ids_[s] = mesh.triangle(order[s]);
        }
        scale_ = scale_of(slot_triangles_);
    }

    Bvh<V> bvh_;
    std::vector<Triangle<T>> slot_triangles_;
    std::vector<std::array<std::uint32_t, 3>> slot_vertex_ids_;
    BuildReport report_;
    std::size_t triangle_count_ = 0;
    T scale_ = 0;
};

}  // namespace bvhkit
