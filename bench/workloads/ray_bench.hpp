#pragma once
// Workload R of docs/workloads.md: build, R1 primary rays, R2 incoherent rays, R3 occlusion,
// for bvhkit and (when installed) Embree 3 in the same process, one thread each, medians of
// repetitions.
#include <span>
#include <string>
#include <vector>

#include "bvhkit/math/ray.hpp"
#include "report.hpp"

namespace bvhkit {
template <class T>
class TriangleBvh;
}

namespace bvhkit::bench {

struct RayBenchOptions {
    std::vector<std::string> meshes;  // files or generator specs
    int repetitions = 5;
    std::uint32_t camera_size = 1024;   // R1: camera_size^2 rays
    std::size_t random_rays = 1000000;  // R2, R3
    std::string builder = "binned-sah";
    /// Also the high-quality builds: bvhkit with spatial splits (rows bvhkit-sbvh) and Embree's
    /// RTC_BUILD_QUALITY_HIGH (embree3-high).
    bool high_quality = false;
};

/// One row per (workload, mesh, library); bvhkit's rows carry `speedup` = Embree ms / bvhkit ms.
std::vector<Row> run_ray_bench(const RayBenchOptions& options, std::FILE* progress);

bool have_embree();

/// bvhkit's timed ray loop (ray_timed_calls.cpp, a file of its own): the closest hits (or, with
/// `occlusion`, any hits) of every ray; returns how many rays hit.
std::size_t trace_rays(const TriangleBvh<float>& tree, std::span<const Ray3f> rays, bool occlusion);

}  // namespace bvhkit::bench
