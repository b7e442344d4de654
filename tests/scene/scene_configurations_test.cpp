// Collision at configurations (colliding_pairs_at, any_collision_at, any_collisions_at): the
// scene is not changed, and the answer is judged against (a) a brute force triangle loop over the
// world-space triangles of a second scene moved to the configuration (margins zero, no library
// triangle test), and (b) the same second scene's colliding_pairs after set_poses, restricted to
// pairs with a moved instance (margins, groups and masks, the ignore list). Far from the origin,
// several geometries, the batch on every thread, and the errors.
#include <gtest/gtest.h>

#include <array>
#include <set>
#include <vector>

#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/primitives/triangle_triangle.hpp"
#include "bvhkit/scene/collision.hpp"
#include "bvhkit/scene/configurations.hpp"
#include "scene_support.hpp"

namespace bvhkit::configurations_test {
namespace {

using scene_test::sphere_mesh;

/// Two copies of one random scene: `fixed` stays, `moved` follows the configurations.
struct Twin {
    Scene<double> fixed, moved;
    std::vector<InstanceId> ids;  // the same in both (same calls in the same order)

    Twin(double offset, bool margins, std::uint64_t seed) {
        SplitMix64 rng(seed);
        BasicTriangleMesh<double> tetra;
        tetra.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
        tetra.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
        for (Scene<double>* s : {&fixed, &moved}) {
            s->add_mesh(sphere_mesh<double>(0, 0.7));
            s->add_mesh(tetra);
            s->add_mesh(make_soup(15, 3));
        }
        for (int i = 0; i < 30; ++i) {
            Transform<double> pose;
            pose.rotation = scene_test::random_rotation<double>(rng);
            for (std::size_t a = 0; a < 3; ++a)
                pose.translation[a] = offset + rng.uniform(-2.5, 2.5);
            InstanceOptions<double> o;
            if (margins) {
                o.margin = std::array<double, 3>{0, 0, 0.1}[rng.next() % 3];
                o.group = 1u << (rng.next() % 2);
                o.mask = rng.next() % 4 == 0 ? ~o.group : 0xFFFFFFFFu;
            }
            const GeometryId g(std::uint32_t(rng.next() % 3));
            const InstanceId a = fixed.add_instance(g, pose, o);
            EXPECT_EQ(moved.add_instance(g, pose, o), a);
            ids.push_back(a);
        }
    }
};

std::vector<Transform<double>> random_poses(SplitMix64& rng, std::size_t n, double offset) {
    std::vector<Transform<double>> poses(n);
    for (auto& p : poses) {
        p.rotation = scene_test::random_rotation<double>(rng);
        for (std::size_t a = 0; a < 3; ++a) p.translation[a] = offset + rng.uniform(-2.5, 2.5);
    }
    return poses;
}

/// The pairs of `pairs` with an instance of `which`.
std::vector<InstancePair> touching(const std::vector<InstancePair>& pairs,
                                   const std::vector<InstanceId>& which) {
    std::vector<InstancePair> out;
    for (const InstancePair& p : pairs)
        if (std::find(which.begin(), which.end(), p.a) != which.end() ||
            std::find(which.begin(), which.end(), p.b) != which.end())
            out.push_back(p);
    return out;
}

TEST(SceneConfigurations, PairsAgreeWithATriangleLoop) {
    for (const double offset : {0.0, 1e5}) {
        Twin twin(offset, false, 3);
        SplitMix64 rng(4);
        const std::vector<InstanceId> which = {twin.ids[2], twin.ids[7], twin.ids[11],
                                               twin.ids[20]};
        int colliding = 0;
        for (int k = 0; k < 20; ++k) {
            const auto poses = random_poses(rng, which.size(), offset);
            twin.moved.set_poses(which, poses);
            const scene_test::WorldMesh<double> world(twin.moved);
            std::set<std::pair<std::int32_t, std::int32_t>> expected;
            for (const auto& x : world.triangles)
                for (const auto& y : world.triangles)
                    if (x.instance.index() < y.instance.index() &&
                        (std::find(which.begin(), which.end(), x.instance) != which.end() ||
                         std::find(which.begin(), which.end(), y.instance) != which.end()) &&
                        triangles_intersect(Triangle<double>{x.p[0], x.p[1], x.p[2]},
                                            Triangle<double>{y.p[0], y.p[1], y.p[2]}))
                        expected.insert({x.instance.index(), y.instance.index()});
            std::vector<InstancePair> pairs;
            colliding_pairs_at(twin.fixed, which, poses, pairs);
            std::set<std::pair<std::int32_t, std::int32_t>> found;
            for (const auto& p : pairs) found.insert({p.a.index(), p.b.index()});
            EXPECT_EQ(found, expected) << "configuration " << k;
            EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
            EXPECT_EQ(any_collision_at(twin.fixed, which, poses), !expected.empty());
            colliding += !expected.empty();
        }
        EXPECT_GT(colliding, 3);
        EXPECT_LT(colliding, 20);
        // The scene read, not changed: each instance's pose and box are as added.
        twin.fixed.validate();
    }
}

TEST(SceneConfigurations, FiltersMarginsAndTheBatch) {
    for (const double offset : {0.0, -3e4}) {
        Twin twin(offset, true, 5);
        SplitMix64 rng(6);
        const std::vector<InstanceId> which = {twin.ids[0], twin.ids[1], twin.ids[5]};
        const std::vector<InstancePair> ignore = {{twin.ids[3], twin.ids[0]},
                                                  {twin.ids[1], twin.ids[5]}};
        const std::size_t K = 60;
        std::vector<Transform<double>> all;
        std::vector<std::uint8_t> expected(K);
        for (std::size_t k = 0; k < K; ++k) {
            const auto poses = random_poses(rng, which.size(), offset);
            all.insert(all.end(), poses.begin(), poses.end());
            twin.moved.set_poses(which, poses);
            std::vector<InstancePair> reference, pairs;
            colliding_pairs(twin.moved, reference, ignore);
            reference = touching(reference, which);
            colliding_pairs_at(twin.fixed, which, poses, pairs, ignore);
            EXPECT_EQ(pairs, reference) << "configuration " << k;
            expected[k] = std::uint8_t(!reference.empty());
            EXPECT_EQ(any_collision_at(twin.fixed, which, poses, ignore), !reference.empty());
        }
        EXPECT_GT(std::count(expected.begin(), expected.end(), 1), 5);
        EXPECT_GT(std::count(expected.begin(), expected.end(), 0), 5);
        for (const unsigned threads : {0u, 1u, 3u}) {
            std::vector<std::uint8_t> batch(K, 9);
            any_collisions_at(twin.fixed, which, all, batch, ignore, threads);
            EXPECT_EQ(batch, expected) << threads << " threads";
        }
        twin.fixed.validate();
    }
}

// At contact the exact test decides for the relative pose as rounded, which depends on the order
// of the pair: the configuration calls run it in slot order, as colliding_pairs does, so the two
// agree ulp by ulp through contact (a moved instance in the higher slot, bisected onto contact).
template <class T>
void sweep_through_contact(T margin, std::uint64_t seed) {
    SplitMix64 rng(seed);
    int steps = 0, touching = 0;
    for (int trial = 0; trial < 25; ++trial) {
        Scene<T> fixed, moved;
        Transform<T> pa, pb;
        pa.rotation = scene_test::random_rotation<T>(rng);
        pb.rotation = scene_test::random_rotation<T>(rng);
        const Vec3d dir = rng.unit_vector();
        InstanceId a, b;
        for (Scene<T>* s : {&fixed, &moved}) {
            s->add_mesh(sphere_mesh<T>(0, 1.0));
            a = s->add_instance(GeometryId(0), pa, {.margin = margin});
            b = s->add_instance(GeometryId(0), pb, {.margin = margin});
        }
        ASSERT_LT(a.index(), b.index());
        const auto placed = [&](double along) {
            Transform<T> p = pb;
            for (std::size_t i = 0; i < 3; ++i) p.translation[i] = T(dir[i] * along);
            return p;
        };
        const auto reference = [&](const Transform<T>& p) {
            moved.set_pose(b, p);
            return any_collision(moved);
        };
        double lo = 0, hi = 6;  // colliding at lo, apart at hi
        for (int it = 0; it < 80; ++it) {
            const double mid = (lo + hi) / 2;
            (reference(placed(mid)) ? lo : hi) = mid;
        }
        for (int k = -10; k <= 10; ++k) {
            Transform<T> p = placed(lo);
            for (std::size_t i = 0; i < 3; ++i)
                for (int j = 0; j < std::abs(k); ++j)
                    p.translation[i] =
                        std::nextafter(p.translation[i], T((k > 0 ? 1 : -1) * dir[i] * 1e30));
            const bool expected = reference(p);
            const InstanceId ids[1] = {b};
            const Transform<T> poses[1] = {p};
            EXPECT_EQ(any_collision_at(fixed, std::span(ids), std::span(poses)), expected)
                << "trial " << trial << " step " << k;
            ++steps;
            touching += expected;
        }
    }
    EXPECT_GT(touching, steps / 4);
    EXPECT_LT(touching, 3 * steps / 4);
}

TEST(SceneConfigurations, ThroughContactAsCollidingPairsDecides) {
    sweep_through_contact<float>(0.0f, 1);
    sweep_through_contact<float>(0.05f, 2);
    sweep_through_contact<double>(0.0, 3);
    sweep_through_contact<double>(0.05, 4);
}

TEST(SceneConfigurations, Errors) {
    Twin twin(0, false, 7);
    const std::vector<InstanceId> which = {twin.ids[0], twin.ids[1]};
    std::vector<Transform<double>> poses(2);
    std::vector<InstancePair> out;
    EXPECT_THROW(colliding_pairs_at(twin.fixed, which, std::span(poses).first(1), out), Error);
    const std::vector<InstanceId> twice = {twin.ids[0], twin.ids[0]};
    EXPECT_THROW(any_collision_at(twin.fixed, twice, poses), Error);
    Transform<double> sheared;
    sheared.rotation[0][1] = 0.5;
    std::vector<Transform<double>> bad = {Transform<double>{}, sheared};
    EXPECT_THROW(any_collision_at(twin.fixed, which, bad), Error);
    twin.moved.remove(twin.ids[1]);
    EXPECT_THROW(any_collision_at(twin.moved, which, poses), Error);
    // A bad pose in configuration 2 of 4: an Error naming it, `collides` unwritten.
    std::vector<Transform<double>> all(8);
    for (std::size_t k = 0; k < 4; ++k) all[2 * k].translation = {3.0 * double(k), 0, 0};
    all[5] = sheared;
    std::vector<std::uint8_t> collides(4, 9);
    try {
        any_collisions_at(twin.fixed, which, all, collides);
        ADD_FAILURE() << "no Error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("configuration 2"), std::string::npos) << e.what();
    }
    EXPECT_EQ(collides, std::vector<std::uint8_t>(4, 9));
    EXPECT_THROW(any_collisions_at(twin.fixed, which, std::span(all).first(7), collides), Error);
    // No instance moved: nothing to test, nothing collides.
    EXPECT_FALSE(any_collision_at(twin.fixed, std::span<const InstanceId>{},
                                  std::span<const Transform<double>>{}));
}

}  // namespace
}  // namespace bvhkit::configurations_test
