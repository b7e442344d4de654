#pragma once
// Workload S1 of docs/workloads.md: a collision manager called once per robot configuration. A
// six-link arm of capsules plus a gripper (robot_arm.hpp) among an environment of meshes, and for
// each of N random configurations: does the arm touch the environment or itself (links that are
// not neighbours in the chain), and, when it does not, how far is it from touching. bvhkit with a
// Scene<double> and FCL 0.7's DynamicAABBTreeCollisionManager over BVHModel<OBBRSS> (when
// installed), in the same process, medians of repetitions interleaved round-robin.
#include <cstdio>
#include <string>
#include <vector>

#include "report.hpp"

namespace bvhkit::bench {

struct SceneBenchOptions {
    /// The environment's meshes (files or generator specs), each scaled to `object_size` across
    /// and placed around the arm's base.
    std::vector<std::string> meshes;
    double object_size = 0.7;
    int repetitions = 3;
    std::size_t configurations = 10000;
    std::uint64_t seed = 2026;
    unsigned threads = 0;  // the batched rows: 0 = every core
};

/// One row per (library, mode); agreement of the answers (colliding flags on every
/// configuration, distances on the free ones) is printed to `progress` and set in the rows.
std::vector<Row> run_scene_bench(const SceneBenchOptions& options, std::FILE* progress);

/// The shared meshes S1 uses by default, as file names for find_data_file (about 100k triangles).
std::vector<std::string> scene_bench_default_meshes();

}  // namespace bvhkit::bench
