#pragma once
// Workloads D1, D2, D3 and D4 of docs/workloads.md: the dynamic tree as a broadphase, against Box2D
// 2.4.1's b2BroadPhase (D1, 2D) and Bullet's btDbvtBroadphase (D2, 3D) in the same process.
#include <cstdio>
#include <vector>

#include "report.hpp"

namespace bvhkit::bench {

struct DynamicBenchConfig {
    int n = 100000;  // boxes in D1 and D2 (D3 starts from n / 10)
    int steps = 40;  // simulation steps in D1 and D2 (D3: rounds of 1,000 operations)
    int reps = 3;    // repetitions; medians are reported
    bool d1 = true, d2 = true, d3 = true, d4 = true;
};

/// Runs the workloads and returns one row per (workload, library) with the fields workload,
/// library, build_ms, step_ms, speedup (peer step ms / bvhkit step ms, on the peer's row), pairs,
/// agree, height, sah_cost, area_ratio, touched (moves that restructured the tree). Progress goes
/// to `log`.
std::vector<Row> run_dynamic_bench(const DynamicBenchConfig& config, std::FILE* log);

/// D4: closest-hit ray casts, long and short, on D1's boxes (dynamic_cast_bench.cpp): rows with
/// step_ms (all rays), speedup on the peer's row, pairs (rays that hit), nodes_per_ray (bvhkit)
/// and agree (the same closest fraction for every ray).
void dynamic_ray_casts(const DynamicBenchConfig& config, std::FILE* log, std::vector<Row>& rows);

}  // namespace bvhkit::bench
