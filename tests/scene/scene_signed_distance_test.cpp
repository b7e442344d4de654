// Signed distance and contains over a Scene (scene/signed_distance.hpp) against references that
// share none of its arithmetic: cubes, whose signed distance is analytic (the box's distance
// function in the instance's frame, in long double), over unions of overlapping and touching
// instances at random poses, near and far from the origin, tiny and huge; icospheres, against
// brute force over the world-space mesh (long double distances and plane sides); an open box
// (a cube without its top) with the winding number rule, against the exact winding number summed
// in long double.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <thread>
#include <vector>

#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/scene/signed_distance.hpp"
#include "scene_support.hpp"

namespace bvhkit {
namespace {

using scene_test::LD;
using scene_test::V3;

/// The cube [-h, h]^3, outward counter-clockwise; without its top (+z) face when `open`.
template <class T>
BasicTriangleMesh<T> cube_mesh(T h, bool open = false) {
    BasicTriangleMesh<T> m;
    for (int k = 0; k < 8; ++k)
        m.vertices.push_back({(k & 1) ? h : -h, (k & 2) ? h : -h, (k & 4) ? h : -h});
    m.triangles = {{0, 2, 3}, {0, 3, 1},                                       // -z
                   {0, 1, 5}, {0, 5, 4},                                       // -y
                   {2, 6, 7}, {2, 7, 3},                                       // +y
                   {0, 4, 6}, {0, 6, 2},                                       // -x
                   {1, 3, 7}, {1, 7, 5}};                                      // +x
    if (!open) m.triangles.insert(m.triangles.end(), {{4, 5, 7}, {4, 7, 6}});  // +z
    return m;
}

/// p in the instance's frame, R^T (p - t), in long double (the stored pose: the scene's own).
template <class T>
V3 local_of(const Transform<T>& pose, const Vec<T, 3>& p) {
    V3 d, q;
    for (std::size_t i = 0; i < 3; ++i) d[i] = LD(p[i]) - LD(pose.translation[i]);
    for (std::size_t j = 0; j < 3; ++j)
        q[j] = LD(pose.rotation[0][j]) * d[0] + LD(pose.rotation[1][j]) * d[1] +
               LD(pose.rotation[2][j]) * d[2];
    return q;
}

/// The signed distance from q to the box [-h, h]^3: analytic.
inline LD box_distance(const V3& q, LD h) {
    LD outside = 0, inside = -INFINITY;
    for (std::size_t a = 0; a < 3; ++a) {
        const LD e = std::fabs(q[a]) - h;
        outside += e > 0 ? e * e : 0;
        inside = std::max(inside, e);
    }
    return outside > 0 ? std::sqrt(outside) : std::min(inside, LD(0));
}

/// The reference over a union: |d| the least |d_i|, inside where some d_i < 0. `sure`: the sign
/// is decided beyond `tol` (some d_i < -tol, or every d_i > tol).
struct UnionReference {
    LD distance = INFINITY;  // unsigned
    bool inside = false, sure = true;
};
inline UnionReference union_of(const std::vector<LD>& d, LD tol) {
    UnionReference r;
    bool deep = false, near = false;
    for (const LD x : d) {
        r.distance = std::min(r.distance, std::fabs(x));
        r.inside = r.inside || x < 0;
        deep = deep || x < -tol;
        near = near || std::fabs(x) <= tol;
    }
    r.sure = deep || !near;
    return r;
}

template <class T>
Transform<T> posed(const Mat3<T>& r, T x, T y, T z) {
    Transform<T> p;
    p.rotation = r;
    p.translation = {x, y, z};
    return p;
}

/// Cubes of half-extent `h * scale` at random poses around `offset`, overlapping, with two that
/// share a face; the points are random around them, and near their faces.
template <class T>
void check_cubes(double scale, double offset, std::uint64_t seed) {
    SCOPED_TRACE(::testing::Message() << "scale " << scale << " offset " << offset);
    SplitMix64 rng(seed);
    Scene<T> scene;
    const T h = T(scale);
    const GeometryId cube = scene.add_mesh(cube_mesh<T>(h));
    std::vector<InstanceId> ids;
    const T o = T(offset);
    // Two axis-aligned cubes sharing the face x = o + h, and one with a margin.
    ids.push_back(scene.add_instance(cube, posed(Mat3<T>::identity(), o, o, o)));
    ids.push_back(scene.add_instance(cube, posed(Mat3<T>::identity(), T(LD(o) + 2 * LD(h)), o, o)));
    ids.push_back(scene.add_instance(cube, posed(Mat3<T>::identity(), o, T(LD(o) - 3 * LD(h)), o),
                                     {.margin = T(0.5) * h}));
    for (int i = 0; i < 7; ++i) {
        const auto at = [&] { return T(offset + scale * rng.uniform(-3, 3)); };
        ids.push_back(
            scene.add_instance(cube, posed(scene_test::random_rotation<T>(rng), at(), at(), at())));
    }
    const LD eps = LD(std::numeric_limits<T>::epsilon());
    const LD reach = 6 * LD(scale);
    const LD tol = 64 * eps * reach;  // the rounding of p into each frame, and of the walk
    int inside = 0, outside = 0;
    const auto check = [&](const Vec<T, 3>& p) {
        std::vector<LD> d;
        for (const InstanceId id : ids) d.push_back(box_distance(local_of(scene.pose(id), p), h));
        const UnionReference ref = union_of(d, tol);
        const SceneSignedDistance<T> pn = signed_distance(scene, p);
        const SceneSignedDistance<T> wn = signed_distance(scene, p, SceneSign::winding_number);
        ASSERT_TRUE(pn);
        EXPECT_NEAR(LD(std::fabs(pn.distance)), ref.distance, tol)
            << p[0] << " " << p[1] << " " << p[2];
        EXPECT_EQ(std::fabs(wn.distance), std::fabs(pn.distance));
        EXPECT_EQ(LD(pn.closest.distance), LD(std::fabs(pn.distance)));
        // The closest point lies on the instance reported, at the distance reported, within
        // its own rounding to T in the world (half a unit of T at the offset per coordinate).
        const LD world_tol = 2 * tol + 2 * eps * std::fabs(LD(offset));
        const LD on = box_distance(local_of(scene.pose(pn.closest.instance), pn.closest.point), h);
        EXPECT_LE(std::fabs(on), world_tol);
        EXPECT_NEAR(scene_test::norm3(scene_test::wide(pn.closest.point) - scene_test::wide(p)),
                    ref.distance, world_tol);
        if (!ref.sure) return;
        (ref.inside ? inside : outside) += 1;
        EXPECT_EQ(std::signbit(pn.distance), ref.inside) << p[0] << " " << p[1] << " " << p[2];
        EXPECT_EQ(std::signbit(wn.distance), ref.inside) << p[0] << " " << p[1] << " " << p[2];
        EXPECT_EQ(contains(scene, p), ref.inside) << p[0] << " " << p[1] << " " << p[2];
    };
    for (int i = 0; i < 600; ++i) {
        const auto at = [&] { return T(offset + scale * rng.uniform(-4.5, 4.5)); };
        check(Vec<T, 3>(at(), at(), at()));
    }
    // Near the shared face, on both sides and in the gap-free seam; inside the first cube near
    // the second's faces; in the third cube's margin (outside).
    for (const LD f : {-1e-3L, -0.25L, 0.25L, 1e-3L, 0.999L, 1.001L})
        check(Vec<T, 3>(T(LD(o) + LD(h) * (1 + f)), T(LD(o) + LD(h) * 0.3L),
                        T(LD(o) - LD(h) * 0.2L)));
    check(Vec<T, 3>(o, T(LD(o) - 4.25L * LD(h)), o));
    // Near random faces of random cubes: just inside and just outside.
    for (int i = 0; i < 300; ++i) {
        const Transform<T>& pose = scene.pose(ids[rng.next() % ids.size()]);
        Vec<T, 3> local(T(scale * rng.uniform(-0.9, 0.9)), T(scale * rng.uniform(-0.9, 0.9)),
                        T(scale * rng.uniform(-0.9, 0.9)));
        const std::size_t axis = rng.next() % 3;
        local[axis] = T(scale * (rng.next() % 2 ? 1 : -1) * (1 + rng.uniform(-0.02, 0.02)));
        check(scene_test::world_vertex(pose, local));
    }
    EXPECT_GT(inside, 100);
    EXPECT_GT(outside, 100);
}

TEST(SceneSignedDistance, CubesAreAnalytic) {
    check_cubes<double>(1, 0, 1);
    check_cubes<float>(1, 0, 2);
    check_cubes<double>(1e-6, 0, 3);
    check_cubes<float>(1e-3, 0, 4);
    check_cubes<double>(1e4, 0, 5);
    check_cubes<float>(1e4, 0, 6);
    check_cubes<double>(1, 1e6, 7);  // far from the origin: the frames keep the detail
    check_cubes<float>(1, 1e5, 8);
    check_cubes<double>(1e-3, 1e6, 9);
}

/// The exact winding number of the instance's world triangles at p, in long double (Van
/// Oosterom and Strackee's solid angle per triangle).
template <class T>
LD winding_reference(const scene_test::WorldMesh<T>& world, InstanceId id, const V3& p) {
    LD sum = 0;
    for (const auto& t : world.triangles) {
        if (t.instance != id) continue;
        const V3 a = scene_test::wide(t.p[0]) - p, b = scene_test::wide(t.p[1]) - p,
                 c = scene_test::wide(t.p[2]) - p;
        const LD la = scene_test::norm3(a), lb = scene_test::norm3(b), lc = scene_test::norm3(c);
        const LD num = scene_test::dot3(a, scene_test::cross3(b, c));
        const LD den = la * lb * lc + scene_test::dot3(a, b) * lc + scene_test::dot3(b, c) * la +
                       scene_test::dot3(c, a) * lb;
        sum += 2 * std::atan2(num, den);
    }
    return sum / (4 * 3.141592653589793238462643383279503L);
}

// Icospheres (convex): distance by brute force over the world mesh, inside by the planes of the
// instance's own triangles, both in long double.
template <class T>
void check_spheres(std::uint64_t seed) {
    SplitMix64 rng(seed);
    Scene<T> scene;
    const GeometryId g = scene.add_mesh(scene_test::sphere_mesh<T>(2, 1.0));
    for (int i = 0; i < 12; ++i)
        scene.add_instance(g, posed(scene_test::random_rotation<T>(rng), T(rng.uniform(-3, 3)),
                                    T(rng.uniform(-3, 3)), T(rng.uniform(-3, 3))));
    const scene_test::WorldMesh<T> world(scene);
    const LD tol = 64 * LD(std::numeric_limits<T>::epsilon()) * 8;
    int inside = 0;
    for (int i = 0; i < 400; ++i) {
        const Vec<T, 3> p(T(rng.uniform(-4.5, 4.5)), T(rng.uniform(-4.5, 4.5)),
                          T(rng.uniform(-4.5, 4.5)));
        const V3 q = scene_test::wide(p);
        LD best = INFINITY;
        for (const auto& t : world.triangles)
            best = std::min(best, scene_test::point_triangle_distance(q, t));
        std::vector<LD> d;  // per instance: the largest plane side (negative: inside)
        scene.for_each_instance([&](InstanceId id) {
            LD side = -INFINITY;
            for (const auto& t : world.triangles) {
                if (t.instance != id) continue;
                const V3 a = scene_test::wide(t.p[0]);
                const V3 n =
                    scene_test::cross3(scene_test::wide(t.p[1]) - a, scene_test::wide(t.p[2]) - a);
                side = std::max(side, scene_test::dot3(n, q - a) / scene_test::norm3(n));
            }
            d.push_back(side);
        });
        const UnionReference ref = union_of(d, tol);
        const SceneSignedDistance<T> pn = signed_distance(scene, p);
        EXPECT_NEAR(LD(std::fabs(pn.distance)), best, tol);
        if (!ref.sure) continue;
        inside += ref.inside;
        EXPECT_EQ(std::signbit(pn.distance), ref.inside);
        EXPECT_EQ(signed_distance(scene, p, SceneSign::winding_number).distance < 0, ref.inside);
        EXPECT_EQ(contains(scene, p), ref.inside);
    }
    EXPECT_GT(inside, 20);
}

TEST(SceneSignedDistance, SpheresAgainstTheWorldMesh) {
    check_spheres<float>(11);
    check_spheres<double>(12);
}

// An open box: the winding number rule finds its inside (about 5/6 at the centre), checked
// against the exact winding number in long double; points where it is within 0.05 of 1/2 are
// left out (the fast winding number's own error).
TEST(SceneSignedDistance, OpenMeshesByTheWindingNumber) {
    SplitMix64 rng(21);
    Scene<double> scene;
    const GeometryId g = scene.add_mesh(cube_mesh<double>(1, true));
    EXPECT_FALSE(scene.geometry(g).is_closed());
    const GeometryId closed = scene.add_mesh(cube_mesh<double>(1));
    EXPECT_TRUE(scene.geometry(closed).is_closed());
    std::vector<InstanceId> ids;
    for (int i = 0; i < 5; ++i)
        ids.push_back(scene.add_instance(
            g, posed(scene_test::random_rotation<double>(rng), rng.uniform(-2, 2),
                     rng.uniform(-2, 2), rng.uniform(-2, 2))));
    const scene_test::WorldMesh<double> world(scene);
    int inside = 0, outside = 0;
    for (int i = 0; i < 400; ++i) {
        const Vec3d p(rng.uniform(-3.5, 3.5), rng.uniform(-3.5, 3.5), rng.uniform(-3.5, 3.5));
        bool in = false, unsure = false;
        for (const InstanceId id : ids) {
            const LD w = winding_reference(world, id, scene_test::wide(p));
            in = in || w > 0.55L;
            unsure = unsure || std::fabs(w - 0.5L) <= 0.05L;
        }
        if (unsure && !in) continue;
        (in ? inside : outside) += 1;
        EXPECT_EQ(contains(scene, p), in) << p[0] << " " << p[1] << " " << p[2];
        const SceneSignedDistance<double> s = signed_distance(scene, p, SceneSign::winding_number);
        EXPECT_EQ(s.distance < 0, in);
        EXPECT_EQ(std::fabs(s.distance), closest_point(scene, p).distance);
    }
    EXPECT_GT(inside, 30);
    EXPECT_GT(outside, 100);
}

TEST(SceneSignedDistance, EmptyScenesAndBadPoints) {
    Scene<float> scene;
    EXPECT_FALSE(signed_distance(scene, Vec3f(0, 0, 0)));
    EXPECT_EQ(signed_distance(scene, Vec3f(0, 0, 0)).distance, INFINITY);
    EXPECT_FALSE(contains(scene, Vec3f(0, 0, 0)));
    // A geometry without triangles, and one whose only triangle has a NaN corner.
    BasicTriangleMesh<float> none;
    none.vertices = {{0, 0, 0}};
    scene.add_instance(scene.add_mesh(none), Transform<float>{});
    BasicTriangleMesh<float> nan_only = cube_mesh<float>(1);
    nan_only.vertices.push_back({NAN, 0, 0});
    nan_only.triangles = {{8, 1, 2}};
    scene.add_instance(scene.add_mesh(nan_only), Transform<float>{});
    for (const SceneSign s : {SceneSign::pseudonormal, SceneSign::winding_number}) {
        EXPECT_FALSE(signed_distance(scene, Vec3f(0, 0, 0), s));
        EXPECT_EQ(signed_distance(scene, Vec3f(0, 0, 0), s).distance, INFINITY);
    }
    EXPECT_FALSE(contains(scene, Vec3f(0, 0, 0)));
    // A cube with an extra triangle that has a NaN corner: the cube answers as without it, and
    // the faces keep their indices.
    BasicTriangleMesh<float> cube = cube_mesh<float>(1);
    cube.vertices.push_back({NAN, 0, 0});
    cube.triangles.insert(cube.triangles.begin(), {8, 0, 1});
    const InstanceId c = scene.add_instance(scene.add_mesh(cube), Transform<float>{});
    EXPECT_TRUE(scene.geometry(scene.geometry_of(c)).is_closed());
    for (const SceneSign s : {SceneSign::pseudonormal, SceneSign::winding_number}) {
        const SceneSignedDistance<float> in = signed_distance(scene, Vec3f(0.25f, 0, 0.5f), s);
        EXPECT_FLOAT_EQ(in.distance, -0.5f);
        EXPECT_EQ(in.closest.instance, c);
        EXPECT_TRUE(in.closest.face == 11 || in.closest.face == 12);  // +z, moved up by one
        EXPECT_FLOAT_EQ(signed_distance(scene, Vec3f(3, 0, 0), s).distance, 2.0f);
        for (const float bad : {NAN, INFINITY, -INFINITY}) {
            EXPECT_FALSE(signed_distance(scene, Vec3f(bad, 0, 0), s));
            EXPECT_EQ(signed_distance(scene, Vec3f(0, bad, 0), s).distance, INFINITY);
        }
    }
    EXPECT_TRUE(contains(scene, Vec3f(0.25f, 0, 0.5f)));
    EXPECT_FALSE(contains(scene, Vec3f(NAN, 0, 0)));
    // Far beyond float's range in an instance's frame: skipped, not a crash.
    const InstanceId far = scene.add_instance(scene.add_mesh(cube_mesh<float>(1)),
                                              posed(Mat3<float>::identity(), -3e38f, 0.0f, 0.0f));
    EXPECT_EQ(signed_distance(scene, Vec3f(3e38f, 0, 0)).closest.instance, c);
    EXPECT_FALSE(contains(scene, Vec3f(3e38f, 0, 0)));
    EXPECT_TRUE(contains(scene, Vec3f(-3e38f, 0, 0)));
    scene.remove(far);
}

// The batches give the single calls' answers for any thread count, also while the per-geometry
// structures are first built by many threads at once.
TEST(SceneSignedDistance, BatchesOnManyThreadsAgree) {
    for (const SceneSign sign : {SceneSign::pseudonormal, SceneSign::winding_number}) {
        SplitMix64 rng(31);
        Scene<float> scene;
        const GeometryId g = scene.add_mesh(scene_test::sphere_mesh<float>(3, 1.0));
        const GeometryId b = scene.add_mesh(cube_mesh<float>(0.7f, true));
        for (int i = 0; i < 30; ++i)
            scene.add_instance(
                i % 2 ? g : b,
                posed(scene_test::random_rotation<float>(rng), float(rng.uniform(-5, 5)),
                      float(rng.uniform(-5, 5)), float(rng.uniform(-5, 5))));
        std::vector<Vec3f> points(3000);
        for (auto& p : points)
            p = Vec3f(float(rng.uniform(-6, 6)), float(rng.uniform(-6, 6)),
                      float(rng.uniform(-6, 6)));
        std::vector<SceneSignedDistance<float>> many(points.size());
        signed_distances<float>(scene, points, many, sign, Executor(4));
        std::vector<SceneSignedDistance<float>> one(points.size());
        signed_distances<float>(scene, points, one, sign, Executor(1));
        const std::unique_ptr<bool[]> in_many(new bool[points.size()]);
        contains<float>(scene, points, std::span<bool>(in_many.get(), points.size()), Executor(3));
        for (std::size_t i = 0; i < points.size(); ++i) {
            const SceneSignedDistance<float> s = signed_distance(scene, points[i], sign);
            EXPECT_EQ(many[i].distance, s.distance);
            EXPECT_EQ(one[i].distance, s.distance);
            EXPECT_EQ(many[i].closest.instance, s.closest.instance);
            EXPECT_EQ(many[i].closest.face, s.closest.face);
            EXPECT_EQ(in_many[i], contains(scene, points[i]));
        }
        std::vector<SceneSignedDistance<float>> small(2);
        EXPECT_THROW(signed_distances<float>(scene, points, small, sign), Error);
    }
}

}  // namespace
}  // namespace bvhkit
