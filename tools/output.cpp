#include "output.hpp"

#include <cstdio>
#include <filesystem>

#include "bvhkit/mesh/data_files.hpp"

namespace bvhkit::tools {

std::vector<std::filesystem::path> data_dirs() {
    return data_search_path(BVHKIT_SHARED_DATA, BVHKIT_SHIPPED_DATA);
}

std::vector<std::string> default_bench_meshes(const char* fallback) {
    std::vector<std::string> meshes;
    for (const char* m : {"stanford-bunny.obj", "igea.ply"})
        if (const auto p = find_data_file(m, data_dirs()); !p.empty()) meshes.push_back(p.string());
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
