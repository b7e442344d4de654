// collide under a pose decides on B's corners carried exactly (R x + t as real numbers), never on a
// rounding of them: near-touching pairs whose decision flips when B's corners are rounded to float
// (or to double) match an exact integer reference that applies the pose exactly
// (posed_reference.hpp), on meshes scaled by 10^k across each type's range and far from the
// origin. Rotations read from float data are accepted by double models.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bvhkit/query/distance.hpp"
#include "bvhkit/volumes/aabb_volume.hpp"
#include "bvhkit/volumes/obb.hpp"
#include "bvhkit/volumes/rss.hpp"
#include "posed_reference.hpp"
#include "test_support.hpp"

namespace bvhkit::test {
namespace {

template <class T>
struct NearTouching {
    std::vector<Triangle<T>> a, b;  // b in its own frame
    Transform<T> pose;
};

/// A random rotation rounded to T (within T's rounding of orthonormal).
template <class T>
Mat3<T> random_rotation(std::mt19937_64& rng) {
    std::normal_distribution<double> g;
    double q[4], n = 0;
    for (double& x : q) {
        x = g(rng);
        n += x * x;
    }
    n = std::sqrt(n);
    const Mat3<double> r = rotation_from_quaternion(q[0] / n, q[1] / n, q[2] / n, q[3] / n);
    return Mat3<T>(r);
}

/// `count` pairs of triangles of size ~s about `origin`, spaced 8 s apart along x, each pair
/// touching at one point before B's corners are rounded into B's frame: a corner of B on A's face
/// (B otherwise above A's plane), or an edge of B piercing A's plane at a point of A's edge (B's
/// cut running outward). Rounding R^T (q - t) to T moves B's corners by an ulp, so whether each
/// pair meets is decided by where R x + t lands exactly, below the resolution of T.
template <class T, class Rotation = T>
NearTouching<T> near_touching(std::size_t count, double s, double origin, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1), w(0.1, 0.9);
    NearTouching<T> out;
    out.pose.rotation = Mat3<T>(random_rotation<Rotation>(rng));
    for (int k = 0; k < 3; ++k) out.pose.translation[k] = T(origin * (1 + 0.1 * u(rng)));
    const Mat3<double> r(out.pose.rotation);
    const Vec<double, 3> t(out.pose.translation);
    const auto in_b = [&](const Vec<double, 3>& q) {
        return Vec<T, 3>(r.transpose_times(q - t));  // rounded: the pair's decision is now open
    };
    for (std::size_t i = 0; i < count; ++i) {
        const Vec<double, 3> c{origin + 8 * s * double(i), origin, origin};
        Triangle<T> a;
        Vec<double, 3> p[3];
        for (auto& x : p) x = c + Vec<double, 3>{u(rng), u(rng), u(rng)} * s;
        a = {Vec<T, 3>(p[0]), Vec<T, 3>(p[1]), Vec<T, 3>(p[2])};
        // Directions from the corners at unit size (their squares stay in range at any scale).
        const Vec<double, 3> a0(a.p0), a1(a.p1), a2(a.p2);
        Vec<double, 3> n = cross((a1 - a0) * (1 / s), (a2 - a0) * (1 / s));
        n = n * (1 / length(n));
        Vec<double, 3> q[3];
        if (i % 2 == 0) {  // a corner of B on A's face, B above
            const double x = w(rng), y = (1 - x) * w(rng);
            q[0] = a0 + (a1 - a0) * x + (a2 - a0) * y;
            q[1] = q[0] + (n * (0.5 + 0.5 * w(rng)) + Vec<double, 3>{u(rng), u(rng), u(rng)}) * s;
            q[2] = q[0] + (n * (0.5 + 0.5 * w(rng)) + Vec<double, 3>{u(rng), u(rng), u(rng)}) * s;
        } else {  // B's edge pierces A's plane on A's edge; B's cut runs outward
            const Vec<double, 3> e = (a1 - a0) * (1 / s), m = a0 + (a1 - a0) * w(rng);
            Vec<double, 3> out_dir = cross(e, n);
            if (dot(out_dir, a2 - a0) > 0) out_dir = -out_dir;
            out_dir = out_dir * (1 / length(out_dir));
            const Vec<double, 3> slant = (e * (u(rng) / length(e)) + out_dir * u(rng)) * 0.5;
            q[0] = m + (n + slant) * s;
            q[1] = m - (n + slant) * s;
            q[2] = m + (out_dir * 2 + n * u(rng)) * s;
        }
        out.a.push_back(a);
        out.b.push_back({in_b(q[0]), in_b(q[1]), in_b(q[2])});
        EXPECT_TRUE(out.b.back().bounds().is_finite()) << s << " " << i;
    }
    return out;
}

template <class T>
BasicTriangleMesh<T> mesh_of(const std::vector<Triangle<T>>& tris) {
    BasicTriangleMesh<T> m;
    for (const auto& t : tris) {
        const auto k = std::uint32_t(m.vertices.size());
        m.vertices.insert(m.vertices.end(), {t.p0, t.p1, t.p2});
        m.triangles.push_back({k, k + 1, k + 2});
    }
    return m;
}

template <class V>
PairSet collide_pairs(const CollisionModel<V>& a, const CollisionModel<V>& b,
                      const Transform<typename V::Scalar>& pose, bool segments) {
    CollideResult<typename V::Scalar> r;
    CollideOptions o;
    o.segments = segments;
    collide(a, b, pose, o, r);
    PairSet got;
    for (const auto& c : r.contacts) got.insert({c.triangle_a, c.triangle_b});
    EXPECT_EQ(got.size(), r.contacts.size());
    return got;
}

/// Scales 10^k for k in [lo, hi] by `step`, at the origin and `far` sizes away from it: every
/// pair set equals the exact reference's. Returns how many pairs the reference says meet and how
/// many pairs B's corners rounded to T would decide otherwise (the cases this test is about).
template <class T>
void check_scales(int lo, int hi, int step, double far, std::size_t& meeting,
                  std::size_t& flipped) {
    const std::size_t count = scaled(48, 6);
    std::uint64_t seed = 38;
    for (int k = lo; k <= hi; k += step)
        for (const double away : {0.0, far}) {
            const double s = std::pow(10.0, k);
            const auto c = near_touching<T>(count, s, away * s, ++seed);
            const PairSet want = exact_posed_pairs(c.a, c.b, c.pose);
            meeting += want.size();
            for (std::size_t i = 0; i < count; ++i)
                flipped += triangles_intersect(c.a[i], transformed(c.b[i], c.pose)) !=
                           (want.count({std::uint32_t(i), std::uint32_t(i)}) != 0);
            const auto ma = mesh_of(c.a), mb = mesh_of(c.b);
            const CollisionModel<Aabb<T, 3>> aa(ma), ab(mb);
            const CollisionModel<Obb<T>> oa(ma), ob(mb);
            ASSERT_EQ(collide_pairs(aa, ab, c.pose, true), want) << "10^" << k << " at " << away;
            ASSERT_EQ(collide_pairs(oa, ob, c.pose, false), want) << "10^" << k << " at " << away;
            ASSERT_EQ(collides(oa, ob, c.pose), !want.empty()) << "10^" << k << " at " << away;
            // B's corners carried and rounded, at the identity pose: the exact decision on the
            // coordinates themselves (no rounding bound).
            std::vector<Triangle<T>> carried;
            for (const auto& t : c.b) carried.push_back(transformed(t, c.pose));
            const Transform<T> identity;
            const PairSet here = exact_posed_pairs(c.a, carried, identity);
            const CollisionModel<Obb<T>> oc(mesh_of(carried));
            ASSERT_EQ(collide_pairs(oa, oc, identity, true), here) << "10^" << k << " at " << away;
        }
}

TEST(PosedExact, FloatNearTouchingPairsMatchTheExactPoseAcrossScales) {
    std::size_t meeting = 0, flipped = 0;
    check_scales<float>(-30, 30, 6, 1e3, meeting, flipped);
    // Both answers occur, and rounding B's corners to float decides some pairs wrongly.
    EXPECT_GT(meeting, 0u);
    EXPECT_GT(flipped, 0u);
}

TEST(PosedExact, DoubleNearTouchingPairsMatchTheExactPoseAcrossScales) {
    std::size_t meeting = 0, flipped = 0;
    // Sizes 1e-300 to 1e300 (coordinates to ~1e306): products of differences underflow and
    // overflow double at the ends; Aabb and Obb trees find every contact across it.
    check_scales<double>(-300, 300, 30, 1e6, meeting, flipped);
    // Where products of three differences are subnormal: the filters' bounds sink below their
    // rounding there.
    check_scales<double>(-110, -100, 2, 1e6, meeting, flipped);
    EXPECT_GT(meeting, 0u);
    EXPECT_GT(flipped, 0u);
}

/// The three levels of PosedTriangles give the exact answer pair by pair, segments included:
/// each contact's segment lies within rounding of a's box (widened by 1% of the size s).
template <class T>
void check_levels(std::size_t count, double s, double origin, std::uint64_t seed) {
    const auto c = near_touching<T>(count, s, origin, seed);
    const PosedTriangles<T> posed(c.pose, T(2 * (std::fabs(origin) + 8 * s * double(count))));
    EXPECT_GT(posed.transform_error(), 0.0);
    for (std::size_t i = 0; i < c.a.size(); ++i) {
        const bool want = exact_posed_meet(c.a[i], c.b[i], c.pose);
        ASSERT_EQ(posed.intersects(c.a[i], c.b[i]), want) << i << " at " << s;
        const auto x = posed.intersect(c.a[i], c.b[i]);
        ASSERT_EQ(x.hit, want) << i << " at " << s;
        if (!want) continue;
        Aabb<T, 3> box = c.a[i].bounds();
        box.min = box.min - Vec<T, 3>(T(0.01 * s));
        box.max = box.max + Vec<T, 3>(T(0.01 * s));
        EXPECT_TRUE(box.contains(x.p) && box.contains(x.q)) << i << " at " << s;
    }
}

TEST(PosedExact, ExactPoseLevelsAgreeOnSingleTriangles) {
    check_levels<float>(scaled(200, 10), 1.0, 1e4, 7);
    // Double at the ends of its range, where the double level runs on the pair scaled by a power
    // of two and the segments are constructed on scaled corners.
    for (const double s : {1e-300, 1e-105, 1.0, 1e300})
        for (const double away : {0.0, 1e6}) check_levels<double>(scaled(100, 10), s, away * s, 8);
}

TEST(PosedExact, IdentityAndSignedPermutationsAreExactInDouble) {
    Transform<float> pose;
    EXPECT_EQ(PosedTriangles<float>::transform_error(pose, 10.0f), 0.0);
    pose.rotation.row[0] = {0, -1, 0};
    pose.rotation.row[1] = {1, 0, 0};
    EXPECT_EQ(PosedTriangles<float>::transform_error(pose, 10.0f), 0.0);
    pose.translation = {0, 0, 0.5f};
    EXPECT_GT(PosedTriangles<float>::transform_error(pose, 10.0f), 0.0);
}

TEST(PosedExact, DoubleModelsAcceptRotationsReadFromFloatData) {
    // A rotation rounded to float is ~6e-8 from orthonormal: a double model takes it as given and
    // decides exactly for it; a scale of 1e-3 is still refused.
    const auto c = near_touching<double, float>(scaled(24, 4), 1.0, 10.0, 11);
    const Transform<double> pose = c.pose;
    const auto ma = mesh_of(c.a), mb = mesh_of(c.b);
    const CollisionModel<Obb<double>> a(ma), b(mb);
    const PairSet want = exact_posed_pairs(c.a, c.b, pose);
    EXPECT_FALSE(want.empty());
    EXPECT_EQ(collide_pairs(a, b, pose, true), want);
    EXPECT_NO_THROW((void)distance(a, b, pose));
    Transform<double> scaled_pose = pose;
    for (auto& row : scaled_pose.rotation.row) row = row * 1.001;  // det R = 1.003
    EXPECT_THROW((void)collides(a, b, scaled_pose), Error);
}

}  // namespace
}  // namespace bvhkit::test
