// World boxes from support queries on the geometry's hull (six climbs over the hull's neighbours
// per pose) against the extent of every mesh vertex under the stored pose, taken in long double
// (exact for float meshes, 2^-64 relative for double ones, far inside the box's pad): the box holds
// it and is within a few spacings of it. Hulls large enough to climb (a sphere of 642 vertices, a
// sphere clamped to a box, whose flat facets hold many coplanar vertices that tie along the axes,
// a needle),
// random rotations and exact ones (the identity and quarter turns: every axis query ties), far from
// the origin and at tiny and large scales.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/scene/scene.hpp"
#include "scene_support.hpp"

// A namespace of its own: the unity build joins this file with the other scene tests.
namespace bvhkit::hull_box_cases {
namespace {

using scene_test::LD;

/// A sphere clamped to the box [-h, h]: six flat facets holding many coplanar hull vertices (the
/// axis directions tie among them), and curved edges and corners.
TriangleMesh clamped_sphere(Vec3f h) {
    TriangleMesh m = make_sphere(4);
    for (auto& v : m.vertices)
        for (std::size_t a = 0; a < 3; ++a) v[a] = std::clamp(v[a], -h[a], h[a]);
    return m;
}

template <class T>
std::vector<Mat3<T>> rotations(SplitMix64& rng) {
    std::vector<Mat3<T>> r;
    r.push_back(Mat3<T>{});  // identity
    Mat3<T> quarter;         // a quarter turn about z
    quarter.row[0] = {T(0), T(-1), T(0)};
    quarter.row[1] = {T(1), T(0), T(0)};
    r.push_back(quarter);
    Mat3<T> turn;  // a signed permutation of all three axes
    turn.row[0] = {T(0), T(0), T(1)};
    turn.row[1] = {T(-1), T(0), T(0)};
    turn.row[2] = {T(0), T(-1), T(0)};
    r.push_back(turn);
    for (int i = 0; i < 12; ++i) r.push_back(scene_test::random_rotation<T>(rng));
    return r;
}

template <class T>
void boxes_hold_the_posed_mesh(const TriangleMesh& mesh_f, double scale, double offset,
                               std::uint64_t seed, const char* what) {
    SplitMix64 rng(seed);
    BasicTriangleMesh<T> mesh;
    for (const Vec3f& v : mesh_f.vertices) mesh.vertices.push_back(Vec<T, 3>(Vec3d(v) * scale));
    mesh.triangles = mesh_f.triangles;
    Scene<T> scene;
    const GeometryId g = scene.add_mesh(mesh);
    ASSERT_TRUE(scene.geometry(g).hull().climbs()) << what << ": the test wants a climbing hull";
    for (const Mat3<T>& rotation : rotations<T>(rng)) {
        Transform<T> pose;
        pose.rotation = rotation;
        for (std::size_t a = 0; a < 3; ++a)
            pose.translation[a] = T(offset + rng.uniform(-4.0, 4.0) * scale);
        const InstanceId id = scene.add_instance(g, pose);
        const SceneInstance<T>& r = scene.instance(id);
        const Aabb<T, 3>& box = scene.world_box(id);
        for (std::size_t a = 0; a < 3; ++a) {
            LD lo = INFINITY, hi = -INFINITY;
            for (const auto& v : mesh.vertices) {
                const LD w = LD(r.pose.rotation[a][0]) * v[0] + LD(r.pose.rotation[a][1]) * v[1] +
                             LD(r.pose.rotation[a][2]) * v[2] + LD(r.pose.translation[a]);
                lo = std::min(lo, w), hi = std::max(hi, w);
            }
            const LD spacing =
                LD(std::nextafter(T(hi), std::numeric_limits<T>::infinity())) - LD(T(hi));
            // As in scene_poses_test: two spacings of the outward rounding and the pad's eps_T
            // terms of the mesh's size, and the bound of the extremes taken in double.
            const LD size = LD(scale) * 4;
            const LD slack = 2 * spacing + 64 * LD(std::numeric_limits<T>::epsilon()) * size +
                             8 * LD(std::numeric_limits<double>::epsilon()) *
                                 (std::fabs(LD(r.pose.translation[a])) + size);
            EXPECT_LE(LD(box.min[a]), lo) << what << ", axis " << a;
            EXPECT_GE(LD(box.max[a]), hi) << what << ", axis " << a;
            EXPECT_LE(lo - LD(box.min[a]), slack) << what << ", axis " << a;
            EXPECT_LE(LD(box.max[a]) - hi, slack) << what << ", axis " << a;
        }
    }
    scene.validate();
}

TEST(SceneHullBoxes, SupportQueriesHoldEveryVertex) {
    const TriangleMesh sphere = make_sphere(3);
    const TriangleMesh box = clamped_sphere(Vec3f(0.75f, 0.5f, 0.875f));
    TriangleMesh needle = make_torus(32, 8, 1.0f, 0.01f);
    for (auto& v : needle.vertices) v = Vec3f(v[0] * 1e-4f, v[1] * 1e-4f, v[2] * 50.0f);
    std::uint64_t seed = 1;
    for (const auto& [mesh, name] :
         {std::pair{&sphere, "sphere"}, std::pair{&box, "clamped sphere"},
          std::pair{static_cast<const TriangleMesh*>(&needle), "needle"}}) {
        boxes_hold_the_posed_mesh<float>(*mesh, 1.0, 0.0, seed++, name);
        boxes_hold_the_posed_mesh<float>(*mesh, 1.0, 1e5, seed++, name);
        boxes_hold_the_posed_mesh<float>(*mesh, 1e-20, 0.0, seed++, name);
        boxes_hold_the_posed_mesh<double>(*mesh, 1.0, 1e6, seed++, name);
        boxes_hold_the_posed_mesh<double>(*mesh, 1.0, 1e12, seed++, name);
        boxes_hold_the_posed_mesh<double>(*mesh, 1e30, 0.0, seed++, name);
    }
}

}  // namespace
}  // namespace bvhkit::hull_box_cases
