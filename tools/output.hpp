#pragma once
// What the bench and info subcommands share: the meshes a bench runs on when none is named, and
// printing result rows as a table (for people) or a JSON array (for scripts).
#include <string>
#include <vector>

#include "report.hpp"

namespace bvhkit::tools {

/// The shared bunny and igea when ../shared/data is present, else `fallback` (a generator spec).
std::vector<std::string> default_bench_meshes(const char* fallback = "sphere:subdiv=7");

void print_rows(const std::vector<bench::Row>& rows, bool json);

}  // namespace bvhkit::tools
