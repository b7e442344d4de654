// Penetration depth and signed distance between closed meshes (query/mesh_penetration.hpp) against
// analytic answers: boxes into boxes, spheres into spheres (within the tessellation's bounds), a
// cube into an L-shaped solid, a sphere into a torus's hole, far from the origin and at small
// scale; the separation property on C1 poses of the shared meshes; continuity through contact;
// bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <numbers>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/query/mesh_penetration.hpp"
#include "bvhkit/volumes/aabb_volume.hpp"
#include "bvhkit/volumes/obb.hpp"
#include "random_rigid_poses.hpp"
#include "test_support.hpp"

namespace bvhkit::test {
namespace {

using Mesh = BasicTriangleMesh<double>;
using V3 = Vec<double, 3>;
using Solid = SolidModel<Obb<double>>;

/// A prism over a counter-clockwise polygon (xy) from z0 to z1; caps fanned from polygon vertex
/// `fan` (a reflex vertex of an L sees the whole polygon).
Mesh prism(const std::vector<std::array<double, 2>>& poly, double z0, double z1,
           std::uint32_t fan) {
    Mesh m;
    const auto n = std::uint32_t(poly.size());
    for (const auto& p : poly) m.vertices.push_back({p[0], p[1], z0});
    for (const auto& p : poly) m.vertices.push_back({p[0], p[1], z1});
    for (std::uint32_t k = 1; k + 1 < n; ++k) {
        const std::uint32_t i = (fan + k) % n, j = (fan + k + 1) % n;
        m.triangles.push_back({n + fan, n + i, n + j});  // top, facing +z
        m.triangles.push_back({fan, j, i});              // bottom, facing -z
    }
    for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t j = (i + 1) % n;
        m.triangles.push_back({i, j, n + j});
        m.triangles.push_back({i, n + j, n + i});
    }
    return m;
}

Mesh box(V3 lo, V3 hi) {
    return prism({{lo[0], lo[1]}, {hi[0], lo[1]}, {hi[0], hi[1]}, {lo[0], hi[1]}}, lo[2], hi[2], 0);
}

/// The L: [0,3]x[0,1] joined with [0,1]x[0,3], z in [0,1], all times s plus offset o.
Mesh l_solid(double s = 1, V3 o = V3(0.0)) {
    Mesh m = prism({{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 3}, {0, 3}}, 0, 1, 3);
    for (auto& v : m.vertices) v = v * s + o;
    return m;
}

double signed_volume(const Mesh& m) {
    double v = 0;
    for (const auto& t : m.triangles)
        v += dot(m.vertices[t[0]], cross(m.vertices[t[1]], m.vertices[t[2]]));
    return v / 6;
}

void orient_outward(Mesh& m) {
    if (signed_volume(m) < 0)
        for (auto& t : m.triangles) std::swap(t[1], t[2]);
}

/// An icosphere (vertices on the sphere) of radius r about c.
Mesh sphere(V3 c, double r, int subdivisions) {
    const double g = (1 + std::sqrt(5.0)) / 2;
    std::vector<V3> v = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                         {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
    std::vector<std::array<std::uint32_t, 3>> f = {
        {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (auto& p : v) p = normalize(p);
    for (int s = 0; s < subdivisions; ++s) {
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
        const auto middle = [&](std::uint32_t a, std::uint32_t b) {
            const auto key = std::minmax(a, b);
            const auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            v.push_back(normalize(v[a] + v[b]));
            return mid[key] = std::uint32_t(v.size() - 1);
        };
        std::vector<std::array<std::uint32_t, 3>> next;
        for (const auto& t : f) {
            const std::uint32_t ab = middle(t[0], t[1]), bc = middle(t[1], t[2]),
                                ca = middle(t[2], t[0]);
            next.push_back({t[0], ab, ca});
            next.push_back({t[1], bc, ab});
            next.push_back({t[2], ca, bc});
            next.push_back({ab, bc, ca});
        }
        f = next;
    }
    Mesh m;
    for (const auto& p : v) m.vertices.push_back(c + p * r);
    m.triangles = f;
    orient_outward(m);
    return m;
}

/// Least distance from the centre c to a face plane: the inscribed ball's radius.
double inradius(const Mesh& m, V3 c) {
    double r = 1e300;
    for (const auto& t : m.triangles) {
        const V3 n = normalize(
            cross(m.vertices[t[1]] - m.vertices[t[0]], m.vertices[t[2]] - m.vertices[t[0]]));
        r = std::min(r, std::abs(dot(n, m.vertices[t[0]] - c)));
    }
    return r;
}

Mesh torus(double major, double minor, std::uint32_t nu, std::uint32_t nv) {
    Mesh m;
    const double tau = 2 * std::numbers::pi;
    for (std::uint32_t i = 0; i < nu; ++i)
        for (std::uint32_t j = 0; j < nv; ++j) {
            const double u = tau * i / nu, w = tau * j / nv;
            m.vertices.push_back({(major + minor * std::cos(w)) * std::cos(u),
                                  (major + minor * std::cos(w)) * std::sin(u),
                                  minor * std::sin(w)});
        }
    for (std::uint32_t i = 0; i < nu; ++i)
        for (std::uint32_t j = 0; j < nv; ++j) {
            const std::uint32_t a = i * nv + j, b = ((i + 1) % nu) * nv + j,
                                c = ((i + 1) % nu) * nv + (j + 1) % nv, d = i * nv + (j + 1) % nv;
            m.triangles.push_back({a, b, c});
            m.triangles.push_back({a, c, d});
        }
    orient_outward(m);
    return m;
}

Transform<double> shift(V3 t) {
    return {Mat3<double>::identity(), t};
}

/// The separation property, checked apart from the query: B moved by (1 + 1e-6) of the returned
/// translation meets no face of A (exact test) and no vertex of one lies in the other (exact
/// winding number); by (1 - 1e-3) it still overlaps.
template <class M>
void expect_separates(const Solid& a, const Solid& b, const WindingNumberMesh<double>& wa,
                      const WindingNumberMesh<double>& wb, const M& ma, const M& mb,
                      const Transform<double>& pose, const MeshSignedDistance<double>& r,
                      const std::string& what) {
    ASSERT_LE(r.signed_distance, 0.0) << what;
    const double depth = -r.signed_distance;
    const auto moved = [&](double f) {
        return Transform<double>{pose.rotation, pose.translation + r.normal * (depth * f)};
    };
    const auto overlap = [&](const Transform<double>& p) {
        if (collides(a.collision(), b.collision(), p)) return true;
        const V3 vb = p.apply(V3(mb.vertex(0)));
        const V3 va = p.inverse().apply(V3(ma.vertex(0)));
        return std::lround(wa.exact(vb)) != 0 || std::lround(wb.exact(va)) != 0;
    };
    EXPECT_FALSE(overlap(moved(1 + 1e-6))) << what << " depth " << depth;
    EXPECT_TRUE(overlap(moved(1 - 1e-3))) << what << " depth " << depth;
    EXPECT_TRUE(r.verified) << what;
    EXPECT_NEAR(length(r.point_b - r.point_a), depth, 1e-6 * (1 + depth)) << what;
}

TEST(MeshPenetration, OpenMeshAndBadPoseAreErrors) {
    Mesh open = box({0, 0, 0}, {1, 1, 1});
    open.triangles.pop_back();
    EXPECT_THROW(Solid{open}, Error);
    EXPECT_THROW(Solid{Mesh{}}, Error);
    const Solid a(box({0, 0, 0}, {1, 1, 1}));
    Transform<double> bad = shift({0, 0, 0});
    bad.rotation = Mat3<double>::identity();
    bad.rotation[0][0] = 2;
    EXPECT_THROW(signed_distance_between(a, a, bad), Error);
    bad = shift({std::nan(""), 0, 0});
    EXPECT_THROW(signed_distance_between(a, a, bad), Error);
}

/// Two meshes as one (b's vertices after a's).
Mesh joined(const Mesh& a, const Mesh& b) {
    Mesh m = a;
    const auto n = std::uint32_t(a.vertices.size());
    m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
    for (const auto& t : b.triangles) m.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
    return m;
}

TEST(MeshPenetration, Convexity) {
    EXPECT_TRUE(Solid(box({0, 0, 0}, {1, 2, 3})).convex());
    EXPECT_TRUE(Solid(sphere({0, 0, 0}, 1, 2)).convex());
    EXPECT_FALSE(Solid(l_solid()).convex());
    EXPECT_FALSE(Solid(torus(2, 0.5, 24, 12)).convex());
    // Two disjoint boxes: every edge convex, but two pieces.
    EXPECT_FALSE(Solid(joined(box({0, 0, 0}, {1, 1, 1}), box({3, 0, 0}, {4, 1, 1}))).convex());
}

TEST(MeshPenetration, BoxesApartAndInto) {
    const Solid a(box({0, 0, 0}, {2, 2, 2})), b(box({0, 0, 0}, {1, 1, 1}));
    // Apart by 0.5 along x.
    auto r = signed_distance_between(a, b, shift({2.5, 0.5, 0.5}));
    EXPECT_NEAR(r.signed_distance, 0.5, 1e-12);
    EXPECT_NEAR(r.normal[0], 1.0, 1e-12);
    EXPECT_EQ(r.quality, DepthQuality::Exact);
    // Into a by 0.3 along x (each other way is longer): depth 0.3 along +x.
    r = signed_distance_between(a, b, shift({1.7, 0.5, 0.5}));
    EXPECT_NEAR(r.signed_distance, -0.3, 1e-6);
    EXPECT_NEAR(r.normal[0], 1.0, 1e-6);
    EXPECT_EQ(r.quality, DepthQuality::Exact);
    EXPECT_FALSE(r.contained);
    // Wholly inside: b at [0.6,1.6] x [0.2,1.2] x [0.7,1.7]: the least exit is -y by 1.2.
    r = signed_distance_between(a, b, shift({0.6, 0.2, 0.7}));
    EXPECT_TRUE(r.contained);
    EXPECT_NEAR(r.signed_distance, -1.2, 1e-6);
    EXPECT_NEAR(r.normal[1], -1.0, 1e-6);
    // A rotated b: a unit cube turned 45 degrees about z, centre (2.3, 1, 1): its corner reaches
    // x = 2.3 - sqrt(0.5) inside a's face x = 2; the depth is 2 - (2.3 - sqrt(0.5)).
    Transform<double> turned{rotation_about(V3{0, 0, 1}, std::numbers::pi / 4), V3(0.0)};
    turned.translation = V3{2.3, 1, 1} - turned.rotation * V3{0.5, 0.5, 0.5};
    r = signed_distance_between(a, b, turned);
    EXPECT_NEAR(-r.signed_distance, 2 - (2.3 - std::sqrt(0.5)), 1e-6);
    EXPECT_NEAR(r.normal[0], 1.0, 1e-5);
}

TEST(MeshPenetration, SpheresWithinTessellation) {
    const double r1 = 1, r2 = 0.8;
    const Mesh m1 = sphere({0, 0, 0}, r1, 4), m2 = sphere({0, 0, 0}, r2, 3);
    const double in1 = inradius(m1, {0, 0, 0}), in2 = inradius(m2, {0, 0, 0});
    const Solid a(m1), b(m2);
    const V3 dir = normalize(V3{1, 2, -0.5});
    for (const double dist : {1.7, 1.5, 1.0, 0.4}) {
        const auto r = signed_distance_between(a, b, shift(dir * dist));
        // The meshes lie between their inscribed and circumscribed balls.
        EXPECT_LE(-r.signed_distance, r1 + r2 - dist + 1e-6) << dist;
        EXPECT_GE(-r.signed_distance, in1 + in2 - dist - 1e-6) << dist;
        EXPECT_GT(dot(r.normal, dir), 0.99) << dist;
        EXPECT_EQ(r.quality, DepthQuality::Exact);
    }
    // b inside a: must leave through a's surface, depth r1 + r2 - |c| (contained).
    const auto r = signed_distance_between(a, Solid(sphere({0, 0, 0}, 0.3, 3)), shift(dir * 0.2));
    EXPECT_TRUE(r.contained);
    EXPECT_LE(-r.signed_distance, 1.3 - 0.2 + 1e-6);
    EXPECT_GE(-r.signed_distance, in1 + 0.3 * in2 / r2 - 0.2 - 1e-6);
    EXPECT_GT(dot(r.normal, dir), 0.99);
}

/// The cube of side 0.5 centred at (x, y, 0.5), into the L; scale s and offset o applied to both.
void cube_into_l(double s, V3 o, double tol) {
    const Solid l(l_solid(s, o));
    const Solid cube(box(V3(0.0), V3(0.5 * s)));
    const auto at = [&](double x, double y) { return shift(o + V3{x - 0.25, y - 0.25, 0.25} * s); };
    // Over the long arm's top: out through +y by 1 - 0.65.
    auto r = signed_distance_between(l, cube, at(2, 0.9));
    EXPECT_EQ(r.quality, DepthQuality::LocalOptimum);
    EXPECT_GE(-r.signed_distance, 0.35 * s * (1 - 1e-7));  // it separates, so it is no shorter
    EXPECT_NEAR(-r.signed_distance, 0.35 * s, tol * s);
    EXPECT_NEAR(r.normal[1], 1.0, 1e-3);
    // In the inner corner: x to 1 by 0.15 and y to 1 by 0.2 together, (0.15, 0.2): 0.25.
    r = signed_distance_between(l, cube, at(1.1, 1.05));
    EXPECT_GE(-r.signed_distance, 0.25 * s * (1 - 1e-7));
    EXPECT_NEAR(-r.signed_distance, 0.25 * s, tol * s);
    EXPECT_NEAR(r.normal[0], 0.6, 1e-2);
    EXPECT_NEAR(r.normal[1], 0.8, 1e-2);
}

TEST(MeshPenetration, CubeIntoL) {
    cube_into_l(1, V3(0.0), 1e-4);
}
TEST(MeshPenetration, CubeIntoLFarFromOrigin) {
    cube_into_l(1, V3{1e5, -1e5, 1e5}, 1e-4);
}
TEST(MeshPenetration, CubeIntoLSmall) {
    cube_into_l(1e-4, V3{3e-4, 0, -1e-4}, 1e-4);
}

TEST(MeshPenetration, BoxesFarAndSmall) {
    for (const double s : {1e-4, 1.0, 1e3})
        for (const V3 o : {V3(0.0), V3{1e5, 1e5, -1e5}}) {
            const Solid a(box(o, o + V3(2 * s))), b(box(V3(0.0), V3(s)));
            const auto r = signed_distance_between(a, b, shift(o + V3{1.7, 0.5, 0.5} * s));
            EXPECT_NEAR(-r.signed_distance, 0.3 * s, 1e-6 * s) << s << " " << o[0];
            EXPECT_NEAR(r.normal[0], 1.0, 1e-6);
        }
}

TEST(MeshPenetration, SphereIntoTorusHole) {
    // The hole's radius is 2 - 0.5 = 1.5; a ball of radius 1.7 at the centre must rise until its
    // distance to the tube's centre circle is 1.7 + 0.5: h = sqrt(2.2^2 - 2^2), along +-z.
    const double R = 2, r = 0.5, rs = 1.7;
    const Solid torus_solid(torus(R, r, 128, 48));
    const Solid ball(sphere({0, 0, 0}, rs, 4));
    const double want = std::sqrt((rs + r) * (rs + r) - R * R);
    const auto q = signed_distance_between(torus_solid, ball, shift({0.01, -0.02, 0.03}));
    // Both meshes lie inside their smooth shapes, so the smooth depth bounds theirs from above
    // (up to the offset's change of it); the tessellation's error from below.
    EXPECT_LE(-q.signed_distance, want + 0.04);
    EXPECT_NEAR(-q.signed_distance, want - 0.03, 0.02);  // z already 0.03 up
    EXPECT_GT(std::abs(q.normal[2]), 0.99);
    // A smaller ball in the hole is apart.
    const auto apart =
        signed_distance_between(torus_solid, Solid(sphere({0, 0, 0}, 1.3, 3)), shift(V3(0.0)));
    EXPECT_NEAR(apart.signed_distance, 0.2, 0.01);
}

TEST(MeshPenetration, FloatModels) {
    using SolidF = SolidModel<Obb<float>>;
    const SolidF a(box({0, 0, 0}, {2, 2, 2})), b(box({0, 0, 0}, {1, 1, 1})), l(l_solid());
    const Transform<float> p{Mat3<float>::identity(), Vec<float, 3>{1.7f, 0.5f, 0.5f}};
    auto r = signed_distance_between(a, b, p);
    EXPECT_NEAR(r.signed_distance, -0.3f, 1e-5f);
    EXPECT_EQ(r.quality, DepthQuality::Exact);
    const Transform<float> q{Mat3<float>::identity(), Vec<float, 3>{1.85f, 0.8f, 0.25f}};
    r = signed_distance_between(l, b, q);
    EXPECT_NEAR(r.signed_distance, -0.2f, 1e-4f);
    EXPECT_TRUE(r.verified);
}

TEST(MeshPenetration, EveryPieceOfASolidIsAskedWhetherItIsInside) {
    // b is two unit cubes: [0,1]^3 far from a, and [25,26]^3 wholly inside a = [20,30]^3. No
    // faces meet; the inner piece alone overlaps, and leaving a takes at least 5 (along +x, +y
    // or +z).
    const Solid a(box({20, 20, 20}, {30, 30, 30}));
    const Solid b(joined(box({0, 0, 0}, {1, 1, 1}), box({25, 25, 25}, {26, 26, 26})));
    const auto r = signed_distance_between(a, b, shift({0, 0, 0}));
    EXPECT_TRUE(r.contained);
    EXPECT_LE(r.signed_distance, -5 * (1 - 1e-6));
    EXPECT_GE(r.signed_distance, -6 * (1 + 1e-6));
    EXPECT_TRUE(r.verified);
    // The same two pieces as a, b a box around the inner one: a's piece inside b.
    const Solid big(box({24, 24, 24}, {27.5, 27.5, 27.5}));
    const auto q = signed_distance_between(b, big, shift({0, 0, 0}));
    EXPECT_TRUE(q.contained);
    EXPECT_LT(q.signed_distance, 0.0);
}

TEST(MeshPenetration, ApartNormalsAreUnitAtEveryScale) {
    for (const double s : {1e-170, 1e-30, 1.0, 1e30, 1e150}) {
        const Solid a(box({0, 0, 0}, {s, s, s})), b(box({0, 0, 0}, {s, s, s}));
        const auto r = signed_distance_between(a, b, shift({3 * s, 0, 0}));
        EXPECT_NEAR(r.signed_distance / s, 2.0, 1e-12) << s;
        EXPECT_NEAR(r.normal[0], 1.0, 1e-12) << s;
        EXPECT_NEAR(length(r.normal), 1.0, 1e-12) << s;
    }
}

TEST(MeshPenetration, ConvexDepthIsExactAtEveryScale) {
    // Float cubes [0,s]^3, b moved by (s/2, s/4, 0): depth s/2 along +x at every scale. EPA runs
    // on the pair brought to unit size (convex/distance.hpp), so its products of four
    // coordinates stay in range and the depth is exact from 1e-12 to 1e20.
    using SolidF = SolidModel<Obb<float>>;
    for (const float s : {1e-12f, 1e-3f, 1.0f, 1e3f, 1e10f, 1e20f}) {
        std::vector<std::array<double, 2>> sq = {{0, 0}, {s, 0}, {s, s}, {0, s}};
        const SolidF a(prism(sq, 0, s, 0)), b(prism(sq, 0, s, 0));
        const Transform<float> p{Mat3<float>::identity(), Vec<float, 3>{s / 2, s / 4, 0}};
        const auto r = signed_distance_between(a, b, p);
        EXPECT_NEAR(-r.signed_distance / s, 0.5, 1e-3) << s;
        EXPECT_NEAR(r.normal[0], 1.0f, 1e-3f) << s;
        EXPECT_EQ(r.quality, DepthQuality::Exact) << s;
    }
}

TEST(MeshPenetration, OptionsOutOfRangeAreErrors) {
    const Solid a(box({0, 0, 0}, {2, 2, 2})), b(box({0, 0, 0}, {1, 1, 1}));
    const auto with = [](auto change) {
        MeshPenetrationOptions o;
        change(o);
        return o;
    };
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const MeshPenetrationOptions& o : {with([](auto& o) { o.max_overlap_tests = 0; }),
                                            with([](auto& o) { o.smallest_angle = 0; }),
                                            with([&](auto& o) { o.smallest_angle = nan; }),
                                            with([](auto& o) { o.search_precision = 1; }),
                                            with([&](auto& o) { o.final_precision = nan; }),
                                            with([](auto& o) { o.final_precision = -1e-6; })})
        EXPECT_THROW(signed_distance_between(a, b, shift({1.7, 0.5, 0.5}), o), Error);
    EXPECT_NO_THROW(
        signed_distance_between(a, b, shift({1.7, 0.5, 0.5}), MeshPenetrationOptions{}));
}

TEST(MeshPenetration, ContinuityThroughContact) {
    // A ball moved across a box's face in steps: depth continuous and the normal never flips
    // while it overlaps (convex: exact each step).
    const Solid a(box({0, 0, 0}, {2, 2, 2})), b(sphere({0, 0, 0}, 0.5, 3));
    const double step = 0.01;
    double last = 0;
    V3 last_n(0.0);
    for (int k = 0; k <= 80; ++k) {
        const double x = 2.7 - k * step;  // centre from outside (apart) to 0.3 deep
        const auto r = signed_distance_between(a, b, shift({x, 1, 1}));
        if (k > 0) {
            EXPECT_LE(std::abs(r.signed_distance - last), step * 1.05 + 1e-9) << k;
            if (r.signed_distance < 0 && last < 0) {
                EXPECT_GT(dot(r.normal, last_n), 0.99) << k;
            }
        }
        last = r.signed_distance;
        last_n = r.normal;
    }
    EXPECT_LT(last, -0.25);
    // A cube sliding along the L's long arm at a fixed 0.2 into it: depth min(0.2, 3 - x_min)
    // (the way out turns from +y to +x near the arm's end, as the geometry forces).
    const Solid l(l_solid()), cube(box(V3(0.0), V3(0.5)));
    for (int k = 0; k <= 40; ++k) {
        const double xmin = 1.8 + k * 0.025;
        const auto r = signed_distance_between(l, cube, shift({xmin, 0.8, 0.25}));
        EXPECT_NEAR(-r.signed_distance, std::min(0.2, 3 - xmin), 1e-4) << xmin;
    }
    // The same slide with the last normal as the hint: the normal stays +y until the way out
    // through +x is shorter, then stays +x (one switch, where the geometry forces it).
    MeshPenetrationOptions o;
    int switches = 0;
    V3 last_normal(0.0);
    for (int k = 0; k <= 44; ++k) {
        const double xmin = 1.8 + k * 0.025;
        const auto r = signed_distance_between(l, cube, shift({xmin, 0.8, 0.25}), o);
        EXPECT_NEAR(-r.signed_distance, std::min(0.2, 3 - xmin), 1e-4) << xmin;
        if (k > 0 && dot(r.normal, last_normal) < 0.99) ++switches;
        last_normal = r.normal;
        o.hint = {r.normal[0], r.normal[1], r.normal[2]};
    }
    EXPECT_EQ(switches, 1);
}

template <class M>
void separation_on_c1(const char* name, std::size_t poses_full) {
    const auto path = shared_mesh(name);
    if (path.empty()) GTEST_SKIP() << name << " not found in " << data_dirs_text();
    const TriangleMesh mesh = read_mesh(path);
    const auto solid = std::make_unique<Solid>(mesh);
    const WindingNumberMesh<double> w(mesh);
    Aabb<double, 3> bounds;
    bounds.grow(V3(mesh.bounds().min)).grow(V3(mesh.bounds().max));
    const auto poses = random_rigid_poses(bounds, small_scale() ? 3 : poses_full, 2026);
    std::size_t overlapping = 0;
    for (std::size_t i = 0; i < poses.size(); ++i) {
        const auto r = signed_distance_between(*solid, *solid, poses[i]);
        if (r.signed_distance > 0) continue;
        ++overlapping;
        expect_separates(*solid, *solid, w, w, mesh, mesh, poses[i], r,
                         std::string(name) + " pose " + std::to_string(i));
    }
    std::printf("%s: %zu of %zu poses overlapping, all separated\n", name, overlapping,
                poses.size());
}

TEST(MeshPenetration, SeparationOnSpot) {
    separation_on_c1<TriangleMesh>("spot.obj", 30);
}
TEST(MeshPenetration, OpenSharedMeshesAreErrors) {
    // The shared bunny and teapot have holes: no interior, so no solid.
    for (const char* name : {"stanford-bunny.obj", "teapot.obj"}) {
        const auto path = shared_mesh(name);
        if (path.empty()) continue;
        EXPECT_THROW(Solid{read_mesh(path)}, Error) << name;
    }
}
// The shared bunny and teapot have holes (the Error above); these are closed.
TEST(MeshPenetration, SeparationOnIgea) {
    separation_on_c1<TriangleMesh>("igea.ply", 10);
}
TEST(MeshPenetration, SeparationOnFandisk) {
    separation_on_c1<TriangleMesh>("fandisk.obj", 20);
}
TEST(MeshPenetration, SeparationOnDragon) {
    separation_on_c1<TriangleMesh>("dragon-lowres.ply", 10);
}

}  // namespace
}  // namespace bvhkit::test
