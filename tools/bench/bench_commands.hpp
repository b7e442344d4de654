#pragma once
// One function per workload of bvhkit-bench; argv[0] is the workload's name. They return the
// process exit code (0 ok, 1 error, 2 bad usage) and may throw bvhkit::Error, which main() reports.
#include <string>
#include <vector>

namespace bvhkit::tools {

int bench_rays(int argc, char** argv);       // tools/bench/workloads.cpp
int bench_instances(int argc, char** argv);  // tools/bench/workloads.cpp
int bench_nearest(int argc, char** argv);    // tools/bench/workloads.cpp
int bench_files(int argc, char** argv);      // tools/bench/workloads.cpp
int bench_scene(int argc, char** argv);      // tools/bench/workloads.cpp
int bench_dynamic(int argc, char** argv);    // tools/bench/dynamic.cpp
int bench_collide(int argc, char** argv);    // tools/bench/collide.cpp

/// The bunny and igea when a data folder has them, else `fallback` (a generator spec).
std::vector<std::string> default_bench_meshes(const char* fallback = "sphere:subdiv=7");

}  // namespace bvhkit::tools
