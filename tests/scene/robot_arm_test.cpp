// The robot of workload S1 (bench/inputs/robot_arm.hpp): closed meshes of the stated shape, and
// forward kinematics against poses worked out by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <utility>

#include "robot_arm.hpp"

namespace bvhkit::bench {
namespace {

/// Every undirected edge is used by exactly two triangles, once in each direction (closed and
/// consistently wound), and no triangle repeats a vertex.
void expect_closed(const BasicTriangleMesh<double>& m) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (const auto& t : m.triangles) {
        ASSERT_TRUE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
        for (int e = 0; e < 3; ++e) ++directed[{t[e], t[(e + 1) % 3]}];
    }
    for (const auto& [edge, count] : directed) {
        EXPECT_EQ(count, 1);
        const auto back = directed.find({edge.second, edge.first});
        ASSERT_NE(back, directed.end());
        EXPECT_EQ(back->second, 1);
    }
}

/// Six times the signed volume (divergence theorem): positive when the triangles face outward.
double six_volume(const BasicTriangleMesh<double>& m) {
    double v = 0;
    for (const auto& t : m.triangles)
        v += dot(m.vertices[t[0]], cross(m.vertices[t[1]], m.vertices[t[2]]));
    return v;
}

TEST(RobotArm, CapsuleIsClosedAndOnItsSurface) {
    const ArmShape s;
    const auto m = make_capsule(s.radius, s.link_length, s.around, s.rings);
    EXPECT_EQ(m.triangles.size(), std::size_t(4 * s.around * s.rings));  // 960
    expect_closed(m);
    // Every vertex lies at `radius` from the axis segment between the hemispheres' centres.
    const double half = s.link_length / 2 - s.radius;
    double top = -1, bottom = 1;
    for (const auto& v : m.vertices) {
        const double z = std::clamp(v[2], -half, half);
        const double d = std::sqrt(v[0] * v[0] + v[1] * v[1] + (v[2] - z) * (v[2] - z));
        EXPECT_NEAR(d, s.radius, 1e-15);
        top = std::max(top, v[2]), bottom = std::min(bottom, v[2]);
    }
    EXPECT_NEAR(top, s.link_length / 2, 1e-15);
    EXPECT_NEAR(bottom, -s.link_length / 2, 1e-15);
    // Inscribed in the capsule: a little less than its volume, facing out.
    const double pi = std::numbers::pi, r = s.radius;
    const double capsule = pi * r * r * 2 * half + 4.0 / 3.0 * pi * r * r * r;
    const double volume = six_volume(m) / 6;
    EXPECT_LT(volume, capsule);
    EXPECT_GT(volume, 0.95 * capsule);
    std::printf("[ capsule ] volume %.6f of the round capsule's\n", volume / capsule);
}

TEST(RobotArm, GripperIsThreeClosedBoxes) {
    const auto g = make_gripper();
    EXPECT_EQ(g.triangles.size(), 36u);
    expect_closed(g);
    // Box volumes by hand: 0.16 x 0.05 x 0.03 and two of 0.02 x 0.03 x 0.09.
    EXPECT_NEAR(six_volume(g) / 6, 0.16 * 0.05 * 0.03 + 2 * 0.02 * 0.03 * 0.09, 1e-15);
}

void expect_pose(const Transform<double>& p, const Mat3<double>& r, const Vec<double, 3>& t) {
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_NEAR(p.translation[i], t[i], 1e-15) << "translation " << i;
        for (std::size_t j = 0; j < 3; ++j)
            EXPECT_NEAR(p.rotation[i][j], r[i][j], 1e-15) << "rotation " << i << j;
    }
}

TEST(RobotArm, ForwardKinematicsByHand) {
    const ArmShape s;
    const double L = s.link_length, h = s.base_height;
    // All joints at zero: a straight column up the z axis, the gripper on top.
    const auto up = arm_poses(s, {});
    for (std::size_t k = 0; k < ArmShape::links; ++k)
        expect_pose(up[k], Mat3<double>{}, {0, 0, h + L / 2 + double(k) * L});
    expect_pose(up[ArmShape::links], Mat3<double>{}, {0, 0, h + 6 * L});

    // Base turned a quarter about z, then the second joint a quarter about (the turned) y: the
    // links from the second on lie along the world y axis (Rz(90) Ry(90) takes z to y).
    const double q = std::numbers::pi / 2;
    const auto bent = arm_poses(s, {q, q, 0, 0, 0, 0});
    Mat3<double> rz;
    rz.row[0] = {0, -1, 0}, rz.row[1] = {1, 0, 0};
    Mat3<double> rzy;
    rzy.row[0] = {0, -1, 0}, rzy.row[1] = {0, 0, 1}, rzy.row[2] = {-1, 0, 0};
    expect_pose(bent[0], rz, {0, 0, h + L / 2});
    for (std::size_t k = 1; k < ArmShape::links; ++k)
        expect_pose(bent[k], rzy, {0, L / 2 + double(k - 1) * L, h + L});
    expect_pose(bent[ArmShape::links], rzy, {0, 5 * L, h + L});
}

TEST(RobotArm, ConfigurationsAreSeededAndWithinLimits) {
    const ArmShape s;
    const auto a = random_configurations(s, 500, 7), b = random_configurations(s, 500, 7);
    const auto c = random_configurations(s, 500, 8);
    EXPECT_EQ(a, b);
    EXPECT_NE(a, c);
    for (const auto& q : a)
        for (std::size_t k = 0; k < ArmShape::links; ++k)
            EXPECT_LE(std::fabs(q[k]), k % 2 == 0 ? std::numbers::pi : s.y_limit);
}

}  // namespace
}  // namespace bvhkit::bench
