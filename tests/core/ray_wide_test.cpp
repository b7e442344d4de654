// The four-wide ray layout (query/ray_wide.hpp) against the binary walk, and the four-abreast
// watertight test (primitives/triangle_group.hpp) against the scalar one. Both must give the same
// answers to the bit: the wide walk only changes the order in which boxes are opened, and the
// four-abreast test must reject a lane only when the scalar test would. Whether those answers are
// right is judged against a long-double reference in ray_exactness_test.cpp, which runs on the
// wide layout (TriangleBvh<float>'s default).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/primitives/triangle_group.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using bvhkit::test::same_bits;

namespace {

/// The same hits from both layouts. Where two triangles are hit at the same t (a ray through a
/// shared vertex or edge), which one is reported depends on the order they are tested in, so then
/// the t must be the same and each must really be hit there.
void expect_same(const TriangleBvh<float>& wide, const TriangleBvh<float>& binary,
                 const std::vector<Triangle<float>>& tris, const std::vector<Ray3f>& rays) {
    std::size_t hits = 0, ties = 0;
    for (std::size_t r = 0; r < rays.size(); ++r) {
        const Hit<float> a = wide.closest_hit(rays[r]), b = binary.closest_hit(rays[r]);
        ASSERT_EQ(bool(a), bool(b)) << "ray " << r;
        hits += bool(a);
        if (a.primitive != b.primitive) {
            ++ties;
            ASSERT_TRUE(same_bits(a.t, b.t)) << "ray " << r << ": t " << a.t << " vs " << b.t;
            const auto h = tris[a.primitive].intersect_watertight(rays[r]);
            ASSERT_TRUE(h && same_bits(h->t, a.t) && same_bits(h->u, a.u) && same_bits(h->v, a.v))
                << "ray " << r;
            continue;
        }
        ASSERT_TRUE(same_bits(a.t, b.t) && same_bits(a.u, b.u) && same_bits(a.v, b.v))
            << "ray " << r << ": t " << a.t << " vs " << b.t;
        ASSERT_EQ(a.normal, b.normal) << "ray " << r;
        ASSERT_EQ(wide.any_hit(rays[r]), binary.any_hit(rays[r])) << "ray " << r;
    }
    // Enough hits and misses for the comparison to mean something.
    EXPECT_GT(hits, rays.size() / 20);
    EXPECT_LT(hits, rays.size());
    EXPECT_LT(ties, rays.size() / 10);
}

}  // namespace

TEST(WideRays, LayoutChosenAsDocumented) {
    const TriangleMesh mesh = make_sphere(2);
    EXPECT_EQ(TriangleBvh<float>(mesh).ray_width(), cpu_has_avx2() ? 8 : 4);
    TriangleBvhOptions four, eight;
    four.ray_layout = RayLayout::Wide4;
    eight.ray_layout = RayLayout(1);  // the deprecated Wide8, which is Auto
    EXPECT_EQ(TriangleBvh<float>(mesh, four).ray_width(), 4);
    EXPECT_EQ(TriangleBvh<float>(mesh, eight).ray_width(), cpu_has_avx2() ? 8 : 4);
    EXPECT_FALSE(TriangleBvh<double>(mesh).traces_wide());
    TriangleBvhOptions fast, binary;
    fast.triangle_test = TriangleTest::Fast;
    binary.ray_layout = RayLayout::Binary;
    EXPECT_FALSE(TriangleBvh<float>(mesh, fast).traces_wide());
    EXPECT_FALSE(TriangleBvh<float>(mesh, binary).traces_wide());
    EXPECT_FALSE(TriangleBvh<float>(TriangleMesh{}).traces_wide());
    EXPECT_FALSE(TriangleBvh<float>(TriangleMesh{}).closest_hit(Ray3f({0, 0, 0}, {1, 0, 0})));
}

// The ray layout of each width, read against the binary tree it came from: every leaf lane's
// groups in range and owned by that lane alone, every group owned; within a leaf, the groups
// full but the last, whose padding comes after its triangles; each triangle in exactly one lane,
// with its corners bit for bit and its own index; and a leaf's triangles those of the binary
// subtree under its box (each inside the lane's box).
Triangle<float> corners(const TriangleMesh& mesh, std::uint32_t t) {
    const auto& v = mesh.triangles[t];
    return {mesh.vertices[v[0]], mesh.vertices[v[1]], mesh.vertices[v[2]]};
}

