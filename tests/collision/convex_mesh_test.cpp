// A convex shape against a mesh's CollisionModel (query/convex_mesh.hpp), judged by long double
// brute force over every world-space triangle that shares none of the library's arithmetic: a
// sphere's distance is its centre's distance to the nearest triangle less its radius, a capsule's
// its segment's (zero where the segment crosses a triangle) less its radius. Boxes are checked by
// bounds: no farther than the nearest mesh vertex's analytic distance to the box, and the witness
// points on both surfaces. Meshes of random triangles (slivers and needles among them) and
// spheres; far from the origin, tiny and huge scales; AABB and OBB trees.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/convex_mesh.hpp"
#include "bvhkit/volumes/aabb_volume.hpp"
#include "bvhkit/volumes/obb.hpp"
#include "test_support.hpp"

namespace bvhkit::convex_mesh_test {
namespace {

using LD = long double;
struct P {
    LD x, y, z;
};
P operator-(P a, P b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
P operator+(P a, P b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
P operator*(P a, LD s) {
    return {a.x * s, a.y * s, a.z * s};
}
LD dot(P a, P b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
P cross(P a, P b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
LD norm(P a) {
    return std::sqrt(dot(a, a));
}
P wide(const Vec3d& v) {
    return {v[0], v[1], v[2]};
}

/// The point of segment [a, b] nearest p.
P on_segment(P p, P a, P b) {
    const P d = b - a;
    const LD dd = dot(d, d);
    const LD t = dd > 0 ? std::clamp(dot(p - a, d) / dd, LD(0), LD(1)) : LD(0);
    return a + d * t;
}

/// Distance from p to triangle abc: inside the prism over the face, the plane distance; else the
/// nearest of the three edges.
LD point_triangle(P p, P a, P b, P c) {
    const P n = cross(b - a, c - a);
    const LD nn = dot(n, n);
    if (nn > 0) {
        const LD s1 = dot(cross(b - a, p - a), n), s2 = dot(cross(c - b, p - b), n),
                 s3 = dot(cross(a - c, p - c), n);
        if (s1 >= 0 && s2 >= 0 && s3 >= 0) return std::fabs(dot(p - a, n)) / std::sqrt(nn);
    }
    return std::min({norm(p - on_segment(p, a, b)), norm(p - on_segment(p, b, c)),
                     norm(p - on_segment(p, c, a))});
}

/// Distance between segments [p, q] and [a, b]: the minimum of the endpoint distances and, where
/// the segments' interiors are nearest, the distance between the lines' nearest points.
LD segment_segment(P p, P q, P a, P b) {
    LD best = std::min({norm(p - on_segment(p, a, b)), norm(q - on_segment(q, a, b)),
                        norm(a - on_segment(a, p, q)), norm(b - on_segment(b, p, q))});
    const P d1 = q - p, d2 = b - a, r = p - a;
    const LD aa = dot(d1, d1), ee = dot(d2, d2), bb = dot(d1, d2), cc = dot(d1, r), ff = dot(d2, r),
             den = aa * ee - bb * bb;
    if (den > 1e-30L * aa * ee) {
        const LD s = (bb * ff - cc * ee) / den, t = (aa * ff - bb * cc) / den;
        if (s > 0 && s < 1 && t > 0 && t < 1)
            best = std::min(best, norm((p + d1 * s) - (a + d2 * t)));
    }
    return best;
}

/// Distance between segment [p, q] and triangle abc (0 where the segment crosses it).
LD segment_triangle(P p, P q, P a, P b, P c) {
    const P n = cross(b - a, c - a);
    const LD dp = dot(p - a, n), dq = dot(q - a, n);
    if ((dp <= 0 && dq >= 0) || (dp >= 0 && dq <= 0)) {
        if (dp != dq) {
            const P x = p + (q - p) * (dp / (dp - dq));
            if (point_triangle(x, a, b, c) == 0) return 0;
        }
    }
    return std::min({point_triangle(p, a, b, c), point_triangle(q, a, b, c),
                     segment_segment(p, q, a, b), segment_segment(p, q, b, c),
                     segment_segment(p, q, c, a)});
}

Transformd random_pose(std::mt19937_64& rng, double spread, double offset) {
    std::normal_distribution<double> g;
    Vec3d axis{g(rng), g(rng), g(rng)};
    axis = axis / length(axis);
    std::uniform_real_distribution<double> u(-spread, spread), angle(-3.14159, 3.14159);
    return {rotation_about(axis, angle(rng)), Vec3d{offset + u(rng), offset + u(rng), u(rng)}};
}

struct WorldTriangles {
    std::vector<std::array<P, 3>> t;
    WorldTriangles(const BasicTriangleMesh<double>& m, const Transformd& pose) {
        for (const auto& tri : m.triangles) {
            std::array<P, 3> w;
            for (int k = 0; k < 3; ++k) {
                const Vec3d& v = m.vertices[tri[k]];
                LD c[3];
                for (int i = 0; i < 3; ++i)
                    c[i] = LD(pose.rotation[i][0]) * v[0] + LD(pose.rotation[i][1]) * v[1] +
                           LD(pose.rotation[i][2]) * v[2] + LD(pose.translation[i]);
                w[k] = {c[0], c[1], c[2]};
            }
            t.push_back(w);
        }
    }
};

BasicTriangleMesh<double> scaled(const TriangleMesh& m, double s) {
    BasicTriangleMesh<double> out;
    for (const auto& v : m.vertices) out.vertices.push_back(Vec3d(v) * s);
    out.triangles = m.triangles;
    return out;
}

template <class V>
void check_spheres_and_capsules(double s, double offset, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    const BasicTriangleMesh<double> meshes[2] = {scaled(make_soup(60, seed), s),
                                                 scaled(make_sphere(2), s)};
    int meeting = 0, apart = 0;
    for (const auto& m : meshes) {
        const CollisionModel<V> model(m);
        for (int i = 0; i < 60; ++i) {
            const Transformd mesh_pose = random_pose(rng, 0.5 * s, offset);
            const Transformd shape_pose = random_pose(rng, 1.5 * s, offset);
            const WorldTriangles world(m, mesh_pose);
            const double r = 0.2 * s, h = 0.4 * s;
            const ConvexShape<double> sphere{SphereShape<double>(r)};
            const ConvexShape<double> capsule{CapsuleShape<double>(r, h)};
            const P c = wide(shape_pose.translation);
            const P axis = wide(shape_pose.rotation * Vec3d{0, 0, h});
            LD to_sphere = std::numeric_limits<LD>::infinity(), to_capsule = to_sphere;
            for (const auto& t : world.t) {
                to_sphere = std::min(to_sphere, point_triangle(c, t[0], t[1], t[2]));
                to_capsule =
                    std::min(to_capsule, segment_triangle(c - axis, c + axis, t[0], t[1], t[2]));
            }
            const ConvexShape<double>* shapes[2] = {&sphere, &capsule};
            const LD reference[2] = {std::max(LD(0), to_sphere - r),
                                     std::max(LD(0), to_capsule - r)};
            for (int k = 0; k < 2; ++k) {
                const auto d = convex_mesh_distance(*shapes[k], shape_pose, model, mesh_pose);
                const double tol = 1e-9 * s + 1e-12 * std::fabs(offset);
                EXPECT_NEAR(d.distance, double(reference[k]), tol)
                    << "scale " << s << " offset " << offset << " pose " << i << " shape " << k;
                // The witnesses: as far apart as the distance, the mesh's on its triangle.
                EXPECT_NEAR(double(norm(wide(d.point_shape) - wide(d.point_mesh))), d.distance,
                            tol);
                ASSERT_LT(d.face, world.t.size());
                const auto& t = world.t[d.face];
                EXPECT_NEAR(double(point_triangle(wide(d.point_mesh), t[0], t[1], t[2])), 0.0, tol);
                if (std::fabs(double(reference[k]) - 0) > 1e-7 * s) {
                    const bool meets = reference[k] == 0;
                    EXPECT_EQ(convex_mesh_collides(*shapes[k], shape_pose, model, mesh_pose), meets)
                        << "scale " << s << " pose " << i << " shape " << k;
                    EXPECT_EQ(d.overlap, meets);
                } else if (reference[k] == 0) {
                    EXPECT_TRUE(convex_mesh_collides(*shapes[k], shape_pose, model, mesh_pose));
                }
                (reference[k] == 0 ? meeting : apart) += 1;
            }
        }
    }
    EXPECT_GT(meeting, 20);
    EXPECT_GT(apart, 20);
}

TEST(ConvexMesh, SpheresAndCapsulesAgainstBruteForce) {
    check_spheres_and_capsules<Aabb<double, 3>>(1.0, 0.0, 1);
    check_spheres_and_capsules<Obb<double>>(1.0, 0.0, 2);
    check_spheres_and_capsules<Aabb<double, 3>>(1.0, 1e5, 3);
    check_spheres_and_capsules<Obb<double>>(1e-5, 0.0, 4);
    check_spheres_and_capsules<Aabb<double, 3>>(1e5, 0.0, 5);
    check_spheres_and_capsules<Aabb<double, 3>>(std::ldexp(1.0, -700), 0.0, 6);
}

TEST(ConvexMesh, BoxesAreBoundedByTheVertices) {
    std::mt19937_64 rng(7);
    const BasicTriangleMesh<double> m = scaled(make_soup(80, 9), 1.0);
    const CollisionModel<Aabb<double, 3>> model(m);
    const Vec3d half{0.3, 0.2, 0.5};
    const ConvexShape<double> box{BoxShape<double>(half)};
    int meeting = 0;
    for (int i = 0; i < 200; ++i) {
        const Transformd mesh_pose = random_pose(rng, 0.5, 0), box_pose = random_pose(rng, 1.5, 0);
        const auto d = convex_mesh_distance(box, box_pose, model, mesh_pose);
        // No farther than the nearest mesh vertex (each vertex's distance to the box, in the
        // box's frame, analytically).
        LD nearest = std::numeric_limits<LD>::infinity();
        for (const Vec3d& v : m.vertices) {
            const Vec3d w = mesh_pose.apply(v);
            const Vec3d local = box_pose.rotation.transpose_times(w - box_pose.translation);
            LD sum = 0;
            for (int a = 0; a < 3; ++a) {
                const LD out = std::max(LD(0), std::fabs(LD(local[a])) - LD(half[a]));
                sum += out * out;
            }
            nearest = std::min(nearest, std::sqrt(sum));
        }
        EXPECT_LE(d.distance, double(nearest) + 1e-12) << i;
        // The box's witness on the box (within rounding), the mesh's on its face.
        const Vec3d local = box_pose.rotation.transpose_times(d.point_shape - box_pose.translation);
        for (int a = 0; a < 3; ++a) EXPECT_LE(std::fabs(local[a]), half[a] + 1e-9) << i;
        EXPECT_NEAR(length(d.point_shape - d.point_mesh), d.distance, 1e-9) << i;
        EXPECT_EQ(d.overlap, d.distance == 0);
        if (d.distance > 1e-7 || d.overlap) {
            EXPECT_EQ(convex_mesh_collides(box, box_pose, model, mesh_pose), d.overlap) << i;
        }
        meeting += d.overlap;
    }
    EXPECT_GT(meeting, 20);
    EXPECT_LT(meeting, 180);
}

TEST(ConvexMesh, EmptyMeshesAndBadPoses) {
    const CollisionModel<Aabb<double, 3>> empty{BasicTriangleMesh<double>{}};
    const ConvexShape<double> sphere{SphereShape<double>(1)};
    const Transformd identity{};
    EXPECT_FALSE(convex_mesh_collides(sphere, identity, empty, identity));
    const auto d = convex_mesh_distance(sphere, identity, empty, identity);
    EXPECT_TRUE(std::isinf(d.distance));
    EXPECT_FALSE(d.overlap);
    const CollisionModel<Aabb<double, 3>> model(scaled(make_sphere(1), 1.0));
    Transformd sheared;
    sheared.rotation[0][1] = 0.5;
    EXPECT_THROW(convex_mesh_distance(sphere, sheared, model, identity), Error);
    EXPECT_THROW(convex_mesh_collides(sphere, identity, model, sheared), Error);
    Transformd nan_pose;
    nan_pose.translation[0] = std::nan("");
    EXPECT_THROW(convex_mesh_distance(sphere, nan_pose, model, identity), Error);
    // A shape beyond double's range from the mesh: no contact, +inf; a tiny point near a tiny
    // triangle: its subnormal distance, not NaN.
    Transformd far_out, far_mesh;
    far_out.translation = Vec3d{1e308, 0, 0};
    far_mesh.translation = Vec3d{-1e308, 0, 0};
    EXPECT_FALSE(convex_mesh_collides(sphere, far_out, model, far_mesh));
    EXPECT_TRUE(std::isinf(convex_mesh_distance(sphere, far_out, model, far_mesh).distance));
    BasicTriangleMesh<double> speck;
    speck.vertices = {{0, 0, 0}, {1e-309, 0, 0}, {0, 1e-309, 0}};
    speck.triangles = {{0, 1, 2}};
    const CollisionModel<Aabb<double, 3>> tiny(speck);
    const ConvexShape<double> point{SphereShape<double>(0)};
    Transformd above;
    above.translation = Vec3d{0, 0, 3e-309};
    const auto near = convex_mesh_distance(point, above, tiny, identity);
    EXPECT_FALSE(std::isnan(near.point_mesh[0]));
    EXPECT_NEAR(near.distance, 3e-309, 1e-320);
    EXPECT_EQ(near.face, 0u);
}

}  // namespace
}  // namespace bvhkit::convex_mesh_test
