#pragma once
// Batches of rays over a Scene (scene.hpp): closest_hits and any_hits on the library's threads,
// and SceneRayTop, the top level flattened for them (the per-instance steps are rays.hpp's).
#include <cstdint>
#include <type_traits>
#include <vector>

#include "bvhkit/build/build.hpp"
#include "bvhkit/exec/executor.hpp"
#include "bvhkit/query/ray.hpp"
#include "bvhkit/query/triangle_rays.hpp"
#include "bvhkit/scene/ray_top_wide.hpp"
#include "bvhkit/scene/rays.hpp"

namespace bvhkit {

/// The scene's top level flattened for rays: a static binned-SAH tree over the instances' world
/// boxes, one instance per leaf, each leaf holding what its ray needs (the pose, the geometry's
/// ray tree) beside it. The dynamic top level is made for change (its nodes linked, its cast
/// general enough for boxes); a batch of rays through a scene that stands still walks this one
/// instead: flat nodes, and the ray's octant chosen once per ray rather than once per box
/// (query/ray.hpp's walk).
///
/// A snapshot: it answers for the scene as it was when made (its poses copied, its geometry's
/// trees referenced, so it must not outlive the scene), and changing the scene afterwards leaves
/// it stale; make a new one. Making it costs a build over the instances (O(n log n)), so it pays
/// for itself over many rays: closest_hits and any_hits make one per call when the batch is large
/// enough (ray_top_min_rays).
template <class T>
class SceneRayTop {
  public:
    explicit SceneRayTop(const Scene<T>& scene) {
        std::vector<Aabb<T, 3>> boxes;
        std::vector<Vec<T, 3>> centres;
        scene.for_each_instance([&](InstanceId id) {
            const SceneInstance<T>& r = scene.instance_at(id.proxy());
            const SceneGeometry<T>& g = scene.geometry_at(r.geometry);
            if (!g.has_extent()) return;
            boxes.push_back(r.box);
            centres.push_back(safe_centroid(r.box));
            entries_.push_back({r.pose, &g.ray_tree(), id.proxy(), r.geometry});
        });
        BuildOptions options;
        options.max_leaf_size = 1;  // an instance costs a whole tree walk: never two per leaf
        options.threads = 1;
        bvh_ = build_bvh<T, 3>(boxes, centres, options);
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>) wide_ = scene_detail::WideTop4(bvh_);
#endif
    }

    /// As closest_hit(scene, ray) for the scene when this was made (of hits at the same t, the
    /// one this walk reaches first wins, which may be another instance than closest_hit's).
    SceneHit<T> closest_hit(const Ray<T, 3>& ray) const {
        SceneHit<T> best;
        if (!scene_detail::check_scene_ray(ray, "SceneRayTop::closest_hit") || bvh_.nodes.empty())
            return best;
        Hit<T> best_local;
        const Entry* best_entry = nullptr;
        T tmax = ray.tmax;
        walk<true>(ray, tmax, [&](std::uint32_t i) {
            const Entry& e = entries_[i];
            const Ray<T, 3> local = scene_detail::local_ray(e.pose, ray, tmax);
            if (!is_traceable(local)) return false;  // overflowed in the instance's frame
            const Hit<T> h = e.tree->closest_hit(local);
            if (!h || !(h.t < best_local.t)) return false;
            best_local = h;
            best_entry = &e;
            tmax = h.t;
            return h.t == T(0);  // a hit at the origin: nothing can be nearer
        });
        if (best_entry) {
            best.instance = InstanceId(best_entry->proxy);
            best.geometry = best_entry->geometry;
            best.face = best_local.primitive;
            best.t = best_local.t;
            best.u = best_local.u;
            best.v = best_local.v;
            best.normal = scene_detail::to_world_vector<AccurateScalar<T>>(best_entry->pose,
                                                                           best_local.normal);
        }
        return best;
    }

    /// As any_hit(scene, ray) for the scene when this was made.
    bool any_hit(const Ray<T, 3>& ray) const {
        if (!scene_detail::check_scene_ray(ray, "SceneRayTop::any_hit") || bvh_.nodes.empty())
            return false;
        bool hit = false;
        T tmax = ray.tmax;
        walk<false>(ray, tmax, [&](std::uint32_t i) {
            const Entry& e = entries_[i];
            const Ray<T, 3> local = scene_detail::local_ray(e.pose, ray, ray.tmax);
            hit = is_traceable(local) && e.tree->any_hit(local);
            return hit;
        });
        return hit;
    }

