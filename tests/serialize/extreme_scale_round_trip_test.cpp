// What builds must load: every saveable structure (TriangleBvh with both triangle tests,
// ClosestPointMesh, SignedDistanceMesh, WindingNumberMesh, CollisionModel with every volume type,
// DynamicTree), built in float and double over a mesh scaled by 10^k across the type's range and
// moved off the origin, saves, loads (with and without validate), saves again to the same bytes
// and answers a few queries bit for bit as the structure it was saved from. A build whose sizes
// (radius, extents, scale, longest edge) round past the largest finite value must still load.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "bvhkit/io/closest_point_mesh_file.hpp"
#include "bvhkit/io/collision_model_file.hpp"
#include "bvhkit/io/dynamic_tree_file.hpp"
#include "bvhkit/io/signed_distance_mesh_file.hpp"
#include "bvhkit/io/triangle_bvh_file.hpp"
#include "bvhkit/io/winding_number_mesh_file.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/distance.hpp"
#include "bvhkit/query/pairs_model.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using namespace bvhkit::test;

// A named namespace: the unity build shares anonymous ones between the folder's files.
namespace extreme_scale {

/// A bumpy sphere of radius ~`scale` around `scale * (0.25, -0.125, 0.0625)`, in T: corners in
/// the normal range, near the largest finite value, and for the smallest scales in denormals.
template <class T>
BasicTriangleMesh<T> scaled_sphere(double scale, std::uint32_t subdivisions) {
    const TriangleMesh unit = make_sphere(subdivisions, 0.2f);
    BasicTriangleMesh<T> mesh;
    mesh.triangles = unit.triangles;
    const Vec3d offset(0.25, -0.125, 0.0625);
    for (const Vec3f& v : unit.vertices)
        mesh.vertices.push_back(Vec<T, 3>((Vec3d(v) + offset) * scale));
    // A triangle the build leaves out (a NaN corner), and at the top of the range one whose
    // edges, box diagonal and skew projections pass T's largest finite value.
    const auto at = std::uint32_t(mesh.vertices.size());
    mesh.vertices.push_back(Vec<T, 3>(std::numeric_limits<T>::quiet_NaN()));
    mesh.triangles.push_back({0, 1, at});
    if (scale >= double(std::numeric_limits<T>::max()) / 4) {
        const T m = std::numeric_limits<T>::max() * T(0.9);
        mesh.vertices.push_back({-m, -m, T(0)});
        mesh.vertices.push_back({m, T(0), m});
        mesh.vertices.push_back({T(0), m, -m});
        mesh.triangles.push_back({at + 1, at + 2, at + 3});
    }
    return mesh;
}

/// `p` clamped to half the largest finite T, so a query point stays finite at any scale.
template <class T>
Vec<T, 3> finite_point(const Vec3d& p) {
    const double m = double(std::numeric_limits<T>::max()) * 0.5;
    return Vec<T, 3>(
        Vec3d(std::clamp(p[0], -m, m), std::clamp(p[1], -m, m), std::clamp(p[2], -m, m)));
}

/// Query points around the mesh: inside, near the surface and outside.
template <class T>
std::vector<Vec<T, 3>> query_points(double scale, std::size_t count) {
    SplitMix64 rng(11);
    std::vector<Vec<T, 3>> out;
    const Vec3d centre = Vec3d(0.25, -0.125, 0.0625) * scale;
    for (std::size_t i = 0; i < count; ++i)
        out.push_back(finite_point<T>(centre + rng.unit_vector() * (rng.uniform(0, 2.5) * scale)));
    return out;
}

template <class T>
Transform<T> pose_at(SplitMix64& rng, double scale) {
    const double w = rng.uniform(-1, 1), x = rng.uniform(-1, 1), y = rng.uniform(-1, 1),
                 z = rng.uniform(-1, 1);
    const double n = std::sqrt(w * w + x * x + y * y + z * z);
    Transform<T> pose;
    pose.rotation = Mat3<T>(rotation_from_quaternion(w / n, x / n, y / n, z / n));
    pose.translation = finite_point<T>(rng.unit_vector() * (rng.uniform(0, 2.5) * scale));
    return pose;
}

template <class T>
bool same_point(const MeshPoint<T>& a, const MeshPoint<T>& b) {
    return a.triangle == b.triangle && same_bits(a.point, b.point) &&
           same_bits(a.distance_squared, b.distance_squared) && same_bits(a.u, b.u) &&
           same_bits(a.v, b.v);
}

template <class T>
void triangle_bvh(const BasicTriangleMesh<T>& mesh, double scale, TriangleTest test) {
    TriangleBvhOptions options;
    options.triangle_test = test;
    const TriangleBvh<T> tree(mesh, options);
    const auto bytes = to_bytes(tree);
    const Vec3d centre = Vec3d(0.25, -0.125, 0.0625) * scale;
    for (const bool validate : {true, false}) {
        const TriangleBvh<T> loaded = triangle_bvh_from_bytes<T>(bytes, {validate});
        EXPECT_EQ(to_bytes(loaded), bytes);
        for (const Vec<T, 3>& o : query_points<T>(scale * 1.5, 16)) {
            // Toward the centre, a unit direction in double rounded to T.
            const Vec3d d = centre - Vec3d(o);
            const double n = std::max({std::fabs(d[0]), std::fabs(d[1]), std::fabs(d[2])});
            if (!(n > 0)) continue;
            const Ray<T, 3> ray{o, Vec<T, 3>(normalize(d * (1 / n)))};
            const Hit<T> a = tree.closest_hit(ray), b = loaded.closest_hit(ray);
            ASSERT_TRUE(a.primitive == b.primitive && same_bits(a.t, b.t) && same_bits(a.u, b.u) &&
                        same_bits(a.v, b.v) && same_bits(a.normal, b.normal));
        }
    }
}

template <class T>
void proximity(const BasicTriangleMesh<T>& mesh, double scale) {
    const auto points = query_points<T>(scale, 12);
    {
        const ClosestPointMesh<T> m(mesh);
        const auto bytes = to_bytes(m);
        for (const bool validate : {true, false}) {
            const ClosestPointMesh<T> loaded = closest_point_mesh_from_bytes<T>(bytes, {validate});
            EXPECT_EQ(to_bytes(loaded), bytes);
            NearestScratch<T> s1, s2;
            for (const auto& p : points)
                ASSERT_TRUE(same_point(m.closest_point(p, s1), loaded.closest_point(p, s2)));
        }
    }
    {
        const SignedDistanceMesh<T> m(mesh);
        const auto bytes = to_bytes(m);
        for (const bool validate : {true, false}) {
            const SignedDistanceMesh<T> loaded =
                signed_distance_mesh_from_bytes<T>(bytes, {validate});
            EXPECT_EQ(to_bytes(loaded), bytes);
            for (const auto& p : points) {
                const SignedDistance<T> a = m.signed_distance(p), b = loaded.signed_distance(p);
                ASSERT_TRUE(same_bits(a.distance, b.distance) && same_point(a.closest, b.closest));
            }
        }
    }
    {
        const WindingNumberMesh<T> m(mesh);
        const auto bytes = to_bytes(m);
        for (const bool validate : {true, false}) {
            const WindingNumberMesh<T> loaded =
                winding_number_mesh_from_bytes<T>(bytes, {validate});
            EXPECT_EQ(to_bytes(loaded), bytes);
            for (const auto& p : points) {
                ASSERT_TRUE(same_bits(m.fast(p, T(2), 2), loaded.fast(p, T(2), 2)));
                ASSERT_TRUE(same_bits(m.exact(p), loaded.exact(p)));
            }
        }
    }
}

template <class V>
void collision(const BasicTriangleMesh<typename V::Scalar>& mesh, double scale,
               const std::string& name) {
    using T = typename V::Scalar;
    SCOPED_TRACE(name);
    const CollisionModel<V> model(mesh);
    const auto bytes = to_bytes(model);
    for (const bool validate : {true, false}) {
        CollisionModel<V> loaded;
        ASSERT_NO_THROW(loaded = collision_model_from_bytes<V>(bytes, {validate}))
            << "scale() " << double(model.scale());
        EXPECT_EQ(to_bytes(loaded), bytes);
        EXPECT_TRUE(same_bits(loaded.scale(), model.scale()));
        SplitMix64 rng(3);
        CollideResult<T> r1, r2;
        for (int i = 0; i < 2; ++i) {
            const Transform<T> pose = pose_at<T>(rng, scale);
            collide(model, model, pose, {}, r1);
            collide(loaded, loaded, pose, {}, r2);
            ASSERT_EQ(r1.colliding, r2.colliding);
            ASSERT_EQ(r1.contacts.size(), r2.contacts.size());
            for (std::size_t c = 0; c < r1.contacts.size(); ++c) {
                const Contact<T>&x = r1.contacts[c], &y = r2.contacts[c];
                ASSERT_TRUE(x.triangle_a == y.triangle_a && x.triangle_b == y.triangle_b &&
                            same_bits(x.p, y.p) && same_bits(x.q, y.q));
            }
            const DistanceResult<T> d1 = distance(model, model, pose),
                                    d2 = distance(loaded, loaded, pose);
            ASSERT_TRUE(same_bits(d1.distance, d2.distance) && d1.triangle_a == d2.triangle_a &&
                        d1.triangle_b == d2.triangle_b);
        }
    }
}

template <class T>
void collision_all(const BasicTriangleMesh<T>& mesh, double scale) {
    collision<Aabb<T, 3>>(mesh, scale, "aabb");
    collision<Sphere<T>>(mesh, scale, "sphere");
    collision<Kdop<T, 14>>(mesh, scale, "kdop14");
    collision<Kdop<T, 18>>(mesh, scale, "kdop18");
    collision<Kdop<T, 26>>(mesh, scale, "kdop26");
    // The oriented fits square coordinates (RSS radius budgets, hull distances, Quickhull's
    // orientations) or sum them (OBB extents at half the largest value): every scale here.
    collision<Obb<T>>(mesh, scale, "obb");
    collision<Rss<T>>(mesh, scale, "rss");
    collision<ObbRss<T>>(mesh, scale, "obbrss");
    collision<ConvexHull<T>>(mesh, scale, "hull");
}

template <class T>
void dynamic_tree(const BasicTriangleMesh<T>& mesh, double scale) {
    DynamicTreeOptions<T> options;
    options.margin_relative = T(0.1);
    DynamicTree<T, 3> tree(options);
    std::vector<ProxyId> ids;
    for (std::size_t i = 0; i < mesh.triangle_count(); ++i)
        if (triangle_at<T>(mesh, i).bounds().is_finite())
            ids.push_back(tree.create(triangle_at<T>(mesh, i).bounds(), i));
    std::vector<ProxyPair> pairs;
    tree.find_pairs(pairs);
    SplitMix64 rng(9);
    for (std::size_t i = 0; i < ids.size(); i += 3) {  // moves that leave the fat boxes
        const Aabb<T, 3> b = triangle_at<T>(mesh, (i * 7) % (ids.size() - 1)).bounds();
        tree.move(ids[i], b, finite_point<T>(rng.unit_vector() * scale));
    }
    const auto bytes = to_bytes(tree);
    auto loaded = dynamic_tree_from_bytes<T, 3>(bytes);
    EXPECT_EQ(to_bytes(loaded), bytes);
    for (const auto& p : query_points<T>(scale, 8)) {
        const Vec<T, 3> r = finite_point<T>(Vec3d(scale * 0.3));
        const Aabb<T, 3> box(p - r, p + r);
        std::vector<ProxyId> a, b;
        tree.query(box, [&](ProxyId id) { return a.push_back(id), true; });
        loaded.query(box, [&](ProxyId id) { return b.push_back(id), true; });
        ASSERT_EQ(a, b);
    }
    std::vector<ProxyPair> p1, p2;
    tree.find_pairs(p1);
    loaded.find_pairs(p2);
    EXPECT_EQ(p1.size(), p2.size());
}

/// The scales: 10^k across T's range (the smallest put corners into denormals; 1e19 in float and
/// 1e150 in double make squares of the extent overflow), and half the largest finite value, where
/// sums of three coordinates and the box's diagonal overflow.
template <class T>
std::vector<double> scales() {
    std::vector<double> out;
    const std::vector<int> exponents =
        sizeof(T) == 4 ? std::vector<int>{-38, -30, -20, -10, 0, 10, 19, 25, 30, 37, 38}
                       : std::vector<int>{-307, -300, -150, -50, 0, 50, 150, 155, 200, 300, 307};
    for (const int k : exponents) out.push_back(std::pow(10.0, k));
    out.push_back(double(std::numeric_limits<T>::max()) * 0.5);
    return out;
}

template <class T>
void every_structure_every_scale() {
    for (const double scale : scales<T>()) {
        SCOPED_TRACE(std::string(sizeof(T) == 4 ? "float" : "double") + " scale " +
                     std::to_string(std::log10(scale)));
        const BasicTriangleMesh<T> mesh = scaled_sphere<T>(scale, small_scale() ? 1 : 2);
        // Collision queries at the edges of the range test every pair exactly: fewer triangles.
        const BasicTriangleMesh<T> coarse = scaled_sphere<T>(scale, 0);
        triangle_bvh(mesh, scale, TriangleTest::Watertight);
        triangle_bvh(mesh, scale, TriangleTest::Fast);
        proximity(mesh, scale);
        collision_all(coarse, scale);
        dynamic_tree(mesh, scale);
    }
}

}  // namespace extreme_scale

TEST(ExtremeScaleRoundTrip, FloatLoadsWhatItBuilds) {
    extreme_scale::every_structure_every_scale<float>();
}

TEST(ExtremeScaleRoundTrip, DoubleLoadsWhatItBuilds) {
    extreme_scale::every_structure_every_scale<double>();
}