template <int W>
void expect_layout_holds_every_triangle_once(const TriangleMesh& mesh) {
    const TriangleBvh<float> tree(mesh);
    const Bvh<Aabb3f>& bvh = tree.bvh();
    const auto& index = bvh.primitive_indices;
    const WideRayBvh<W> wide = make_wide_ray_bvh<W>(
        bvh, [&](std::uint32_t s) { return corners(mesh, index[s]); },
        [&](std::uint32_t s) { return index[s]; });
    constexpr int lanes = WideRayBvh<W>::Group::lanes;
    static_assert(lanes == (W == 8 ? 8 : 4));
    std::vector<int> owner_count(wide.groups.size(), 0), seen(mesh.triangle_count(), 0);
    for (const RayNode<W>& node : wide.nodes)
        for (int c = 0; c < W; ++c) {
            if (node.groups[c] == 0) continue;
            ASSERT_NE(node.child[c], invalid_index);
            ASSERT_LE(std::size_t(node.child[c]) + node.groups[c], wide.groups.size());
            const Aabb3f box({node.lo[0][c], node.lo[1][c], node.lo[2][c]},
                             {node.lo[3][c], node.lo[4][c], node.lo[5][c]});
            for (std::uint32_t g = node.child[c]; g < node.child[c] + node.groups[c]; ++g) {
                ++owner_count[g];
                const bool last = g + 1 == node.child[c] + node.groups[c];
                bool padded = false;
                for (int lane = 0; lane < lanes; ++lane) {
                    const std::uint32_t t = wide.groups[g].slot[lane];
                    if (t == invalid_index) {
                        ASSERT_TRUE(last) << "padding inside a leaf's run, group " << g;
                        padded = true;
                        continue;
                    }
                    ASSERT_FALSE(padded) << "a triangle after padding, group " << g;
                    ASSERT_LT(t, mesh.triangle_count());
                    ++seen[t];
                    const Triangle<float> want = corners(mesh, t);
                    const Triangle<float> got = wide.groups[g].triangle(lane);
                    ASSERT_EQ(std::memcmp(&got, &want, sizeof got), 0) << "triangle " << t;
                    ASSERT_TRUE(box.contains(want.bounds())) << "triangle " << t;
                }
            }
        }
    for (std::size_t g = 0; g < owner_count.size(); ++g)
        ASSERT_EQ(owner_count[g], 1) << "group " << g;
    for (std::size_t t = 0; t < seen.size(); ++t) ASSERT_EQ(seen[t], 1) << "triangle " << t;
}

TEST(WideRays, LayoutHoldsEveryTriangleOnce) {
    test::Random rng(3);
    TriangleMesh soup;  // leaves of every size, duplicates and zero-area triangles among them
    for (std::uint32_t i = 0; i < 3000; ++i) {
        const Vec3f c = rng.point_in(Aabb3f({0, 0, 0}, {10, 10, 10}));
        for (int k = 0; k < 3; ++k)
            soup.vertices.push_back(c + rng.point_in(Aabb3f({0, 0, 0}, {1, 1, 1})) *
                                            (i % 17 == 0 ? 0.0f : 1.0f));
        soup.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
        if (i % 29 == 0) soup.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
    }
    for (const TriangleMesh& mesh : {make_sphere(4), soup, make_sphere(0)}) {
        expect_layout_holds_every_triangle_once<4>(mesh);
        expect_layout_holds_every_triangle_once<8>(mesh);
    }
}

