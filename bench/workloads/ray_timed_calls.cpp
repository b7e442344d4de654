// bvhkit's timed ray loops of workload R, alone in their file, as a renderer's would be in its own.
//
// Compiled inside ray_bench.cpp (which also holds Embree's calls, the table code and the other
// workloads' lambdas), the very same R1 loop ran slower: GCC's inlining budget is per file
// (--param inline-unit-growth). Embree's
// traversal is precompiled in its own library and never pays for the file it is called from;
// here bvhkit does not either. (The build stays in ray_bench.cpp: put here too, it made this file
// large enough for GCC's unit-growth limit to cost the loops their speed again.)
#include "bvhkit/triangle_bvh.hpp"
#include "ray_bench.hpp"

namespace bvhkit::bench {

std::size_t trace_rays(const TriangleBvh<float>& tree, std::span<const Ray3f> rays,
                       bool occlusion) {
    std::size_t hits = 0;
    if (occlusion)
        for (const Ray3f& r : rays) hits += tree.any_hit(r);
    else
        for (const Ray3f& r : rays) hits += bool(tree.closest_hit(r));
    return hits;
}

}  // namespace bvhkit::bench
