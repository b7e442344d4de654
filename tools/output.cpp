#include "output.hpp"

#include <cstdio>
#include <filesystem>

namespace bvhkit::tools {

std::vector<std::string> default_bench_meshes(const char* fallback) {
    std::vector<std::string> meshes;
    for (const char* m : {"stanford-bunny.obj", "igea.ply"}) {
        const auto p = std::filesystem::path(BVHKIT_SHARED_DATA) / m;
        if (std::filesystem::exists(p)) meshes.push_back(p.string());
    }
    if (meshes.empty()) meshes.push_back(fallback);
    return meshes;
}

void print_rows(const std::vector<bench::Row>& rows, bool json) {
    if (json)
        bench::print_json(stdout, rows);
    else
        bench::print_table(stdout, rows);
}

}  // namespace bvhkit::tools
