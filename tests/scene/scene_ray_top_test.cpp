// SceneRayTop and the batch ray calls over a Scene (scene/ray_batches.hpp): the flat top level
// answers as the per-ray walk over the dynamic tree does, and both as brute force in long double
// over the concatenated world mesh (scene_support.hpp), on random scenes near and far from the
// origin, at tiny and huge scales, with overlapping and touching instances, removed instances,
// meshes without extent, and empty scenes.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/scene/ray_batches.hpp"
#include "scene_support.hpp"

namespace bvhkit {
namespace ray_top_test {

using scene_test::LD;

template <class T>
BasicTriangleMesh<T> mesh_scaled(const TriangleMesh& m, double scale) {
    BasicTriangleMesh<T> out;
    for (const auto& v : m.vertices)
        out.vertices.push_back(Vec<T, 3>(T(v[0] * scale), T(v[1] * scale), T(v[2] * scale)));
    out.triangles = m.triangles;
    return out;
}

/// `count` instances of a sphere, a torus, a triangle soup (slivers and needles among them) and a
/// mesh with no triangles, in a cube of side 6 * scale around `offset` (so many overlap), two of
/// them touching face to face, and every fifth removed again.
template <class T>
std::unique_ptr<Scene<T>> random_scene(double scale, double offset, int count, std::uint64_t seed) {
    auto scene = std::make_unique<Scene<T>>();
    SplitMix64 rng(seed);
    std::vector<GeometryId> g{scene->add_mesh(mesh_scaled<T>(make_sphere(1), scale)),
                              scene->add_mesh(mesh_scaled<T>(make_torus(12, 6), scale)),
                              scene->add_mesh(mesh_scaled<T>(make_soup(40, seed), scale)),
                              scene->add_mesh(BasicTriangleMesh<T>{})};
    std::vector<InstanceId> ids;
    for (int i = 0; i < count; ++i) {
        Transform<T> p;
        p.rotation = scene_test::random_rotation<T>(rng);
        for (std::size_t a = 0; a < 3; ++a)
            p.translation[a] = T(offset + scale * rng.uniform(-3.0, 3.0));
        ids.push_back(scene->add_instance(g[rng.next() % g.size()], p));
    }
    // Two unit-scaled spheres touching at one point on the x axis.
    Transform<T> left, right;
    left.translation = {T(offset - scale), T(offset), T(offset)};
    right.translation = {T(offset + scale), T(offset), T(offset)};
    scene->add_instance(g[0], left);
    scene->add_instance(g[0], right);
    for (std::size_t i = 0; i < ids.size(); i += 5) scene->remove(ids[i]);
    return scene;
}

/// Rays from inside the scene's box (random directions) and from outside aimed into it.
template <class T>
std::vector<Ray<T, 3>> random_rays(const Scene<T>& scene, std::size_t count, std::uint64_t seed) {
    SplitMix64 rng(seed);
    const Aabb<T, 3> box = scene.bounds();
    std::vector<Ray<T, 3>> rays;
    for (std::size_t i = 0; i < count; ++i) {
        Vec<T, 3> o, target;
        for (std::size_t a = 0; a < 3; ++a) {
            const double lo = double(box.min[a]), hi = double(box.max[a]), w = hi - lo;
            o[a] = T(i % 2 ? rng.uniform(lo, hi) : rng.uniform(lo - w, hi + w));
            target[a] = T(rng.uniform(lo, hi));
        }
        Vec<T, 3> d = i % 2 ? Vec<T, 3>(rng.unit_vector()) : target - o;
        if (d == Vec<T, 3>{}) d = {T(1), T(0), T(0)};
        rays.emplace_back(o, d);
    }
    // A finite tmax, a tmin past the origin, and a ray along the touching spheres' axis.
    rays.emplace_back(rays[0].origin, rays[0].direction, T(0), T(0.5));
    rays.emplace_back(rays[1].origin, rays[1].direction, T(0.1), std::numeric_limits<T>::max());
    const Vec<T, 3> c = (box.min + box.max) * T(0.5);
    rays.emplace_back(Vec<T, 3>{box.min[0] - T(1), c[1], c[2]}, Vec<T, 3>{T(1), T(0), T(0)});
    // Axis-aligned rays (zero components: infinite reciprocals, and NaN slab distances where the
    // origin lies on a box's plane) and a subnormal component (a NaN reciprocal: the axis is
    // ignored, which must not let the ray into an empty lane of a wide node).
    const T tiny = std::numeric_limits<T>::denorm_min() * T(8);
    for (std::size_t i = 0; i < 40; ++i) {
        const Vec<T, 3> o = rays[i].origin;
        rays.emplace_back(o, Vec<T, 3>{T(0), T(0), i % 2 ? T(1) : T(-1)});
        rays.emplace_back(o, Vec<T, 3>{T(0), i % 2 ? T(1) : T(-1), T(0)});
        rays.emplace_back(o, Vec<T, 3>{tiny, T(1), T(0.5)});
        rays.emplace_back(Vec<T, 3>{c[0], o[1], o[2]}, Vec<T, 3>{T(1), T(0), tiny});
    }
    return rays;
}

/// The flat top level (a batch large enough for closest_hits to make one, and SceneRayTop
/// directly) against the per-ray calls: the same hit or miss, and the same t; the same instance
/// and face unless two instances are hit at the very same t.
template <class T>
void expect_same_answers(const Scene<T>& scene, const std::vector<Ray<T, 3>>& rays) {
    ASSERT_GE(rays.size(), ray_top_min_rays(scene)) << "the batch would not take the flat top";
    std::vector<SceneHit<T>> batch(rays.size());
    closest_hits<T>(scene, rays, batch);
    std::vector<std::uint8_t> any(rays.size());
    any_hits<T>(scene, rays, any);
    const SceneRayTop<T> top(scene);
    std::size_t hits = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const SceneHit<T> one = closest_hit(scene, rays[i]);
        for (const SceneHit<T>& h : {batch[i], top.closest_hit(rays[i])}) {
            ASSERT_EQ(bool(h), bool(one)) << "ray " << i;
            if (!one) continue;
            EXPECT_EQ(h.t, one.t) << "ray " << i;
            if (h.instance != one.instance) continue;  // a tie at the same t
            EXPECT_EQ(h.face, one.face);
            EXPECT_EQ(h.geometry, one.geometry);
            EXPECT_EQ(h.u, one.u);
            EXPECT_EQ(h.v, one.v);
            EXPECT_TRUE(h.normal == one.normal);
        }
        EXPECT_EQ(bool(any[i]), any_hit(scene, rays[i])) << "ray " << i;
        EXPECT_EQ(top.any_hit(rays[i]), bool(any[i])) << "ray " << i;
        hits += bool(one);
    }
    EXPECT_GT(hits, rays.size() / 10) << "too few hits to test anything";
}

/// The flat top level against brute force in long double over the world mesh: a sure hit is
/// found, nothing is found where every triangle surely misses, and the reported triangle is
/// crossed at the reported t with no sure hit nearer.
template <class T>
void expect_reference_answers(const Scene<T>& scene, const std::vector<Ray<T, 3>>& rays) {
    const scene_test::WorldMesh<T> world(scene);
    const SceneRayTop<T> top(scene);
    constexpr LD eps = std::numeric_limits<T>::epsilon();
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Ray<T, 3>& ray = rays[i];
        LD largest = world.largest;
        for (std::size_t a = 0; a < 3; ++a)
            largest = std::max(largest, std::fabs(LD(ray.origin[a])));
        const LD wobble = 32 * eps * largest;  // as scene_test.cpp's checker, far end included
        LD best = INFINITY, best_tol = 0;
        bool sure = false, unsure = false;
        for (const auto& tri : world.triangles) {
            const scene_test::RayCrossing c = scene_test::cross(ray, tri, wobble);
            if (c.kind == scene_test::Crossing::Hit && c.t < best)
                best = c.t, best_tol = c.t_tolerance;
            sure = sure || c.kind == scene_test::Crossing::Hit;
            unsure = unsure || c.kind == scene_test::Crossing::Unsure;
        }
        const SceneHit<T> h = top.closest_hit(ray);
        if (sure) {
            ASSERT_TRUE(h) << "ray " << i << " missed a sure hit at " << double(best);
        }
        if (!sure && !unsure) {
            ASSERT_FALSE(h) << "ray " << i << " hit at " << double(h.t);
        }
        EXPECT_EQ(top.any_hit(ray), bool(h));
        if (!h) continue;
        const auto* tri = world.find(h.instance, h.face);
        ASSERT_NE(tri, nullptr);
        const scene_test::RayCrossing c = scene_test::cross(ray, *tri, wobble);
        ASSERT_NE(c.kind, scene_test::Crossing::Miss) << "ray " << i;
        EXPECT_LE(std::fabs(LD(h.t) - c.t), c.t_tolerance + 4 * eps * c.t);
        if (sure) {
            EXPECT_LE(LD(h.t), best + best_tol + 4 * eps * best);
        }
    }
}

