#pragma once
// What bvhkit and bvhkit-bench share: the folders meshes are found in, and printing result rows as
// a table (for people) or a JSON array (for scripts).
#include <filesystem>
#include <string>
#include <vector>

#include "report.hpp"

namespace bvhkit::tools {

/// The folders meshes are looked up in by name (bvhkit/mesh/data_files.hpp).
std::vector<std::filesystem::path> data_dirs();

void print_rows(const std::vector<bench::Row>& rows, bool json);

}  // namespace bvhkit::tools
