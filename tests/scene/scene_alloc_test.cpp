// Scene::add_instance when the growth of the scene's own record table fails: std::bad_alloc comes
// out and the scene is as it was, with no live id that lacks its record (the record's slot must
// exist before the top-level tree hands the slot out). The global operator new of this test
// program is replaced by one that, while armed on the calling thread, fails the allocations a
// std::vector<SceneInstance<float>> makes when it doubles (a power-of-two count of records, two
// or more); unarmed, and on every other thread, it is malloc. The top-level tree's own
// allocations are not failed: its exception safety is the dynamic tree's, not the scene's.
#include <gtest/gtest.h>

#include <bit>
#include <cstdlib>
#include <new>
#include <vector>

#include "bvhkit/scene/scene.hpp"

namespace {
thread_local bool armed = false;
thread_local int failed = 0;

bool record_table_growth(std::size_t size) {
    constexpr std::size_t record = sizeof(bvhkit::SceneInstance<float>);
    return size % record == 0 && size / record >= 2 && std::has_single_bit(size / record);
}
}  // namespace

// Not inlined: GCC would otherwise see malloc and free meet operator new and delete at the call
// sites (-Wmismatched-new-delete), which this replacement makes them.
[[gnu::noinline]] void* operator new(std::size_t size) {
    if (armed && record_table_growth(size)) {
        ++failed;
        throw std::bad_alloc();
    }
    if (void* p = std::malloc(size ? size : 1)) return p;
    throw std::bad_alloc();
}
[[gnu::noinline]] void* operator new[](std::size_t size) {
    return ::operator new(size);
}
[[gnu::noinline]] void operator delete(void* p) noexcept {
    std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept {
    std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p) noexcept {
    std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p, std::size_t) noexcept {
    std::free(p);
}

namespace bvhkit {
namespace {

TEST(SceneAllocation, FailedRecordGrowthLeavesNoLiveIdWithoutARecord) {
    Scene<float> scene;
    BasicTriangleMesh<float> tri;
    tri.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    tri.triangles = {{0, 1, 2}};
    const GeometryId g = scene.add_mesh(tri);
    for (int i = 0; i < 300; ++i) {
        Transform<float> pose;
        pose.translation = {float(i), 0, 0};
        const std::size_t before = scene.instance_count();
        armed = true;
        try {
            (void)scene.add_instance(g, pose);
        } catch (const std::bad_alloc&) {
        }
        armed = false;
        // Every live id has its record: validate() checks each one's geometry and box.
        ASSERT_NO_THROW(scene.validate()) << "instance " << i;
        if (scene.instance_count() == before) (void)scene.add_instance(g, pose);  // unarmed
        ASSERT_EQ(scene.instance_count(), before + 1);
        scene.validate();
    }
    EXPECT_GE(failed, 5);  // the table doubled (and failed) at 2, 4, 8, ..., 256 records
}

}  // namespace
}  // namespace bvhkit
