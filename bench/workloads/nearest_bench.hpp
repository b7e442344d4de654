#pragma once
// Workload N1 of ../shared/BENCHMARKS.md: closest point, squared distance and triangle for 100,000
// points uniform in the mesh's box grown by 10%, for bvhkit (ClosestPointMesh) and CGAL 5.5's
// AABB_tree (closest_point_and_primitive after accelerate_distance_queries()) in the same process,
// one thread each, medians of interleaved repetitions. With `scaling`, also bvhkit alone on one
// thread against all threads (oneTBB): batched closest points and the parallel builders.
#include <string>
#include <vector>

#include "report.hpp"

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

}  // namespace bvhkit::bench