TEST(WideRays, SameAnswersAsTheBinaryWalkOnHardGeometry) {
    struct Case {
        std::string name;
        std::vector<Triangle<float>> tris;
    };
    std::vector<Case> cases{{"sphere", test::placed<float>(make_sphere(4), 1, 0)},
                            {"torus", test::placed<float>(make_torus(96, 48), 1, 0)},
                            {"far sphere", test::placed<float>(make_sphere(3), 1, 1e5)},
                            {"tiny sphere", test::placed<float>(make_sphere(3), 1e-6, 0)},
                            {"huge terrain", test::placed<float>(make_terrain(64), 1e6, 0)}};
    // Needles and slivers, duplicates and zero-area triangles.
    cases.push_back({"needles", test::random_needles(1500, 7, true)});
    if (const auto spot = test::shared_mesh("spot.obj"); !spot.empty())
        cases.push_back({"spot", test::placed<float>(read_mesh(spot), 1, 0)});
    TriangleBvhOptions binary, four, eight, four_of_eights;
    binary.ray_layout = RayLayout::Binary;
    four.ray_layout = RayLayout::Wide4;
    eight.ray_layout = RayLayout::Auto;
    // The four-wide walk over a tree of leaves priced in eights: what a tree saved where the
    // eight-wide layout runs becomes on a CPU without AVX2.
    four_of_eights.ray_layout = RayLayout::Wide4;
    four_of_eights.costs.leaf_block = 8;
    for (const Case& c : cases) {
        const TriangleBvh<float> flat(c.tris, binary);
        const auto rays = test::rays_through_box(c.tris, test::scaled(20000), 3);
        // Every width this CPU runs (eight needs AVX2).
        for (const auto& options : {four, eight, four_of_eights}) {
            const TriangleBvh<float> wide(c.tris, options);
            SCOPED_TRACE(c.name + ", width " + std::to_string(wide.ray_width()));
            expect_same(wide, flat, c.tris, rays);
            if (testing::Test::HasFatalFailure()) return;
        }
    }
}

TEST(WideRays, RefitKeepsTheWideLayoutInStep) {
    TriangleMesh mesh = make_sphere(4);
    TriangleBvhOptions binary;
    binary.ray_layout = RayLayout::Binary;
    TriangleBvh<float> wide(mesh), flat(mesh, binary);
    ASSERT_TRUE(wide.traces_wide());
    for (auto& v : mesh.vertices) v = v * (1.0f + 0.3f * v[0]) + Vec3f{0.1f, 0, 0};
    wide.refit(mesh);
    flat.refit(mesh);
    const auto tris = test::placed<float>(mesh, 1, 0);
    expect_same(wide, flat, tris, test::rays_through_box(tris, test::scaled(5000), 5));
}

// wide_ray_usable against its definition, written here per component: origin and direction
// finite, tmin <= tmax, some direction component non-zero, none subnormal; over every mix of the
// special values.
TEST(WideRays, UsableRaysAreTheDefinitionsOnes) {
    const float inf = std::numeric_limits<float>::infinity();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float least = std::numeric_limits<float>::min();
    const std::vector<float> values{0.0f,   -0.0f,   1.0f,  -2.5f, least, -least,
                                    1e-40f, -1e-45f, 3e38f, -inf,  inf,   nan};
    const auto reference = [](const Ray3f& r) {
        bool finite = r.tmin <= r.tmax, moves = false, subnormal = false;
        for (int a = 0; a < 3; ++a) {
            finite = finite && std::isfinite(r.origin[a]) && std::isfinite(r.direction[a]);
            moves = moves || r.direction[a] != 0.0f;
            subnormal = subnormal || std::fpclassify(r.direction[a]) == FP_SUBNORMAL;
        }
        return finite && moves && !subnormal;
    };
    std::size_t usable = 0, tested = 0;
    for (const float a : values)
        for (const float b : values)
            for (const float c : values)
                for (int k = 0; k < 7; ++k) {
                    Ray3f r;
                    r.direction = {a, b, c};
                    r.origin = {1.0f, -2.0f, 3.0f};
                    if (k == 1) r.origin = {c, 0.5f, a};  // the special values in the origin
                    if (k == 2) r.tmin = 2.0f, r.tmax = 1.0f;
                    if (k == 3) r.tmin = nan;
                    if (k == 4) r.tmin = 1.0f;  // tmin other than 0 in a valid window
                    if (k == 5) r.tmin = -inf;
                    if (k == 6) r.tmin = 1e-40f;
                    ASSERT_EQ(wide_ray_usable(r), reference(r))
                        << a << " " << b << " " << c << " " << k;
                    usable += reference(r);
                    ++tested;
                }
    EXPECT_GT(usable, tested / 20);
}

