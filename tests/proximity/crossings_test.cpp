// Inside/outside by one ray's signed crossings (query/crossings.hpp): the classification of hits
// on hand-made hits, and the winding number on closed meshes against the dense solid-angle sum
// (arithmetic the crossings do not share), with overlapping shells, inward-facing and split
// meshes, far from the origin.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/primitives/weld.hpp"
#include "bvhkit/query/closest_point_mesh.hpp"
#include "bvhkit/query/crossings.hpp"
#include "bvhkit/query/winding_number.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

/// Rays that report the hits they were given, whatever the ray.
struct GivenHits {
    std::vector<Hit<float>> hits;
    bool any_hit(const Ray<float, 3>&) const { return !hits.empty(); }
    template <class OnHit>
    void all_hits(const Ray<float, 3>&, OnHit&& on_hit) const {
        for (const Hit<float>& h : hits)
            if (!on_hit(h)) return;
    }
};

Hit<float> crossing(float t, float u, float v, Vec3f normal) {
    Hit<float> h;
    h.t = t;
    h.primitive = 0;
    h.u = u;
    h.v = v;
    h.normal = normal;
    return h;
}

TEST(Crossings, HitsAreCountedBySideOrLeftUndecided) {
    const Vec3f d = crossing_direction<float>();
    const Vec3f p{0, 0, 0};
    const auto winding = [&](std::vector<Hit<float>> hits) {
        return crossing_winding_number(GivenHits{std::move(hits)}, p);
    };
    EXPECT_EQ(winding({}), 0);
    EXPECT_EQ(winding({crossing(1, 0.3f, 0.3f, d)}), 1);           // leaves through the front
    EXPECT_EQ(winding({crossing(1, 0.3f, 0.3f, -2.0f * d)}), -1);  // enters through the front
    EXPECT_EQ(winding({crossing(1, 0.3f, 0.3f, -d), crossing(2, 0.2f, 0.1f, d)}), 0);
    EXPECT_EQ(winding({crossing(1, 0.3f, 0.3f, d), crossing(2, 0.2f, 0.1f, d)}), 2);
    // An edge or a vertex met exactly, a hit at the origin, a grazing hit: undecided.
    EXPECT_FALSE(winding({crossing(1, 0.0f, 0.3f, d)}));
    EXPECT_FALSE(winding({crossing(1, 0.3f, 0.0f, d)}));
    EXPECT_FALSE(winding({crossing(1, 0.4f, 0.6f, d)}));
    EXPECT_FALSE(winding({crossing(1, 0.4f, 0.6f - 1e-7f, d)}));
    EXPECT_FALSE(winding({crossing(0, 0.3f, 0.3f, d)}));
    const Vec3f along = normalize(cross(d, Vec3f{1, 0, 0}));  // perpendicular to d
    EXPECT_FALSE(winding({crossing(1, 0.3f, 0.3f, along)}));
    EXPECT_FALSE(winding({crossing(1, 0.3f, 0.3f, d), crossing(2, 0.3f, 0.0f, d)}));
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(crossing_winding_number(GivenHits{}, Vec3f{nan, 0, 0}));
    EXPECT_FALSE(crossing_winding_number(GivenHits{}, Vec3f{0, INFINITY, 0}));
}

TriangleMesh joined(const TriangleMesh& a, const TriangleMesh& b) {
    TriangleMesh m = a;
    const auto base = std::uint32_t(a.vertices.size());
    m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
    for (auto t : b.triangles) m.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    return m;
}

TriangleMesh moved(TriangleMesh m, Vec3f by, float scale = 1) {
    for (auto& v : m.vertices) v = v * scale + by;
    return m;
}

TriangleMesh flipped(TriangleMesh m) {
    for (auto& t : m.triangles) std::swap(t[1], t[2]);
    return m;
}

/// The dense reference: every triangle's solid angle, summed in long double.
long double dense_winding(const TriangleMesh& mesh, const Vec3d& q) {
    long double sum = 0;
    for (const auto& t : mesh.triangles)
        sum += solid_angle(Vec3d(mesh.vertices[t[0]]), Vec3d(mesh.vertices[t[1]]),
                           Vec3d(mesh.vertices[t[2]]), q);
    return sum / (4 * std::numbers::pi_v<long double>);
}

