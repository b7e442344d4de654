#pragma once
// Helpers shared by every test program: where the shared meshes are, and how big a randomized test
// should be (the sanitizer build sets BVHKIT_TEST_SCALE=small to keep CI fast; Release runs in
// full).
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "bvhkit/mesh/data_files.hpp"

namespace bvhkit::test {

/// Where the tests look for meshes by name: BVHKIT_DATA_DIR from the environment, the folder the
/// build was configured with, then the repository's data/ (spot.obj and teapot.obj ship there).
inline std::vector<std::filesystem::path> data_dirs() {
    return data_search_path(BVHKIT_DATA_DIR, BVHKIT_SHIPPED_DATA_DIR);
}

inline std::string data_dirs_text() {
    std::string s;
    for (const auto& d : data_dirs()) s += (s.empty() ? "" : ", ") + d.string();
    return s;
}

/// Path of a test mesh, or an empty path when no data folder has it (callers GTEST_SKIP).
inline std::filesystem::path shared_mesh(std::string_view name) {
    return find_data_file(name, data_dirs());
}

inline bool small_scale() {
    const char* s = std::getenv("BVHKIT_TEST_SCALE");
    return s && std::string_view(s) == "small";
}

/// BVHKIT_TEST_SCALE=full: the acceptance-size runs (slow brute-force references), not run in CI.
inline bool full_scale() {
    const char* s = std::getenv("BVHKIT_TEST_SCALE");
    return s && std::string_view(s) == "full";
}

/// `full` in the Release run, `full / divisor` (at least 1) under the sanitizers.
inline std::size_t scaled(std::size_t full, std::size_t divisor = 20) {
    return small_scale() ? std::max<std::size_t>(1, full / divisor) : full;
}

/// Whether a and b hold the same bytes (+0 and -0 differ, a NaN equals itself): for answers that
/// must be identical, not merely equal.
template <class T>
bool same_bits(const T& a, const T& b) {
    return std::memcmp(&a, &b, sizeof(T)) == 0;
}

/// Test names for tests parameterized by a mesh file name ("teapot.obj" -> "teapot_obj").
struct MeshFileName {
    template <class Info>
    std::string operator()(const Info& p) const {
        std::string n = p.param;
        for (char& c : n)
            if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
        return n;
    }
};

/// The extreme-scale sweeps: check(scale, offset) for scale = 10^k, k = lowest..highest by step,
/// at the origin and offset_sizes * scale from it; stops at the first failure (the scales after it
/// would mostly repeat it).
template <class F>
void for_each_scale(int lowest, int highest, int step, double offset_sizes, F&& check) {
    for (int k = lowest; k <= highest; k += step) {
        const double scale = std::pow(10.0, k);
        for (const double offset : {0.0, offset_sizes * scale}) {
            char offset_text[32];
            std::snprintf(offset_text, sizeof offset_text, "%g", offset);
            SCOPED_TRACE("scale 1e" + std::to_string(k) + " offset " + offset_text);
            check(scale, offset);
            if (::testing::Test::HasFailure()) return;
        }
    }
}

}  // namespace bvhkit::test

#define BVHKIT_REQUIRE_MESH(var, name)                                                      \
    const auto var = ::bvhkit::test::shared_mesh(name);                                     \
    if (var.empty())                                                                        \
    GTEST_SKIP() << "mesh " << name << " not found in " << ::bvhkit::test::data_dirs_text() \
                 << " (scripts/fetch-meshes.sh, then set BVHKIT_DATA_DIR)"
