// Google Benchmark micro-benchmarks: build per builder, traversal per ray kind. Inputs: a
// procedural sphere (always there) and the bunny when a data folder has it (data_files.hpp).
#include <benchmark/benchmark.h>

#include <filesystem>

#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "ray_sets.hpp"

namespace {

using namespace bvhkit;

const TriangleMesh& mesh(int which) {
    static const TriangleMesh sphere = load_mesh("sphere:subdiv=7");
    static const TriangleMesh bunny = [] {
        const auto p = std::filesystem::path(BVHKIT_SHARED_DATA) / "stanford-bunny.obj";
        return std::filesystem::exists(p) ? load_mesh(p.string()) : load_mesh("sphere:subdiv=6");
    }();
    return which == 0 ? sphere : bunny;
}

void build(benchmark::State& state) {
    const auto configs = all_builder_configurations();
    const auto& [name, options] = configs[state.range(1)];
    state.SetLabel(name);
    const TriangleMesh& m = mesh(int(state.range(0)));
    for (auto _ : state) {
        TriangleBvh<float> bvh(m, options);
        benchmark::DoNotOptimize(bvh.bvh().nodes.data());
    }
    state.counters["tris/s"] = benchmark::Counter(double(m.triangle_count()),
                                                  benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(build)->ArgsProduct({{0, 1}, {0, 1, 2, 3, 4, 5, 6, 7}})->Unit(benchmark::kMillisecond);

enum RayKind { Primary, Incoherent, Occlusion };

void trace(benchmark::State& state) {
    const TriangleMesh& m = mesh(int(state.range(0)));
    const auto kind = RayKind(state.range(1));
    static const char* names[] = {"R1 closest", "R2 closest", "R3 any-hit"};
    state.SetLabel(names[kind]);
    const TriangleBvh<float> bvh(m);
    const auto rays =
        kind == Primary ? camera_rays(m.bounds(), 256, 256) : random_rays(m.bounds(), 65536, 1);
    for (auto _ : state) {
        std::size_t hits = 0;
        for (const auto& r : rays)
            hits += kind == Occlusion ? bvh.any_hit(r) : bool(bvh.closest_hit(r));
        benchmark::DoNotOptimize(hits);
    }
    state.counters["rays/s"] =
        benchmark::Counter(double(rays.size()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(trace)
    ->ArgsProduct({{0, 1}, {Primary, Incoherent, Occlusion}})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
