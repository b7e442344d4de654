// HugePageAllocator (bvh/huge_page_allocator.hpp): on Linux, arrays of 2 MB or more on 2 MB
// boundaries and advised for transparent huge pages (read back from the kernel's own account of the
// mapping, /proc/self/smaps); smaller arrays from the default allocator; contents kept through
// growth. And the wide ray layout of a large mesh placed with it.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bvhkit/bvh/huge_page_allocator.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/ray_wide.hpp"
#include "bvhkit/triangle_bvh.hpp"

using namespace bvhkit;

namespace {

constexpr std::size_t huge_page = std::size_t(2) << 20;

[[maybe_unused]] bool on_huge_page_boundary(const void* p) {
    return reinterpret_cast<std::uintptr_t>(p) % huge_page == 0;
}

#if defined(__linux__)
/// Whether the kernel has transparent huge pages at all (without them madvise refuses the advice).
bool kernel_has_thp() {
    return std::ifstream("/sys/kernel/mm/transparent_hugepage/enabled").good();
}

/// The VmFlags line of the mapping of /proc/self/smaps that holds `p` ("" if none is found).
std::string vm_flags_of(const void* p) {
    const auto address = reinterpret_cast<std::uintptr_t>(p);
    std::ifstream smaps("/proc/self/smaps");
    std::string line;
    bool inside = false;
    while (std::getline(smaps, line)) {
        std::uintptr_t lo = 0, hi = 0;
        char dash = 0;
        std::istringstream head(line);
        if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
            inside = lo <= address && address < hi;
            continue;
        }
        if (inside && line.rfind("VmFlags:", 0) == 0) return line;
    }
    return "";
}
#endif

}  // namespace

TEST(HugePageAllocator, LargeArraysOnHugePageBoundariesSmallOnesNot) {
    using Alloc = HugePageAllocator<float>;
    EXPECT_FALSE(Alloc::uses_huge_pages(huge_page / sizeof(float) - 1));
#if defined(__linux__)
    EXPECT_TRUE(Alloc::uses_huge_pages(huge_page / sizeof(float)));
    EXPECT_TRUE(Alloc::uses_huge_pages(std::size_t(-1) / 2 + 1));  // n * 4 would wrap to 0
#endif
    std::vector<float, Alloc> small(1000, 1.0f);
    EXPECT_EQ(small[999], 1.0f);

    std::vector<float, Alloc> large;
    for (std::uint32_t i = 0; i < 3 * huge_page / sizeof(float); ++i) large.push_back(float(i));
    for (std::uint32_t i = 0; i < large.size(); i += 4097) ASSERT_EQ(large[i], float(i));
#if defined(__linux__)
    EXPECT_TRUE(on_huge_page_boundary(large.data()));
    // The kernel records the advice on the mapping ("hg"), whether or not it can grant the pages.
    if (!kernel_has_thp()) GTEST_SKIP() << "this kernel has no transparent huge pages";
    const std::string flags = vm_flags_of(large.data());
    // Some sandboxes (gVisor) list the mappings without their flags.
    if (flags.empty()) GTEST_SKIP() << "/proc/self/smaps gives no VmFlags for the array";
    EXPECT_NE(flags.find(" hg"), std::string::npos) << flags;
#endif
}

TEST(HugePageAllocator, RefusesAnImpossibleSize) {
    HugePageAllocator<double> alloc;
    EXPECT_THROW((void)alloc.allocate(std::size_t(-1) / sizeof(double)), std::bad_array_new_length);
}

#if defined(__SSE2__)
TEST(HugePageAllocator, ALargeMeshesRayLayoutLiesOnHugePages) {
    // 327,680 triangles: the four-wide groups take about 13 MB.
    const TriangleMesh mesh = make_sphere(7);
    const TriangleBvh<float> tree(mesh);
    const auto& bvh = tree.bvh();
    const auto& index = bvh.primitive_indices;
    const auto corners = [&](std::uint32_t s) {
        const auto& v = mesh.triangles[index[s]];
        return Triangle<float>{mesh.vertices[v[0]], mesh.vertices[v[1]], mesh.vertices[v[2]]};
    };
    const WideRayBvh<4> wide =
        make_wide_ray_bvh<4>(bvh, corners, [&](std::uint32_t s) { return index[s]; });
    ASSERT_GE(wide.groups.size() * sizeof(wide.groups[0]), huge_page);
#if defined(__linux__)
    EXPECT_TRUE(on_huge_page_boundary(wide.groups.data()));
    const std::string flags = vm_flags_of(wide.groups.data());
    if (kernel_has_thp() && !flags.empty()) {
        EXPECT_NE(flags.find(" hg"), std::string::npos) << flags;
    }
#endif
}
#endif
