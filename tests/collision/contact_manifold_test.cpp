// contact_manifold (query/contact_manifold.hpp) against analytic answers: a box pushed into a box
// (normal the face normal, depth the overlap), crossed boxes (no vertex inside), boxes resting on
// each other (touching, coplanar faces), far from the origin and at a tiny scale; sphere meshes
// into each other, with every vertex inside checked against the convex polytope's own planes in
// long double (inside iff behind every face plane; depth the smallest plane distance); and
// stepping one mesh through contact.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/contact_manifold.hpp"
#include "bvhkit/volumes/obb.hpp"

namespace bvhkit {
namespace {

using Mesh = BasicTriangleMesh<double>;
using Model = CollisionModel<Obb<double>>;
using V3 = Vec<double, 3>;

/// The box [lo, hi], 12 triangles counter-clockwise seen from outside.
Mesh box_mesh(V3 lo, V3 hi) {
    Mesh m;
    for (int i = 0; i < 8; ++i)
        m.vertices.push_back(
            {(i & 1) ? hi[0] : lo[0], (i & 2) ? hi[1] : lo[1], (i & 4) ? hi[2] : lo[2]});
    const std::uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                   {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& f : q) {
        m.triangles.push_back({f[0], f[1], f[2]});
        m.triangles.push_back({f[0], f[2], f[3]});
    }
    return m;
}

Mesh sphere_mesh(std::uint32_t subdivisions, double radius) {
    const TriangleMesh s = make_sphere(subdivisions);
    Mesh m;
    for (const auto& v : s.vertices)
        m.vertices.push_back(V3(v) * (radius / length(V3(v))));  // on the sphere in double
    m.triangles = s.triangles;
    return m;
}

struct Pair {
    Mesh ma, mb;
    Model a, b;
    ContactMesh<double> ca, cb;
    Pair(Mesh x, Mesh y) : ma(std::move(x)), mb(std::move(y)), a(ma), b(mb), ca(ma), cb(mb) {}
    ContactManifold<double> run(const Transform<double>& pose, ContactOptions o = {}) const {
        ContactManifold<double> r;
        contact_manifold(a, ca, b, cb, pose, o, r);
        return r;
    }
};

Transform<double> moved(V3 t) {
    Transform<double> p;
    p.translation = t;
    return p;
}

/// Twice the area of the convex hull of the points projected along z (at most 4 points).
double footprint_area(const std::vector<ContactPoint<double>>& pts) {
    std::vector<std::array<double, 2>> p;
    // Relative to the first point: absolute coordinates far from the origin would cancel.
    for (const auto& c : pts)
        p.push_back({c.point[0] - pts[0].point[0], c.point[1] - pts[0].point[1]});
    std::sort(p.begin(), p.end());
    const auto turn = [](auto o, auto a, auto b) {
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    };
    std::vector<std::array<double, 2>> h;  // monotone chain
    for (int pass = 0; pass < 2; ++pass) {
        const std::size_t base = h.size();
        for (const auto& q : p) {
            while (h.size() >= base + 2 && turn(h[h.size() - 2], h.back(), q) <= 0) h.pop_back();
            h.push_back(q);
        }
        h.pop_back();
        std::reverse(p.begin(), p.end());
    }
    double area = 0;
    for (std::size_t i = 0; i < h.size(); ++i) {
        const auto& u = h[i];
        const auto& v = h[(i + 1) % h.size()];
        area += u[0] * v[1] - u[1] * v[0];
    }
    return std::fabs(area) / 2;
}

// A 1 x 1 box (A) pushed by delta into the top of a 4 x 4 box (B, placed by the pose): every
// contact has normal +z (A is pushed up) and depth delta; the four points kept span A's whole
// footprint.
void box_into_box(double scale, double offset) {
    const double delta = 0.1 * scale;
    const V3 o(offset, -offset, offset / 2);
    const Pair p(box_mesh(o + V3(-0.5, -0.5, -0.1) * scale, o + V3(0.5, 0.5, 0.9) * scale),
                 box_mesh(V3(-2, -2, -3) * scale, V3(2, 2, 0) * scale));
    const double tol = 1e-12 * (std::fabs(offset) + scale) * 16;
    for (const std::uint32_t k : {4u, 0u}) {
        ContactOptions options;
        options.max_points_per_region = k;
        const ContactManifold<double> r = p.run(moved(o), options);
        ASSERT_TRUE(r.colliding);
        EXPECT_EQ(r.region_count(), 1u);
        ASSERT_FALSE(r.points.empty());
        EXPECT_NEAR(r.region_depths[0], delta, tol);
        EXPECT_EQ(r.region_normals[0], V3(0, 0, 1));
        int vertices_of_a = 0;
        for (const auto& c : r.points) {
            EXPECT_NE(c.kind, ContactKind::VertexOfB);  // B's corners lie outside A
            EXPECT_GE(c.point[2], o[2] - delta - tol);
            EXPECT_LE(c.point[2], o[2] + tol);
            EXPECT_LE(c.depth, delta + tol);
            EXPECT_GE(c.normal[2], 0.0);  // never pulling A into B
            if (c.kind != ContactKind::VertexOfA) continue;
            ++vertices_of_a;  // a bottom corner of A: the exact answer
            EXPECT_NEAR(c.depth, delta, tol);
            EXPECT_EQ(c.normal, V3(0, 0, 1));
        }
        if (k == 4) {  // A's four bottom corners
            EXPECT_EQ(vertices_of_a, 4);
            EXPECT_EQ(r.points.size(), 4u);
            EXPECT_NEAR(footprint_area(r.points), scale * scale, 1e-9 * scale * scale);
        } else {
            EXPECT_EQ(vertices_of_a, 4);
            EXPECT_EQ(r.points.size(), r.candidate_count);
        }
    }
}

TEST(ContactManifold, BoxIntoBoxIsExact) {
    box_into_box(1, 0);
}
TEST(ContactManifold, BoxIntoBoxFarFromTheOrigin) {
    box_into_box(1, 1e6);
}
TEST(ContactManifold, BoxIntoBoxAtTinyScale) {
    box_into_box(1e-4, 0);
}
TEST(ContactManifold, BoxIntoBoxTinyAndFar) {
    box_into_box(1e-4, 1e3);
}

// Two long boxes crossed at right angles, overlapping by delta in z: no vertex of either lies
// inside the other; the edges passing through the other box (a's bottom edges, b's top edges)
// carry the depth, exactly delta along +z, and the curve points mark the crossing's corners.
TEST(ContactManifold, CrossedBoxesWithNoVertexInside) {
    const double delta = 0.05;
    const Pair p(box_mesh({-2, -0.3, -delta}, {2, 0.3, 1}), box_mesh({-0.3, -2, -1}, {0.3, 2, 0}));
    ContactOptions all;
    all.max_points_per_region = 0;
    const ContactManifold<double> r = p.run(Transform<double>{}, all);
    ASSERT_TRUE(r.colliding);
    EXPECT_EQ(r.region_count(), 1u);
    EXPECT_EQ(r.region_depths[0], delta);
    EXPECT_EQ(r.region_normals[0], V3(0, 0, 1));
    int edges = 0;
    for (const auto& c : r.points) {
        EXPECT_NE(c.kind, ContactKind::VertexOfA);
        EXPECT_NE(c.kind, ContactKind::VertexOfB);
        EXPECT_GE(c.normal[2], 0.0);
        EXPECT_LE(std::fabs(c.point[0]), 0.3 + 1e-15);
        EXPECT_LE(std::fabs(c.point[1]), 0.3 + 1e-15);
        EXPECT_GE(c.point[2], -delta - 1e-15);
        EXPECT_LE(c.point[2], 1e-15);
        if (c.kind == ContactKind::Curve) {
            EXPECT_EQ(c.depth, 0.0);
        } else {
            ++edges;
            EXPECT_NEAR(c.depth, delta, 1e-15);
            EXPECT_NEAR(c.normal[2], 1, 1e-15);
        }
    }
    EXPECT_GE(edges, 4);  // a's two bottom edges, b's two top edges at least
    const ContactManifold<double> four = p.run(Transform<double>{});
    EXPECT_EQ(four.points.size(), 4u);
    EXPECT_NEAR(four.points[0].depth, delta, 1e-15);
    EXPECT_GT(footprint_area(four.points), 0.18);  // over half the 0.6 x 0.6 crossing
}

// A box resting on another (touching, faces coplanar and facing each other; equal footprints, so
// the side faces are coplanar too): depth 0 everywhere, normal +z on the faces that face.
TEST(ContactManifold, RestingBoxesTouch) {
    for (const double w : {0.5, 2.0}) {
        const Pair p(box_mesh({-0.5, -0.5, 0}, {0.5, 0.5, 1}), box_mesh({-w, -w, -1}, {w, w, 0}));
        ContactOptions all;
        all.max_points_per_region = 0;
        const ContactManifold<double> r = p.run(Transform<double>{}, all);
        ASSERT_TRUE(r.colliding);
        bool up = false;
        for (const auto& c : r.points) {
            EXPECT_EQ(c.depth, 0.0);
            EXPECT_EQ(c.kind, ContactKind::Curve);
            EXPECT_GE(c.normal[2], 0.0);  // never pulling A down
            up = up || c.normal[2] == 1.0;
        }
        EXPECT_TRUE(up);
    }
}

TEST(ContactManifold, ApartGivesNothing) {
    const Pair p(box_mesh({0, 0, 0}, {1, 1, 1}), box_mesh({0, 0, 0}, {1, 1, 1}));
    const ContactManifold<double> r = p.run(moved({0, 0, 1.0 + 1e-12}));
    EXPECT_FALSE(r.colliding);
    EXPECT_TRUE(r.points.empty());
    EXPECT_EQ(r.region_count(), 0u);
}

// Plane values of a convex mesh's faces at x, in long double: the reference of the sphere tests.
struct Planes {
    std::vector<std::array<long double, 4>> p;  // unit normal, offset
    explicit Planes(const Mesh& m, const Transform<double>& pose) {
        for (const auto& t : m.triangles) {
            using L = long double;
            L v[3][3];
            for (int k = 0; k < 3; ++k) {
                const V3 q = pose.apply(m.vertices[t[k]]);
                for (int a = 0; a < 3; ++a) v[k][a] = q[a];
            }
            L e1[3], e2[3], n[3];
            for (int a = 0; a < 3; ++a) e1[a] = v[1][a] - v[0][a], e2[a] = v[2][a] - v[0][a];
            n[0] = e1[1] * e2[2] - e1[2] * e2[1];
            n[1] = e1[2] * e2[0] - e1[0] * e2[2];
            n[2] = e1[0] * e2[1] - e1[1] * e2[0];
            const L len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            p.push_back({n[0] / len, n[1] / len, n[2] / len,
                         -(n[0] * v[0][0] + n[1] * v[0][1] + n[2] * v[0][2]) / len});
        }
    }
    /// Largest signed plane value: negative inside; minus the depth there.
    long double value(const V3& x) const {
        long double best = -INFINITY;
        for (const auto& q : p)
            best = std::max(best, q[0] * x[0] + q[1] * x[1] + q[2] * x[2] + q[3]);
        return best;
    }
};

// Unit sphere A at the origin, sphere B pushed in from +x by delta: every vertex of A inside B and
// of B inside A is found, with its depth; the deepest normal points along -x within the
// tessellation's angle, its depth is delta within the tessellation's error.
TEST(ContactManifold, SpheresMatchThePolytopes) {
    const Mesh s = sphere_mesh(3, 1.0);
    const Pair p(s, s);
    double h = 0;  // longest edge
    for (const auto& t : s.triangles)
        for (int k = 0; k < 3; ++k)
            h = std::max(h, length(s.vertices[t[k]] - s.vertices[t[(k + 1) % 3]]));
    for (const double delta : {0.02, 0.2, 0.7}) {
        const Transform<double> pose = moved({2 - delta, 0.01, -0.02});
        ContactOptions all;
        all.max_points_per_region = 0;
        const ContactManifold<double> r = p.run(pose, all);
        ASSERT_TRUE(r.colliding);
        const Planes in_b(s, pose), in_a(s, Transform<double>{});
        std::size_t expect_a = 0, expect_b = 0, got_a = 0, got_b = 0;
        for (const auto& v : s.vertices) {
            expect_a += in_b.value(v) < -1e-12;
            expect_b += in_a.value(pose.apply(v)) < -1e-12;
        }
        double deepest = 0;
        V3 deepest_normal{};
        for (const auto& c : r.points) {
            if (c.kind == ContactKind::VertexOfA) {
                ++got_a;
                EXPECT_NEAR(c.depth, double(-in_b.value(c.point)), 1e-12);
            } else if (c.kind == ContactKind::VertexOfB) {
                ++got_b;
                EXPECT_NEAR(c.depth, double(-in_a.value(c.point)), 1e-12);
            }
            EXPECT_LT(c.normal[0], 0.0);  // always pushing A away from B
            EXPECT_NEAR(length(c.normal), 1.0, 1e-12);
            if (c.depth > deepest) deepest = c.depth, deepest_normal = c.normal;
        }
        EXPECT_EQ(got_a, expect_a);
        EXPECT_EQ(got_b, expect_b);
        EXPECT_EQ(r.region_count(), 1u);
        // The facets lie within h^2 / 2 inside the spheres, the vertices on them.
        EXPECT_NEAR(deepest, delta, h * h) << delta;
        EXPECT_GT(-deepest_normal[0], std::cos(h));
        const ContactManifold<double> four = p.run(pose);
        EXPECT_EQ(four.points.size(), 4u);
        EXPECT_EQ(four.points[0].depth, deepest);
    }
}

// Without the walk only the corners of intersecting faces are tested: every vertex contact is one
// of them, each also found (same depth) by the full query, and the box case is unchanged.
TEST(ContactManifold, WithoutTheWalk) {
    const Mesh s = sphere_mesh(3, 1.0);
    const Pair p(s, s);
    const Transform<double> pose = moved({1.4, 0.02, 0.01});
    ContactOptions all, near;
    all.max_points_per_region = near.max_points_per_region = 0;
    near.walk_inside = false;
    const ContactManifold<double> full = p.run(pose, all), local = p.run(pose, near);
    std::vector<std::pair<double, double>> full_vertices;
    for (const auto& c : full.points)
        if (c.kind == ContactKind::VertexOfA) full_vertices.push_back({c.point[0], c.depth});
    std::size_t local_vertices = 0;
    for (const auto& c : local.points) {
        if (c.kind != ContactKind::VertexOfA) continue;
        ++local_vertices;
        EXPECT_NE(std::find(full_vertices.begin(), full_vertices.end(),
                            std::pair<double, double>(c.point[0], c.depth)),
                  full_vertices.end());
    }
    EXPECT_GT(local_vertices, 0u);
    EXPECT_LT(local_vertices, full_vertices.size());  // deep vertices are left out
    EXPECT_LT(local.region_depths[0], full.region_depths[0]);
}

// Two spheres in each model, each pair overlapping apart from the other: two regions.
TEST(ContactManifold, SeparateRegions) {
    Mesh two = sphere_mesh(2, 1.0);
    const Mesh one = two;
    const auto n = std::uint32_t(one.vertices.size());
    for (const auto& v : one.vertices) two.vertices.push_back(v + V3(5, 0, 0));
    for (const auto& t : one.triangles) two.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
    const Pair p(two, two);
    const ContactManifold<double> r = p.run(moved({1.7, 0.1, 0}));
    ASSERT_TRUE(r.colliding);
    ASSERT_EQ(r.region_count(), 2u);
    EXPECT_NE(r.points[0].point[0] < 3, r.points[r.region_offsets[1]].point[0] < 3);
    for (std::size_t g = 0; g < r.region_count(); ++g) {
        EXPECT_EQ(r.region_offsets[g + 1] - r.region_offsets[g], 4u);
        EXPECT_NEAR(r.region_depths[g], 0.3, 0.05);
        const double centre = r.points[r.region_offsets[g]].point[0] < 3 ? 0.85 : 5.85;
        for (std::uint32_t i = r.region_offsets[g]; i < r.region_offsets[g + 1]; ++i) {
            EXPECT_EQ(r.points[i].region, g);
            EXPECT_NEAR(r.points[i].point[0], centre, 0.5);
        }
    }
}

// B moved through A by small steps: the largest depth never jumps by more than the step (each
// contact's depth moves by at most the translation, and a contact appears at depth 0), no normal
// ever points against the motion, and the same pose gives the same answer twice.
TEST(ContactManifold, SmallStepsAreStable) {
    const Mesh s = sphere_mesh(3, 1.0);
    const Pair spheres(s, s);
    const Pair boxes(box_mesh({-0.5, -0.5, 0}, {0.5, 0.5, 1}), box_mesh({-2, -2, -2}, {2, 2, 0}));
    const double step = 1e-3;
    for (int which = 0; which < 2; ++which) {
        const Pair& p = which == 0 ? spheres : boxes;
        const V3 dir = which == 0 ? V3(-1, 0, 0) : V3(0, 0, 1);  // B's motion towards A
        const V3 start = which == 0 ? V3(2.05, 0.013, 0.007) : V3(0.1, 0.07, -0.05);
        ContactManifold<double> r, again;
        double last = 0;
        V3 last_normal{};
        for (int i = 0; i < 300; ++i) {
            const Transform<double> pose = moved(start + dir * (step * i));
            contact_manifold(p.a, p.ca, p.b, p.cb, pose, ContactOptions{}, r);
            contact_manifold(p.a, p.ca, p.b, p.cb, pose, ContactOptions{}, again);
            ASSERT_EQ(r.points.size(), again.points.size());
            for (std::size_t k = 0; k < r.points.size(); ++k) {
                EXPECT_EQ(r.points[k].point, again.points[k].point);
                EXPECT_EQ(r.points[k].depth, again.points[k].depth);
            }
            const double deepest = r.colliding ? r.region_depths[0] : 0.0;
            const V3 normal = r.colliding ? r.region_normals[0] : V3{};
            for (const auto& c : r.points)
                EXPECT_GT(dot(c.normal, dir), -1e-12) << which << " step " << i;
            EXPECT_LE(std::fabs(deepest - last), step * (1 + 1e-9)) << which << " step " << i;
            if (last_normal != V3{} && normal != V3{}) {
                EXPECT_GT(dot(normal, last_normal), 0.0) << which << " step " << i;
            }
            last = deepest;
            last_normal = normal;
        }
    }
}

TEST(ContactManifold, MismatchedContactMeshIsAnError) {
    const Mesh a = box_mesh({0, 0, 0}, {1, 1, 1});
    const Mesh s = sphere_mesh(1, 1.0);
    const Model ma(a), mb(a);
    const ContactMesh<double> ca(a), cs(s);
    ContactManifold<double> r;
    EXPECT_THROW(contact_manifold(ma, ca, mb, cs, Transform<double>{}, ContactOptions{}, r), Error);
    Transform<double> bad;
    bad.translation = {NAN, 0, 0};
    EXPECT_THROW(contact_manifold(ma, ca, mb, ca, bad, ContactOptions{}, r), Error);
}

}  // namespace
}  // namespace bvhkit
