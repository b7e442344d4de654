#include "output.hpp"

#include <cstdio>
#include <filesystem>

#include "bvhkit/mesh/data_files.hpp"

namespace bvhkit::tools {

std::vector<std::filesystem::path> data_dirs() {
    return data_search_path(BVHKIT_SHARED_DATA, BVHKIT_SHIPPED_DATA);
}

void print_rows(const std::vector<bench::Row>& rows, bool json) {
    if (json)
        bench::print_json(stdout, rows);
    else
        bench::print_table(stdout, rows);
}

}  // namespace bvhkit::tools
