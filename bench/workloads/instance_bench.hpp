#pragma once
// Workload S3 of issue 40 (docs/workloads.md): rays through a crowd of instances of one mesh,
// bvhkit's Scene against Embree 3's instancing (RTC_GEOMETRY_TYPE_INSTANCE) in the same process,
// one thread each: build, then closest and any hit for camera rays (R1-style) and random rays
// through the crowd's box (R2-style), medians of interleaved repetitions, and the answers
// compared ray by ray.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/math/aabb.hpp"
#include "bvhkit/math/ray.hpp"
#include "bvhkit/math/transform.hpp"
#include "report.hpp"

namespace bvhkit {
template <class T>
class Scene;
template <class T>
struct SceneHit;
}  // namespace bvhkit

namespace bvhkit::bench {

struct InstanceBenchOptions {
    std::string mesh;                             // a file or a generator spec
    std::vector<std::size_t> counts{100, 10000};  // instances per scene
    int repetitions = 5;
    std::uint32_t camera_size = 1024;   // R1-style: camera_size^2 rays
    std::size_t random_rays = 1000000;  // R2-style
    /// The crowd's density: the instances' bounding spheres fill this fraction of the crowd's
    /// cube (spheres placed at random, so neighbours overlap now and then).
    double density = 0.3;
    std::uint64_t seed = 1;
};

/// `count` poses of a mesh with box `bounds`: each a rotation uniform over SO(3) about the box's
/// centre c, then c moved to a point uniform in a cube centred on the origin whose side makes the
/// bounding spheres (radius half the box's diagonal) fill `density` of it. x -> R (x - c) + p.
std::vector<Transform<float>> crowd_poses(const Aabb3f& bounds, std::size_t count, double density,
                                          std::uint64_t seed);

/// One row per (workload, instance count, library): bvhkit (one call per ray), bvhkit-batch (the
/// batch call on all the rays, the flat top level's build included) and embree3 (rtcIntersect1 /
/// rtcOccluded1 per ray). bvhkit's rows carry `speedup` = Embree ms /
/// bvhkit ms and, with Embree, `disagree`: the rays whose answers differ (hit or miss, instance,
/// or t beyond a relative 1e-4 or an absolute 1e-6 of the crowd's size), of which `ties` (two
/// instances hit at the same t), and of the rest how many each library got right by a brute-force
/// referee in double (`bvhkit_right`, `embree_right`).
std::vector<Row> run_instance_bench(const InstanceBenchOptions& options, std::FILE* progress);

/// bvhkit's timed loop (instance_timed_calls.cpp): closest hits (or, with `occlusion`, any hits)
/// of every ray over the scene; returns how many rays hit.
std::size_t trace_scene_rays(const Scene<float>& scene, std::span<const Ray3f> rays,
                             bool occlusion);

/// The same through the batch calls (closest_hits into `hits`, or any_hits into `flags`, each as
/// long as `rays`), which trace a large batch through a flat top level made for the call.
std::size_t trace_scene_batch(const Scene<float>& scene, std::span<const Ray3f> rays,
                              bool occlusion, std::span<SceneHit<float>> hits,
                              std::span<std::uint8_t> flags);

}  // namespace bvhkit::bench
