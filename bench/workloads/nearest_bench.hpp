#pragma once
// Workload N1 of docs/workloads.md: closest point, squared distance and triangle for 100,000
// points uniform in the mesh's box grown by 10%, for bvhkit (ClosestPointMesh) and CGAL 5.5's
// AABB_tree (closest_point_and_primitive after accelerate_distance_queries()) in the same process,
// one thread each, medians of interleaved repetitions. With `scaling`, also bvhkit alone on one
// thread against all threads (oneTBB): batched closest points and the parallel builders.
#include <span>
#include <string>
#include <vector>

#include "bvhkit/math/vec.hpp"
#include "report.hpp"

namespace bvhkit {
template <class T>
class ClosestPointMesh;
template <class T>
struct MeshPoint;
}  // namespace bvhkit

namespace bvhkit::bench {

struct NearestBenchOptions {
    std::vector<std::string> meshes;  // files or generator specs
    int repetitions = 5;
    std::size_t points = 100000;
    std::string builder = "binned-sah";
    bool scaling = false;
};

/// One row per (workload, mesh, library): workload, library, mesh, build_ms, queries_per_s; the
/// bvhkit N1 row also carries speedup = bvhkit queries/s over CGAL's.
std::vector<Row> run_nearest_bench(const NearestBenchOptions& options, std::FILE* progress);

bool have_cgal();

/// bvhkit's timed loop (nearest_timed_calls.cpp, a file of its own): the closest point of every
/// point, on the calling thread.
void closest_points_one_thread(const ClosestPointMesh<float>& mesh, std::span<const Vec3f> points,
                               std::span<MeshPoint<float>> out);

}  // namespace bvhkit::bench