template <class T>
void expect_dense_windings(const TriangleMesh& mesh, std::uint64_t seed) {
    BasicTriangleMesh<T> m;
    for (const auto& v : mesh.vertices) m.vertices.push_back(Vec<T, 3>(v));
    m.triangles = mesh.triangles;
    ASSERT_TRUE(is_closed_surface(m, weld_vertices(m)));
    const TriangleBvh<T> rays(m);
    const ClosestPointMesh<T> surface(m);
    const Aabb3f box = mesh.bounds();
    const Vec3f e = box.extent();
    const double size = length(Vec3d(e));
    test::Random rng(seed);
    int decided = 0, tested = 0, inside = 0;
    // Each point's reference sums every triangle: fewer points under the sanitizers.
    const int count = int(test::scaled(3000, 5));
    for (int i = 0; i < count; ++i) {
        const Vec3f q = rng.point_in(Aabb3f(box.min - e * 0.2f, box.max + e * 0.2f));
        // A point on the surface (float points far from the origin can land on a face) is on
        // neither side.
        if (surface.closest_point(Vec<T, 3>(q)).distance <= 1e-6 * size) continue;
        const long double w = dense_winding(mesh, Vec3d(q));
        ASSERT_LT(std::abs(w - std::round(w)), 1e-6L);  // an integer off a closed surface
        ++tested;
        inside += std::round(w) != 0;
        if (const auto got = crossing_winding_number(rays, Vec<T, 3>(q))) {
            ++decided;
            EXPECT_EQ(*got, int(std::round(w))) << "point " << q[0] << " " << q[1] << " " << q[2];
        }
    }
    EXPECT_GT(tested, count * 5 / 6);
    EXPECT_GT(inside, count / 30);
    EXPECT_GE(decided, tested - 3);  // an exact edge or vertex hit is rare on random points
}

TEST(Crossings, WindingNumbersOfClosedMeshesEqualTheDenseSum) {
    const TriangleMesh sphere = make_sphere(3);
    expect_dense_windings<float>(sphere, 1);
    expect_dense_windings<double>(sphere, 2);
    expect_dense_windings<double>(moved(sphere, {1e5f, -2e5f, 3e5f}), 3);  // far from the origin
    expect_dense_windings<float>(moved(sphere, {0, 0, 0}, 1e-5f), 4);
    expect_dense_windings<double>(make_torus(24, 12), 5);
    // Overlapping shells (winding number 2 in the lens), a hollow ball, an inward sphere.
    expect_dense_windings<float>(joined(sphere, moved(sphere, {0.7f, 0, 0})), 6);
    expect_dense_windings<double>(joined(moved(sphere, {0, 0, 0}, 2), flipped(sphere)), 7);
    expect_dense_windings<double>(flipped(sphere), 8);
}

TEST(Crossings, ClosedSurfacesAreTold) {
    const TriangleMesh sphere = make_sphere(2);
    EXPECT_TRUE(is_closed_surface(sphere, weld_vertices(sphere)));
    EXPECT_TRUE(is_closed_surface(flipped(sphere), weld_vertices(sphere)));
    TriangleMesh open = sphere;
    open.triangles.pop_back();
    EXPECT_FALSE(is_closed_surface(open, weld_vertices(open)));
    EXPECT_FALSE(is_closed_surface(sphere, weld_vertices(sphere), {3}));
    // One triangle turned over: its edges run the same way as its neighbours'.
    TriangleMesh turned = sphere;
    std::swap(turned.triangles[5][1], turned.triangles[5][2]);
    EXPECT_FALSE(is_closed_surface(turned, weld_vertices(turned)));
    // Every triangle with corners of its own: closed once welded, open without.
    TriangleMesh split;
    for (const auto& t : sphere.triangles) {
        const auto k = std::uint32_t(split.vertices.size());
        for (int c = 0; c < 3; ++c) split.vertices.push_back(sphere.vertices[t[c]]);
        split.triangles.push_back({k, k + 1, k + 2});
    }
    EXPECT_TRUE(is_closed_surface(split, weld_vertices(split)));
    std::vector<std::uint32_t> unwelded(split.vertices.size());
    for (std::uint32_t i = 0; i < unwelded.size(); ++i) unwelded[i] = i;
    EXPECT_FALSE(is_closed_surface(split, unwelded));
    // Empty: closed (no edge), winding number 0 everywhere.
    EXPECT_TRUE(is_closed_surface(TriangleMesh{}, std::vector<std::uint32_t>{}));
}

}  // namespace
}  // namespace bvhkit
