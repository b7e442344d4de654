// bvhkit's timed loops of workload S3, in a file of their own as ray_timed_calls.cpp's are.
#include "bvhkit/scene/rays.hpp"
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

}  // namespace bvhkit::bench
