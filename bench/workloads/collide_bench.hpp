#pragma once
// Workloads C1 and C2 of docs/workloads.md: a mesh against a copy of itself under 1,000
// random rigid poses (yes/no and all-pairs collision), and distance at the poses where the copies
// do not collide; bvhkit with each of its volume types and (when installed) FCL 0.7 with
// BVHModel<OBBRSS> and BVHModel<OBB>, in the same process, one thread, medians of repetitions
// interleaved round-robin so that load on the machine affects every library alike.
#include <cstdio>
#include <string>
#include <vector>

#include "report.hpp"

namespace bvhkit::bench {

struct CollideBenchOptions {
    std::vector<std::string> meshes;  // files or generator specs
    int repetitions = 3;
    std::size_t poses = 1000;
    std::size_t distance_poses = 0;  // C2: at most this many non-colliding poses (0: all)
    std::uint64_t seed = 2026;
};

/// One row per (workload, mesh, library, volume, mode); bvhkit rows carry `vs_fcl_best` (FCL's
/// best queries/s over its volume types divided into bvhkit's). Agreement between the libraries'
/// answers is printed to `progress`.
std::vector<Row> run_collide_bench(const CollideBenchOptions& options, std::FILE* progress);

bool have_fcl();

}  // namespace bvhkit::bench
