#pragma once
// Helpers shared by every test program: where the shared meshes are, and how big a randomized test
// should be (the sanitizer build sets BVHKIT_TEST_SCALE=small to keep CI fast; Release runs in
// full).
#include <gtest/gtest.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

namespace bvhkit::test {

inline std::filesystem::path data_dir() {
    return BVHKIT_DATA_DIR;
}

/// Path of a shared mesh, or an empty path when ../shared/data is absent (callers GTEST_SKIP).
inline std::filesystem::path shared_mesh(std::string_view name) {
    const auto p = data_dir() / std::string(name);
    return std::filesystem::exists(p) ? p : std::filesystem::path{};
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

}  // namespace bvhkit::test

#define BVHKIT_REQUIRE_MESH(var, name)                                                          \
    const auto var = ::bvhkit::test::shared_mesh(name);                                         \
    if (var.empty())                                                                            \
    GTEST_SKIP() << "shared mesh " << name << " not found under " << ::bvhkit::test::data_dir() \
                 << "; skipping"
