// Scene distance (closest pair, pairs within a threshold, the instance nearest a posed mesh) and
// collision between two scenes. References: a brute force over every pair with the one-pair
// distance() / collides() (so the top-level pruning is judged by a loop that has none), and
// analytic answers that share none of the library's arithmetic: axis-aligned cubes at known gaps
// (far from the origin, at tiny and huge scales), and spheres between their inner and outer
// balls.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/scene/collision.hpp"
#include "bvhkit/scene/distance.hpp"
#include "scene_support.hpp"

namespace bvhkit::distance_test {
namespace {

using scene_test::LD;
using scene_test::sphere_mesh;

template <class T>
BasicTriangleMesh<T> cube_mesh(T h) {
    BasicTriangleMesh<T> m;
    for (int i = 0; i < 8; ++i)
        m.vertices.push_back(Vec<T, 3>(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h));
    m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    return m;
}

template <class T>
Transform<T> at(T x, T y, T z) {
    Transform<T> p;
    p.translation = Vec<T, 3>(x, y, z);
    return p;
}

/// The one-pair distance less the margins, as the reference: no tree, no pruning.
template <class T>
T pair_distance(const Scene<T>& s, const Transform<T>& pa, GeometryId ga, T ma,
                const Transform<T>& pb, GeometryId gb, T mb) {
    using W = AccurateScalar<T>;
    const T d = distance(s.geometry(ga).collision_model(), s.geometry(gb).collision_model(),
                         scene_detail::relative_pose<W>(pa, pb))
                    .distance;
    const T m = ma + mb;
    return m == T(0) ? d : scene_detail::narrow<T>(W(d) - W(m));
}

template <class T>
void expect_witnesses(const Scene<T>& s, const SceneDistance<T>& d, const Transform<T>& pose_a,
                      GeometryId ga, T margins) {
    // The witness points lie on the two meshes (up to the pose's rounding) and are as far apart
    // as the distance says (plus the margins).
    const LD sep = scene_test::norm3(scene_test::wide(d.point_a) - scene_test::wide(d.point_b));
    const LD scale = std::max({LD(1e-30), std::fabs(LD(d.distance)) + LD(margins),
                               scene_test::norm3(scene_test::wide(d.point_a))});
    EXPECT_NEAR(double(sep), double(LD(d.distance) + LD(margins)),
                double(LD(std::numeric_limits<T>::epsilon()) * 64 * scale));
    (void)s, (void)pose_a, (void)ga;
}

/// Cubes of half size h in a row along x, gaps known exactly, the row at `offset`.
template <class T>
void check_cubes(T h, T offset) {
    Scene<T> s;
    const GeometryId g = s.add_mesh(cube_mesh<T>(h));
    // Centres at x = 0, 2h + 3h, ... with gaps 3h, 0.5h, 2h (the middle pair is the closest).
    const T gaps[3] = {3 * h, h / 2, 2 * h};
    std::vector<InstanceId> ids;
    T x = offset;
    ids.push_back(s.add_instance(g, at<T>(x, offset, offset)));
    for (const T gap : gaps) {
        x = x + 2 * h + gap;
        ids.push_back(s.add_instance(g, at<T>(x, offset, offset)));
    }
    // The positions as stored (rounding far out may shift them): the gaps as the scene sees them.
    LD stored[4];
    for (int i = 0; i < 4; ++i) stored[i] = LD(s.pose(ids[i]).translation[0]);
    LD best = INFINITY;
    int at_best = -1;
    for (int i = 0; i < 3; ++i)
        if (stored[i + 1] - stored[i] - 2 * LD(h) < best)
            best = stored[i + 1] - stored[i] - 2 * LD(h), at_best = i;
    const SceneDistance<T> d = closest_pair(s);
    ASSERT_TRUE(d);
    EXPECT_EQ(d.a, ids[at_best]);
    EXPECT_EQ(d.b, ids[at_best + 1]);
    const LD tol = LD(std::numeric_limits<T>::epsilon()) * 8 * LD(h);
    EXPECT_NEAR(double(d.distance), double(best), double(tol)) << "h " << h << " offset " << offset;
    // The witnesses: on a's +x face and b's -x face.
    EXPECT_NEAR(double(d.point_a[0]), double(stored[at_best] + LD(h)),
                double(tol + LD(std::numeric_limits<T>::epsilon()) * std::fabs(LD(offset))));
    EXPECT_NEAR(double(d.point_b[0]), double(stored[at_best + 1] - LD(h)),
                double(tol + LD(std::numeric_limits<T>::epsilon()) * std::fabs(LD(offset))));
    expect_witnesses(s, d, s.pose(d.a), g, T(0));

    // Margins: a margin of h on the second cube lowers both of its pairs by h; the closest pair
    // is then below zero (-h / 2) where the gap is h / 2.
    InstanceOptions<T> o;
    o.margin = h;
    s.set_options(ids[1], o);
    const SceneDistance<T> m = closest_pair(s);
    ASSERT_TRUE(m);
    EXPECT_EQ(m.a, ids[1]);
    EXPECT_EQ(m.b, ids[2]);
    EXPECT_NEAR(double(m.distance), double(stored[2] - stored[1] - 3 * LD(h)), double(tol));
    EXPECT_LT(m.distance, T(0));

    // Pairs within a threshold: (1, 2) at -h/2, (0, 1) at 3h less the margin = 2h, (2, 3) at 2h.
    std::vector<SceneDistance<T>> within;
    pairs_within(s, T(0), within);
    ASSERT_EQ(within.size(), 1u);
    EXPECT_EQ(within[0].a, ids[1]);
    pairs_within(s, T(2.5) * h, within);
    ASSERT_EQ(within.size(), 3u);
    EXPECT_EQ(within[0].a, ids[0]);
    EXPECT_EQ(within[1].a, ids[1]);
    EXPECT_EQ(within[2].a, ids[2]);
    pairs_within(s, T(1.5) * h, within);
    EXPECT_EQ(within.size(), 1u);

    // A posed cube above the row's last cube, h/4 over its top face.
    const Transform<T> above = at<T>(s.pose(ids[3]).translation[0], offset, offset + 2 * h + h / 4);
    const SceneDistance<T> c = closest_instance(s, g, above);
    ASSERT_TRUE(c);
    EXPECT_TRUE(c.a.is_null());
    EXPECT_EQ(c.b, ids[3]);
    EXPECT_NEAR(double(c.distance),
                double(LD(above.translation[2]) - LD(s.pose(ids[3]).translation[2]) - 2 * LD(h)),
                double(tol));
    // The filter: a mask that excludes group 1 finds nothing.
    InstanceOptions<T> none;
    none.mask = 0;
    EXPECT_FALSE(closest_instance(s, g, above, none));
}

TEST(SceneDistance, CubesAtKnownGaps) {
    check_cubes<double>(1.0, 0.0);
    check_cubes<double>(1.0, 1e6);
    check_cubes<double>(1e-6, -3e3);
    check_cubes<double>(1e-150, 0.0);
    check_cubes<double>(1e150, 1e151);
    check_cubes<float>(1.0f, 0.0f);
    check_cubes<float>(1.0f, 4096.0f);
    check_cubes<float>(1e-5f, 0.0f);
    check_cubes<float>(1e15f, -1e16f);
}

TEST(SceneDistance, EmptyAndLonelyScenes) {
    Scene<float> s;
    EXPECT_FALSE(closest_pair(s));
    std::vector<SceneDistance<float>> within;
    pairs_within(s, INFINITY, within);
    EXPECT_TRUE(within.empty());
    const GeometryId g = s.add_mesh(cube_mesh<float>(1.0f));
    EXPECT_FALSE(closest_instance(s, g, Transform<float>{}));
    const InstanceId a = s.add_instance(g, Transform<float>{});
    EXPECT_FALSE(closest_pair(s));
    const SceneDistance<float> c = closest_instance(s, g, at<float>(0, 0, 0));
    ASSERT_TRUE(c);
    EXPECT_EQ(c.b, a);
    EXPECT_EQ(c.distance, 0.0f);  // the same cube on itself
    // Filtered apart: two instances that never meet.
    InstanceOptions<float> o;
    o.group = 2;
    o.mask = ~2u;
    const InstanceId b = s.add_instance(g, at<float>(5, 0, 0), o);
    const InstanceId c2 = s.add_instance(g, at<float>(10, 0, 0), o);
    EXPECT_EQ(closest_pair(s).a, a);  // (a, b) at 3; (b, c2) never
    std::vector<InstancePair> ignore = {{b, a}};
    EXPECT_EQ(closest_pair(s, ignore).b, c2);  // (a, c2) at 8 remains
    EXPECT_NEAR(closest_pair(s, ignore).distance, 8.0f, 1e-5f);
    ignore.push_back({a, c2});
    EXPECT_FALSE(closest_pair(s, ignore));
    EXPECT_THROW(pairs_within(s, float(NAN), within), Error);
    EXPECT_THROW(closest_instance(s, GeometryId(7), Transform<float>{}), Error);
    InstanceOptions<float> bad;
    bad.margin = -1;
    EXPECT_THROW(closest_instance(s, g, Transform<float>{}, bad), Error);
}

/// Random spheres and cubes: closest_pair, pairs_within and closest_instance against every pair
/// measured by the one-pair distance, and the spheres' distances against their balls.
template <class T>
void check_random(double scale, double offset, std::uint64_t seed) {
    SplitMix64 rng(seed);
    Scene<T> s;
    const GeometryId gs = s.add_mesh(sphere_mesh<T>(1, scale));
    const GeometryId gc = s.add_mesh(cube_mesh<T>(T(0.7 * scale)));
    std::vector<InstanceId> ids;
    for (int i = 0; i < 36; ++i) {
        Transform<T> pose;
        pose.rotation = scene_test::random_rotation<T>(rng);
        for (std::size_t a = 0; a < 3; ++a)
            pose.translation[a] = T(offset + scale * rng.uniform(-8.0, 8.0));
        InstanceOptions<T> o;
        o.margin = T(scale * std::array<double, 3>{0, 0, 0.2}[rng.next() % 3]);
        o.group = 1u << (rng.next() % 3);
        o.mask = rng.next() % 4 == 0 ? ~o.group : 0xFFFFFFFFu;
        ids.push_back(s.add_instance(rng.next() % 2 ? gs : gc, pose, o));
    }
    std::vector<InstancePair> ignore;
    for (int k = 0; k < 20; ++k) {
        const InstanceId a = ids[rng.next() % ids.size()], b = ids[rng.next() % ids.size()];
        if (a != b) ignore.push_back({b, a});
    }
    const auto is_ignored = [&](InstanceId a, InstanceId b) {
        for (const auto& p : ignore)
            if ((p.a == a && p.b == b) || (p.a == b && p.b == a)) return true;
        return false;
    };
    for (int round = 0; round < 3; ++round) {
        struct Ref {
            InstanceId a, b;
            T d;
        };
        std::vector<Ref> all;
        for (std::size_t i = 0; i < ids.size(); ++i)
            for (std::size_t j = i + 1; j < ids.size(); ++j) {
                InstanceId a = ids[i], b = ids[j];
                if (a.index() > b.index()) std::swap(a, b);
                const auto& oa = s.options(a);
                const auto& ob = s.options(b);
                if (!may_collide(oa, ob) || is_ignored(a, b)) continue;
                all.push_back({a, b,
                               pair_distance(s, s.pose(a), s.geometry_of(a), oa.margin, s.pose(b),
                                             s.geometry_of(b), ob.margin)});
            }
        std::sort(all.begin(), all.end(), [](const Ref& x, const Ref& y) {
            return x.a.index() != y.a.index() ? x.a.index() < y.a.index()
                                              : x.b.index() < y.b.index();
        });
        ASSERT_GT(all.size(), 100u);
        Ref best{{}, {}, std::numeric_limits<T>::infinity()};
        for (const Ref& r : all)
            if (r.d < best.d) best = r;  // strict: the first in pair order keeps a tie
        const SceneDistance<T> d = closest_pair(s, ignore);
        ASSERT_TRUE(d);
        EXPECT_EQ(d.distance, best.d);
        EXPECT_EQ(d.a, best.a);
        EXPECT_EQ(d.b, best.b);
        expect_witnesses(s, d, s.pose(d.a), s.geometry_of(d.a),
                         T(s.options(d.a).margin + s.options(d.b).margin));

        // Spheres: the centres' distance bounds each pair between the balls.
        LD inner = INFINITY, outer = 0;
        {
            const BasicTriangleMesh<T>& m = s.geometry(gs).mesh();
            for (const auto& v : m.vertices)
                outer = std::max(outer, scene_test::norm3(scene_test::wide(v)));
            for (const auto& t : m.triangles) {
                const auto a = scene_test::wide(m.vertices[t[0]]),
                           b = scene_test::wide(m.vertices[t[1]]),
                           c = scene_test::wide(m.vertices[t[2]]);
                const auto n = scene_test::cross3(b - a, c - a);
                inner = std::min(inner, std::fabs(scene_test::dot3(n, a)) / scene_test::norm3(n));
            }
        }
        int spheres = 0;
        for (const Ref& r : all) {
            if (s.geometry_of(r.a) != gs || s.geometry_of(r.b) != gs) continue;
            const LD c = scene_test::norm3(scene_test::wide(s.pose(r.a).translation) -
                                           scene_test::wide(s.pose(r.b).translation));
            const LD m = LD(s.options(r.a).margin) + LD(s.options(r.b).margin);
            const LD tol = 1e-4L * scale;
            if (c <= 2 * inner) continue;  // crossing: 0 less the margins, checked by the ref
            EXPECT_GE(LD(r.d), c - 2 * outer - m - tol);
            EXPECT_LE(LD(r.d), c - 2 * inner - m + tol);
            ++spheres;
        }
        EXPECT_GT(spheres, 20);

        // Pairs within thresholds: the reference's own list.
        for (const T threshold : {best.d, T(0), T(scale), T(3 * scale)}) {
            std::vector<SceneDistance<T>> within;
            pairs_within(s, threshold, within, ignore);
            std::vector<Ref> expected;
            for (const Ref& r : all)
                if (r.d <= threshold) expected.push_back(r);
            ASSERT_EQ(within.size(), expected.size()) << "threshold " << threshold;
            for (std::size_t k = 0; k < within.size(); ++k) {
                EXPECT_EQ(within[k].a, expected[k].a);
                EXPECT_EQ(within[k].b, expected[k].b);
                EXPECT_EQ(within[k].distance, expected[k].d);
            }
        }

        // The posed mesh against the scene: the least over the instances it may meet.
        for (int k = 0; k < 10; ++k) {
            Transform<T> pose;
            pose.rotation = scene_test::random_rotation<T>(rng);
            for (std::size_t a = 0; a < 3; ++a)
                pose.translation[a] = T(offset + scale * rng.uniform(-10.0, 10.0));
            InstanceOptions<T> o;
            o.margin = T(scale * 0.1);
            o.group = 2;
            const GeometryId g = k % 2 ? gs : gc;
            const Transform<T> stored = scene_detail::rigid_pose(pose);
            Ref ref{{}, {}, std::numeric_limits<T>::infinity()};
            s.for_each_instance([&](InstanceId b) {
                if (!may_collide(o, s.options(b))) return;
                const T dd = pair_distance(s, stored, g, o.margin, s.pose(b), s.geometry_of(b),
                                           s.options(b).margin);
                if (dd < ref.d) ref = {{}, b, dd};
            });
            const SceneDistance<T> c = closest_instance(s, g, pose, o);
            EXPECT_EQ(c.distance, ref.d);
            EXPECT_EQ(c.b, ref.b);
        }

        // Half move, one goes: the answers follow.
        std::vector<InstanceId> moved;
        std::vector<Transform<T>> poses;
        for (std::size_t i = round % 2; i < ids.size(); i += 2) {
            Transform<T> pose = s.pose(ids[i]);
            for (std::size_t a = 0; a < 3; ++a)
                pose.translation[a] = T(offset + scale * rng.uniform(-8.0, 8.0));
            moved.push_back(ids[i]);
            poses.push_back(pose);
        }
        s.set_poses(moved, poses);
        const InstanceId gone = ids[ids.size() / 2];
        s.remove(gone);
        ids.erase(ids.begin() + std::ptrdiff_t(ids.size() / 2));
        std::erase_if(ignore, [&](const InstancePair& p) { return p.a == gone || p.b == gone; });
    }
}

TEST(SceneDistance, RandomScenesAgainstEveryPair) {
    check_random<float>(1.0, 0.0, 11);
    check_random<double>(1.0, 0.0, 12);
    check_random<float>(1.0, 5e3, 13);
    check_random<double>(1e-5, 1e4, 14);
    check_random<double>(1e8, -3e9, 15);
    check_random<float>(1e-3, 0.0, 16);
}

/// Two scenes: every (a, b) pair against the one-pair test, margins and filters included.
template <class T>
void check_two_scenes(double scale, double offset, std::uint64_t seed) {
    SplitMix64 rng(seed);
    Scene<T> s1, s2;
    const BasicTriangleMesh<T> sphere = sphere_mesh<T>(1, scale);
    const GeometryId g1 = s1.add_mesh(sphere), c1 = s1.add_mesh(cube_mesh<T>(T(0.6 * scale)));
    const GeometryId g2 = s2.add_mesh(cube_mesh<T>(T(0.8 * scale)));
    (void)s2.add_mesh(sphere);
    std::vector<InstanceId> ids1, ids2;
    const auto add = [&](Scene<T>& s, GeometryId g, std::vector<InstanceId>& ids) {
        Transform<T> pose;
        pose.rotation = scene_test::random_rotation<T>(rng);
        for (std::size_t a = 0; a < 3; ++a)
            pose.translation[a] = T(offset + scale * rng.uniform(-5.0, 5.0));
        InstanceOptions<T> o;
        o.margin = T(scale * std::array<double, 3>{0, 0, 0.2}[rng.next() % 3]);
        o.group = 1u << (rng.next() % 2);
        o.mask = rng.next() % 5 == 0 ? ~o.group : 0xFFFFFFFFu;
        ids.push_back(s.add_instance(g, pose, o));
    };
    for (int i = 0; i < 25; ++i) add(s1, i % 3 ? g1 : c1, ids1);
    for (int i = 0; i < 20; ++i) add(s2, GeometryId(std::uint32_t(i % 2)), ids2);
    (void)g2;
    std::vector<InstancePair> ignore;
    for (int k = 0; k < 10; ++k)
        ignore.push_back({ids1[rng.next() % ids1.size()], ids2[rng.next() % ids2.size()]});
    std::vector<InstancePair> expected;
    std::vector<std::pair<InstancePair, T>> measured;  // every wanted pair, distance less margins
    // The closest pair by every pair's one-pair distance less the margins, the lower (a's slot,
    // b's slot) on a tie.
    T closest = std::numeric_limits<T>::infinity();
    InstancePair closest_ids;
    for (const InstanceId a : ids1)
        for (const InstanceId b : ids2) {
            const auto& oa = s1.options(a);
            const auto& ob = s2.options(b);
            if (!may_collide(oa, ob) ||
                std::find(ignore.begin(), ignore.end(), InstancePair{a, b}) != ignore.end())
                continue;
            const Transform<T> rel =
                scene_detail::relative_pose<AccurateScalar<T>>(s1.pose(a), s2.pose(b));
            const auto& ma = s1.geometry(s1.geometry_of(a)).collision_model();
            const auto& mb = s2.geometry(s2.geometry_of(b)).collision_model();
            const T m = oa.margin + ob.margin;
            const T d = distance(ma, mb, rel).distance;
            const T less =
                m == T(0) ? d
                          : scene_detail::narrow<T>(AccurateScalar<T>(d) - AccurateScalar<T>(m));
            if (less < closest) closest = less, closest_ids = {a, b};
            measured.push_back({{a, b}, less});
            if (m == T(0) ? collides(ma, mb, rel) : d <= m) expected.push_back({a, b});
        }
    const SceneDistance<T> nearest = closest_pair(s1, s2, ignore);
    EXPECT_EQ(nearest.distance, closest);
    EXPECT_EQ(nearest.a, closest_ids.a);
    EXPECT_EQ(nearest.b, closest_ids.b);
    EXPECT_FALSE(closest_pair(s1, Scene<T>(), ignore));
    // Pairs within thresholds that keep none, some and all of them.
    std::sort(measured.begin(), measured.end());
    for (const double t : {-1.0, 0.0, 0.5, 2.0, 1e30}) {
        const T threshold = T(t * scale);
        std::vector<SceneDistance<T>> within;
        pairs_within(s1, s2, threshold, within, ignore);
        std::vector<std::pair<InstancePair, T>> want;
        for (const auto& m : measured)
            if (m.second <= threshold) want.push_back(m);
        ASSERT_EQ(within.size(), want.size()) << "threshold " << t;
        for (std::size_t i = 0; i < want.size(); ++i) {
            EXPECT_EQ((InstancePair{within[i].a, within[i].b}), want[i].first);
            EXPECT_EQ(within[i].distance, want[i].second);
        }
        if (t == 2.0) {
            EXPECT_GT(want.size(), 3u);
        }
    }
    std::vector<SceneDistance<T>> none;
    EXPECT_THROW(pairs_within(s1, s2, std::numeric_limits<T>::quiet_NaN(), none), Error);
    std::sort(expected.begin(), expected.end());
    std::vector<InstancePair> found;
    colliding_pairs(s1, s2, found, ignore);
    EXPECT_EQ(found, expected);
    EXPECT_GT(expected.size(), 3u);
    EXPECT_EQ(any_collision(s1, s2, ignore), !expected.empty());
    // Every found pair ignored: none left.
    std::vector<InstancePair> all_ignored = ignore;
    all_ignored.insert(all_ignored.end(), expected.begin(), expected.end());
    EXPECT_FALSE(any_collision(s1, s2, all_ignored));
    colliding_pairs(s1, s2, found, all_ignored);
    EXPECT_TRUE(found.empty());
    // An empty scene meets nothing.
    Scene<T> empty;
    EXPECT_FALSE(any_collision(s1, empty));
    colliding_pairs(empty, s2, found);
    EXPECT_TRUE(found.empty());
}

TEST(SceneDistance, TwoScenesAgainstEveryPair) {
    check_two_scenes<float>(1.0, 0.0, 21);
    check_two_scenes<double>(1.0, 1e5, 22);
    check_two_scenes<float>(1e-4, 10.0, 23);
    check_two_scenes<double>(1e9, 0.0, 24);
}

}  // namespace
}  // namespace bvhkit::distance_test