// The per-ray constants the wide walks make once, against their definitions: the slab constants
// (made four lanes at once) per component, and the watertight constants of a ray known usable
// (made without the checks) equal to the checked constructor's, bit for bit, over every mix of
// the special direction values a usable ray can have.
TEST(WideRays, PerRayConstantsAreTheDefinitionsOnes) {
    const float least = std::numeric_limits<float>::min();
    const float largest = std::numeric_limits<float>::max();  // its reciprocal is subnormal
    const std::vector<float> values{0.0f,   -0.0f, 1.0f,    -2.5f,   least,
                                    -least, 3e38f, -7e-30f, largest, -largest};
    const auto same = [](auto a, auto b) { return std::memcmp(&a, &b, sizeof a) == 0; };
    constexpr float s = 1.0f + 2.0f * rounding_gamma<float>(3);
    std::size_t tested = 0;
    for (const float a : values)
        for (const float b : values)
            for (const float c : values) {
                Ray3f r;
                r.direction = {a, b, c};
                r.origin = {1e5f, -2.0f, 3e-3f};
                if (!wide_ray_usable(r)) continue;
                const detail::SlabConstants k(r);
                // The fourth lane restricts nothing: origin 0, direction 1, rows 3 and 6.
                ASSERT_EQ(k.origin[3], 0.0f);
                ASSERT_EQ(k.inv[3], 1.0f);
                ASSERT_EQ(k.near[3], 3u);
                ASSERT_EQ(k.far[3], 6u);
                for (std::uint32_t axis = 0; axis < 3; ++axis) {
                    const float inv = 1.0f / r.direction[axis];
                    ASSERT_TRUE(same(k.inv[axis], inv)) << a << " " << b << " " << c;
                    ASSERT_TRUE(same(k.inv_far[axis], inv * s));
                    ASSERT_EQ(k.origin[axis], r.origin[axis]);
                    const bool negative = std::signbit(r.direction[axis]);
                    ASSERT_EQ(k.near[axis], negative ? axis + 3 : axis);
                    ASSERT_EQ(k.far[axis], negative ? axis : axis + 3);
                }
                const WatertightRay<float> checked(r);
                const WatertightRay<float> known(r, WatertightRay<float>::KnownValid{});
                ASSERT_TRUE(checked.valid);
                EXPECT_EQ(known.kx, checked.kx);
                EXPECT_EQ(known.ky, checked.ky);
                EXPECT_EQ(known.kz, checked.kz);
                EXPECT_TRUE(same(known.sx, checked.sx) && same(known.sy, checked.sy));
                EXPECT_TRUE(same(known.dz, checked.dz));
                EXPECT_TRUE(same(known.ox, checked.ox) && same(known.oy, checked.oy) &&
                            same(known.oz, checked.oz));
                EXPECT_TRUE(known.valid);
                ++tested;
            }
    EXPECT_GT(tested, 200u);
}

// The watertight test's axes against their definition, written here per component: kz the axis
// of the largest direction magnitude (d0 >= d1 ? (d0 >= d2 ? 0 : 2) : (d1 >= d2 ? 1 : 2), so the
// first of tied axes; a NaN compares false), kx and ky the next two in cyclic order, swapped when
// d[kz] < 0 (the winding kept; -0 is not below 0), and the origin read along them; for float and
// double rays, over every mix of the special values, unusable directions included (the checked
// constructor still chooses axes). The wide walks make these once per ray.
template <class T>
void expect_axes_as_defined() {
    const T inf = std::numeric_limits<T>::infinity();
    const T nan = std::numeric_limits<T>::quiet_NaN();
    const T least = std::numeric_limits<T>::min();
    const T tiny = std::numeric_limits<T>::denorm_min();
    const std::vector<T> values{T(0),   -T(0), T(1),    T(-1), T(2), T(-2.5), least,
                                -least, tiny,  T(3e30), -inf,  inf,  nan};
    std::size_t tested = 0;
    for (const T a : values)
        for (const T b : values)
            for (const T c : values) {
                Ray<T, 3> r;
                r.direction = {a, b, c};
                r.origin = {T(10), T(20), T(30)};
                const T m0 = std::fabs(a), m1 = std::fabs(b), m2 = std::fabs(c);
                const std::uint32_t kz = m0 >= m1 ? (m0 >= m2 ? 0 : 2) : (m1 >= m2 ? 1 : 2);
                std::uint32_t kx = (kz + 1) % 3, ky = (kz + 2) % 3;
                if (r.direction[kz] < T(0)) std::swap(kx, ky);
                const WatertightRay<T> w(r);
                ASSERT_EQ(w.kz, kz) << a << " " << b << " " << c;
                ASSERT_EQ(w.kx, kx) << a << " " << b << " " << c;
                ASSERT_EQ(w.ky, ky) << a << " " << b << " " << c;
                ASSERT_EQ(w.ox, r.origin[kx]);
                ASSERT_EQ(w.oy, r.origin[ky]);
                ASSERT_EQ(w.oz, r.origin[kz]);
                ++tested;
            }
    EXPECT_EQ(tested, values.size() * values.size() * values.size());
}