template <class T>
void check_scenes() {
    for (const double scale : {1e-3, 1.0, 1e4})
        for (const double offset : {0.0, 1e5 * scale}) {
            SCOPED_TRACE(testing::Message() << "scale " << scale << " offset " << offset);
            const auto scene = random_scene<T>(scale, offset, 24, 7);
            const auto rays = random_rays(*scene, 400, 3);
            expect_same_answers(*scene, rays);
            expect_reference_answers(*scene,
                                     std::vector<Ray<T, 3>>(rays.begin(), rays.begin() + 60));
        }
}

TEST(SceneRayTop, FloatAgreesWithThePerRayWalkAndBruteForce) {
    check_scenes<float>();
}
TEST(SceneRayTop, DoubleAgreesWithThePerRayWalkAndBruteForce) {
    check_scenes<double>();
}

TEST(SceneRayTop, AfterPoseChangesANewOneSeesThem) {
    auto scene = random_scene<float>(1.0, 0.0, 16, 11);
    std::vector<InstanceId> live;
    scene->for_each_instance([&](InstanceId id) { live.push_back(id); });
    SplitMix64 rng(5);
    for (const InstanceId id : live) {
        Transform<float> p = scene->pose(id);
        p.translation += Vec3f(float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)), 0.5f);
        scene->set_pose(id, p);
    }
    expect_same_answers(*scene, random_rays(*scene, 300, 9));
}

