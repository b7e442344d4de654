#pragma once
// Saved trees (docs/serialization.md): for a TriangleBvh<float> over each mesh, the time to save,
// load (copied) and map (in place) its file, what each adds to the process's own memory, and
// incoherent rays (R2) through the mapped tree against the same tree in memory.
#include <cstdio>
#include <string>
#include <vector>

#include "report.hpp"

namespace bvhkit::bench {

struct FileBenchOptions {
    std::vector<std::string> meshes;  // files or generator specs
    int repetitions = 5;
    std::size_t random_rays = 200000;  // R2
};

/// One row per (mesh, operation): ms, and for load and map the growth of resident anonymous and
/// file-backed memory (Linux; blank elsewhere).
std::vector<Row> run_file_bench(const FileBenchOptions& options, std::FILE* progress);

}  // namespace bvhkit::bench