TEST(WideRays, WatertightAxesAreTheDefinitionsOnes) {
    expect_axes_as_defined<float>();
    expect_axes_as_defined<double>();
}

// SlabConstants::meets (the closest-hit early out on the tree's bounds) decides as the scalar slab
// test of the binary walk (RaySlabData::clip, the same rounding model written independently), on
// rays that touch the box exactly: aimed at its corners, edges and faces, grazing a face with a
// zero direction component of either sign, from inside and outside, with flat boxes and far
// offsets; and a mesh whose triangles lie on its own bounds is hit from outside at every corner and
// edge.
TEST(WideRays, BoxEarlyOutDecidesAsTheSlabTest) {
    test::Random rng(23);
    std::size_t hits = 0, misses = 0;
    for (std::size_t i = 0; i < test::scaled(200000, 10); ++i) {
        const double offset = i % 3 == 0 ? 1e5 : 0.0;
        Vec3f lo, hi;
        for (int a = 0; a < 3; ++a) {
            lo[a] = float(offset + rng.uniform(-1, 1));
            hi[a] =
                i % 7 == std::size_t(a) ? lo[a] : float(double(lo[a]) + rng.uniform(0, 2));  // flat
        }
        const Aabb3f box(lo, hi);
        Vec3f target, origin;
        for (int a = 0; a < 3; ++a) {
            const std::uint32_t pick = rng.below(3);  // a corner, edge or face coordinate
            target[a] = pick == 0 ? lo[a] : pick == 1 ? hi[a] : float(rng.uniform(lo[a], hi[a]));
            origin[a] = float(offset + rng.uniform(-4, 4));
        }
        Ray3f ray;
        ray.origin = origin;
        ray.direction = target - origin;
        if (i % 5 == 1) {  // grazing: parallel to a face, in its plane
            const int a = int(i % 3);
            ray.origin[a] = rng.below(2) ? lo[a] : hi[a];
            ray.direction[a] = rng.below(2) ? 0.0f : -0.0f;
        }
        if (i % 9 == 4) ray.tmax = float(rng.uniform(0, 1.5));
        if (i % 11 == 6) ray.tmin = float(rng.uniform(0, 1));
        if (!wide_ray_usable(ray)) continue;
        float t0 = ray.tmin, t1 = ray.tmax;
        const bool want = RaySlabData<float, 3>(ray).clip(box, t0, t1);
        ASSERT_EQ(detail::SlabConstants(ray).meets(box, ray.tmin, ray.tmax), want) << i;
        (want ? hits : misses)++;
    }
    EXPECT_GT(hits, test::scaled(200000, 10) / 10);
    EXPECT_GT(misses, test::scaled(200000, 10) / 20);

    // A cube's triangles lie on its bounds: every ray from outside aimed at a corner or at an
    // edge's midpoint, along the axes and diagonally, hits as the binary walk says.
    TriangleMesh cube;
    for (int v = 0; v < 8; ++v)
        cube.vertices.push_back({v & 1 ? 1.0f : -1.0f, v & 2 ? 1.0f : -1.0f, v & 4 ? 1.0f : -1.0f});
    // Two triangles a face; the orientation does not matter to either walk.
    for (const auto& q : std::vector<std::array<std::uint32_t, 4>>{
             {0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}}) {
        cube.triangles.push_back({q[0], q[1], q[2]});
        cube.triangles.push_back({q[0], q[2], q[3]});
    }
    TriangleBvhOptions binary;
    binary.ray_layout = RayLayout::Binary;
    const TriangleBvh<float> wide(cube), flat(cube, binary);
    ASSERT_TRUE(wide.traces_wide());
    std::size_t tested = 0;
    for (int x = -1; x <= 1; ++x)
        for (int y = -1; y <= 1; ++y)
            for (int z = -1; z <= 1; ++z) {
                if (x == 0 && y == 0 && z == 0) continue;
                const Vec3f target{float(x), float(y), float(z)};
                for (const Vec3f& from : {target * 3.0f, target + Vec3f{3, 0, 0},
                                          target + Vec3f{0, -3, 0}, target + Vec3f{0, 0, 3}}) {
                    const Ray3f ray(from, target - from);
                    const Hit<float> a = wide.closest_hit(ray), b = flat.closest_hit(ray);
                    ASSERT_EQ(bool(a), bool(b)) << x << y << z;
                    if (a) {
                        ASSERT_EQ(a.t, b.t);
                    }
                    ++tested;
                }
            }
    EXPECT_EQ(tested, 26u * 4u);
}