TEST(SceneRayTop, EmptyScenesAndErrors) {
    Scene<float> empty;
    const SceneRayTop<float> top(empty);
    const Ray3f ray(Vec3f(0, 0, 0), Vec3f(1, 0, 0));
    EXPECT_FALSE(top.closest_hit(ray));
    EXPECT_FALSE(top.any_hit(ray));
    std::vector<Ray3f> rays(200, ray);
    std::vector<SceneHit<float>> hits(200);
    closest_hits<float>(empty, rays, hits);
    for (const auto& h : hits) EXPECT_FALSE(h);
    // Only meshes without triangles: nothing to hit, through either path.
    const GeometryId none = empty.add_mesh(TriangleMesh{});
    empty.add_instance(none, Transform<float>{});
    EXPECT_FALSE(SceneRayTop<float>(empty).closest_hit(ray));
    // Mismatched spans and a negative tmin are Errors, on both paths; an untraceable ray misses.
    auto scene = random_scene<float>(1.0, 0.0, 8, 2);
    std::vector<SceneHit<float>> short_hits(3);
    EXPECT_THROW(closest_hits<float>(*scene, rays, short_hits), Error);
    std::vector<std::uint8_t> flags(3);
    EXPECT_THROW(any_hits<float>(*scene, rays, flags), Error);
    const Ray3f negative(Vec3f(0, 0, 0), Vec3f(1, 0, 0), -1.0f, 1.0f);
    EXPECT_THROW((void)SceneRayTop<float>(*scene).closest_hit(negative), Error);
    EXPECT_THROW((void)SceneRayTop<float>(*scene).any_hit(negative), Error);
    std::vector<Ray3f> many(1000, negative);
    std::vector<SceneHit<float>> many_hits(1000);
    EXPECT_THROW(closest_hits<float>(*scene, many, many_hits), Error);
    const Ray3f nan_ray(Vec3f(NAN, 0, 0), Vec3f(1, 0, 0));
    EXPECT_FALSE(SceneRayTop<float>(*scene).closest_hit(nan_ray));
    EXPECT_FALSE(SceneRayTop<float>(*scene).any_hit(nan_ray));
}

}  // namespace ray_top_test
}  // namespace bvhkit
