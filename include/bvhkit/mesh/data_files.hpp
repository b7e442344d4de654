#pragma once
// Finding the test and benchmark meshes by file name. Two small meshes ship in the repository's
// data/ folder; the larger scanned ones live in a data folder of the user's
// (scripts/fetch-meshes.sh fills one). The search order: the BVHKIT_DATA_DIR environment variable,
// the folder the build was configured with, then the repository's data/ folder.
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace bvhkit {

/// The folders searched for a mesh by name, in order; `configured` and `shipped` are the folders
/// the build knows (either may be empty).
inline std::vector<std::filesystem::path> data_search_path(const std::filesystem::path& configured,
                                                           const std::filesystem::path& shipped) {
    std::vector<std::filesystem::path> dirs;
    if (const char* env = std::getenv("BVHKIT_DATA_DIR"); env && *env) dirs.emplace_back(env);
    if (!configured.empty()) dirs.push_back(configured);
    if (!shipped.empty()) dirs.push_back(shipped);
    return dirs;
}

/// The first regular file called `name` in `dirs`, or an empty path when none has it.
inline std::filesystem::path find_data_file(std::string_view name,
                                            const std::vector<std::filesystem::path>& dirs) {
    for (const auto& d : dirs) {
        std::error_code ec;
        const auto p = d / std::string(name);
        if (std::filesystem::is_regular_file(p, ec)) return p;
    }
    return {};
}

}  // namespace bvhkit
