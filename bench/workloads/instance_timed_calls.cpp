// bvhkit's timed loops of workload S3, in a file of their own as ray_timed_calls.cpp's are.
#include "bvhkit/scene/ray_batches.hpp"
#include "instance_bench.hpp"

namespace bvhkit::bench {

std::size_t trace_scene_rays(const Scene<float>& scene, std::span<const Ray3f> rays,
                             bool occlusion) {
    std::size_t hits = 0;
    if (occlusion)
        for (const Ray3f& r : rays) hits += any_hit(scene, r);
    else
        for (const Ray3f& r : rays) hits += bool(closest_hit(scene, r));
    return hits;
}

std::size_t trace_scene_batch(const Scene<float>& scene, std::span<const Ray3f> rays,
                              bool occlusion, std::span<SceneHit<float>> hits,
                              std::span<std::uint8_t> flags) {
    std::size_t n = 0;
    if (occlusion) {
        any_hits(scene, rays, flags, 1u);  // one thread, as every row of S3
        for (const std::uint8_t f : flags) n += f;
    } else {
        closest_hits(scene, rays, hits, 1u);
        for (const SceneHit<float>& h : hits) n += bool(h);
    }
    return n;
}

}  // namespace bvhkit::bench
