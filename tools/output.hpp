#pragma once
// What the bench and info subcommands share: the meshes a bench runs on when none is named, and
// printing result rows as a table (for people) or a JSON array (for scripts).
#include <filesystem>
#include <string>
#include <vector>

#include "report.hpp"

namespace bvhkit::tools {

/// The folders meshes are looked up in by name (bvhkit/mesh/data_files.hpp).
std::vector<std::filesystem::path> data_dirs();

/// The bunny and igea when a data folder has them, else `fallback` (a generator spec).
std::vector<std::string> default_bench_meshes(const char* fallback = "sphere:subdiv=7");

void print_rows(const std::vector<bench::Row>& rows, bool json);

}  // namespace bvhkit::tools