  private:
    struct Entry {
        Transform<T> pose;
        const TriangleBvh<T>* tree;
        ProxyId proxy;
        GeometryId geometry;
    };
    /// on_instance(index in entries_) -> bool (true stops) for each instance whose box the ray
    /// meets within [tmin, tmax], which on_instance may lower; a checked ray, a tree not empty.
    template <bool NearestFirst, class F>
    void walk(const Ray<T, 3>& ray, T& tmax, F&& on_instance) const {
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>) {
            wide_.template walk<NearestFirst>(ray, tmax, on_instance);
            return;
        }
#endif
        Ray<T, 3> narrowed = ray;
        // The ray was checked by the caller and the tree is not empty: the walk's own checks are
        // skipped.
        traverse_ray(
            bvh_view(bvh_), narrowed, RaySlabData<T, 3>(ray),
            [&](const BvhNode<Aabb<T, 3>>& leaf) {
                for (std::uint32_t s = leaf.first; s < leaf.first + leaf.count; ++s) {
                    const bool stop = on_instance(bvh_.primitive_indices[s]);
                    narrowed.tmax = tmax;
                    if (stop) return true;
                }
                return false;
            },
            NoStats{});
    }

    Bvh<Aabb<T, 3>> bvh_;
#if defined(__SSE2__)
    scene_detail::WideTop4 wide_;  // float scenes: the same tree, four children a node
#endif
    std::vector<Entry> entries_;  // by the tree's primitive index
};

/// The batch size from which closest_hits and any_hits trace through a SceneRayTop made for the
/// call: below it, making one costs more than it saves.
template <class T>
std::size_t ray_top_min_rays(const Scene<T>& scene) {
    return 64 + 4 * scene.instance_count();
}

/// hits[i] = closest_hit(scene, rays[i]) for every ray, on `threads` threads (0 = every core, 1 =
/// the calling thread; several only when bvhkit has oneTBB) or on an Executor. A batch of at least
/// ray_top_min_rays rays goes through one SceneRayTop made for the call (so of two instances hit
/// at exactly the same t, the one it reaches first wins, which may be another than closest_hit's);
/// otherwise each ray takes closest_hit. Rays go in fixed chunks and each answer is its ray's
/// alone, so the answers are the same for any thread count. A geometry's ray tree is built by the
/// first ray to reach it (once, under call_once), or for every geometry by the SceneRayTop's
/// constructor, on the calling thread. Error when the spans' lengths differ.
template <class T>
void closest_hits(const Scene<T>& scene, std::span<const Ray<T, 3>> rays,
                  std::span<SceneHit<T>> hits, const Executor& exec) {
    scene_detail::check_batch(rays.size(), hits.size(), "closest_hits(Scene): hits");
    if (rays.size() >= ray_top_min_rays(scene)) {
        const SceneRayTop<T> top(scene);
        exec.parallel_for(rays.size(), ray_batch_grain, [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) hits[i] = top.closest_hit(rays[i]);
        });
        return;
    }
    exec.parallel_for(rays.size(), ray_batch_grain, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) hits[i] = closest_hit(scene, rays[i]);
    });
}
template <class T>
void closest_hits(const Scene<T>& scene, std::span<const Ray<T, 3>> rays,
                  std::span<SceneHit<T>> hits, unsigned threads = 0) {
    closest_hits(scene, rays, hits, Executor(threads));
}

/// occluded[i] = any_hit(scene, rays[i]) (1 or 0) for every ray; threads and the SceneRayTop as
/// closest_hits.
template <class T>
void any_hits(const Scene<T>& scene, std::span<const Ray<T, 3>> rays,
              std::span<std::uint8_t> occluded, const Executor& exec) {
    scene_detail::check_batch(rays.size(), occluded.size(), "any_hits(Scene): occluded");
    if (rays.size() >= ray_top_min_rays(scene)) {
        const SceneRayTop<T> top(scene);
        exec.parallel_for(rays.size(), ray_batch_grain, [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) occluded[i] = std::uint8_t(top.any_hit(rays[i]));
        });
        return;
    }
    exec.parallel_for(rays.size(), ray_batch_grain, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) occluded[i] = std::uint8_t(any_hit(scene, rays[i]));
    });
}
template <class T>
void any_hits(const Scene<T>& scene, std::span<const Ray<T, 3>> rays,
              std::span<std::uint8_t> occluded, unsigned threads = 0) {
    any_hits(scene, rays, occluded, Executor(threads));
}

}  // namespace bvhkit