// A NaN or infinite vertex in a triangle of the tree makes refit an Error for every layout, and
// the tree answers afterwards exactly as before it (a NaN box would make rays miss silently).
TEST(WideRays, RefitWithANonFiniteVertexIsAnError) {
    const TriangleMesh mesh = make_sphere(3);
    const auto tris = test::placed<float>(mesh, 1, 0);
    const auto rays = test::rays_through_box(tris, test::scaled(2000), 7);
    for (const RayLayout layout : {RayLayout::Binary, RayLayout::Wide4, RayLayout::Auto}) {
        TriangleBvhOptions options;
        options.ray_layout = layout;
        for (const float bad :
             {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
            TriangleBvh<float> tree(mesh, options);
            const TriangleBvh<float> untouched(mesh, options);
            TriangleMesh moved = mesh;
            for (auto& v : moved.vertices) v = v * 1.5f;
            moved.vertices[mesh.triangles[7][1]][2] = bad;
            EXPECT_THROW(tree.refit(moved), Error);
            SCOPED_TRACE("layout " + std::to_string(int(layout)));
            for (const Ray<float, 3>& ray : rays) {
                const Hit<float> a = tree.closest_hit(ray), b = untouched.closest_hit(ray);
                ASSERT_EQ(a.primitive, b.primitive);
                ASSERT_EQ(a.t, b.t);
            }
        }
    }
}

#if BVHKIT_RAY_AVX2
// The eight-abreast AVX test (the eight-wide walk's), in a function that carries its target.
[[gnu::target("avx2")]] void test_eight(const WatertightRay<float>& prep, const TriangleGroup8& g,
                                        float tmin, float tmax, bool (&got)[8],
                                        TriangleHit<float> (&hit)[8]) {
    const float open = tmax;
    const detail::avx2::WatertightRayLanes<8> lanes(prep);
    detail::avx2::intersect_watertight(lanes, g, tmin, tmax,
                                       [&](int lane, const TriangleHit<float>& h) {
                                           got[lane] = true;
                                           hit[lane] = h;
                                           return open;  // keep the whole range open
                                       });
}
#endif

// Every lane of the four-abreast test against the scalar test, with the whole range open (so that
// every hit is reported), on triangles and rays chosen to sit at the edge of the float filter:
// rays through vertices and edges, needles, zero-area triangles, coordinates from 1e-30 to 1e30;
// and the two-group AVX test against the four-abreast one.
TEST(WideRays, FourAbreastTestEqualsTheScalarTest) {
    test::Random rng(11);
    const std::size_t n = test::scaled(200000);
    std::size_t hits = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double scale = std::pow(10.0, rng.uniform(-30, 30) * (i % 3 == 0));
        TriangleGroup4 group;
        Triangle<float> tris[4];
        for (int lane = 0; lane < 4; ++lane) {
            Vec3f p[3];
            for (auto& q : p)
                for (int k = 0; k < 3; ++k) q[k] = float(rng.uniform(-1, 1) * scale);
            if (lane == 1) p[2] = p[0] + (p[1] - p[0]) * float(rng.uniform(0, 1));  // zero area
            if (lane == 2) p[2] = p[1] + Vec3f{1e-7f, 0, 0} * float(scale);         // a needle
            tris[lane] = {p[0], p[1], p[2]};
            group.set(lane, tris[lane], std::uint32_t(lane));
        }
        if (i % 9 == 0) group.clear(3);
        // Aim at a vertex, an edge point or an inside point of one lane's triangle.
        const Triangle<float>& aim = tris[rng.below(4)];
        const float a = float(rng.uniform(0, 1));
        Vec3f target = i % 3 == 0   ? aim.p1
                       : i % 3 == 1 ? aim.p0 + (aim.p2 - aim.p0) * a
                                    : (aim.p0 + aim.p1 + aim.p2) * (1.0f / 3.0f);
        Ray3f ray;
        for (int k = 0; k < 3; ++k) ray.origin[k] = float(rng.uniform(-3, 3) * scale);
        ray.direction = target - ray.origin;
        if (i % 10 == 0) ray.direction[i % 3] = 0.0f;
        const WatertightRay<float> prep(ray);
        bool got[4] = {}, want[4] = {};
        TriangleHit<float> got_hit[4], want_hit[4];
        float tmax = ray.tmax;
        detail::sse2::intersect_watertight(detail::sse2::WatertightRayLanes<4>(prep), group,
                                           ray.tmin, tmax,
                                           [&](int lane, const TriangleHit<float>& h) {
                                               got[lane] = true;
                                               got_hit[lane] = h;
                                               return ray.tmax;  // keep the whole range open
                                           });
        for (int lane = 0; lane < 4; ++lane) {
            if (group.slot[lane] == invalid_index) continue;
            want[lane] = intersect_watertight(prep, tris[lane].p0, tris[lane].p1, tris[lane].p2,
                                              ray.tmin, ray.tmax, want_hit[lane]);
            ASSERT_EQ(got[lane], want[lane]) << "case " << i << " lane " << lane;
            if (want[lane]) {
                ++hits;
                ASSERT_TRUE(same_bits(got_hit[lane].t, want_hit[lane].t) &&
                            same_bits(got_hit[lane].u, want_hit[lane].u) &&
                            same_bits(got_hit[lane].v, want_hit[lane].v))
                    << "case " << i << " lane " << lane;
            }
        }
        for (int lane = 0; lane < 4; ++lane)
            if (group.slot[lane] == invalid_index) {
                ASSERT_FALSE(got[lane]) << "a padding lane hit";
            }
#if BVHKIT_RAY_AVX2
        // Eight abreast in AVX (here the group's four triangles twice): each half answers as
        // the four-abreast test.
        if (cpu_has_avx2()) {
            TriangleGroup8 eight;
            for (int lane = 0; lane < 8; ++lane) {
                if (group.slot[lane & 3] == invalid_index)
                    eight.clear(lane);
                else
                    eight.set(lane, group.triangle(lane & 3), group.slot[lane & 3]);
            }
            bool got8[8] = {};
            TriangleHit<float> hit8[8];
            test_eight(prep, eight, ray.tmin, ray.tmax, got8, hit8);
            for (int lane = 0; lane < 8; ++lane) {
                ASSERT_EQ(got8[lane], got[lane & 3]) << "case " << i << " lane " << lane;
                if (got8[lane]) {
                    ASSERT_TRUE(same_bits(hit8[lane].t, got_hit[lane & 3].t) &&
                                same_bits(hit8[lane].u, got_hit[lane & 3].u) &&
                                same_bits(hit8[lane].v, got_hit[lane & 3].v))
                        << "case " << i << " lane " << lane;
                }
            }
        }
#endif
    }
    EXPECT_GT(hits, n / 4);
}
