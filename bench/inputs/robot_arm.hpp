#pragma once
// The robot of workload S1 (docs/workloads.md): a chain of six capsule links with joints
// alternating about z and y, and a gripper of three boxes on the last link, posed by forward
// kinematics from six joint angles. The meshes are closed and have no degenerate triangles (one
// vertex at each pole), so every library measures the same surfaces. A benchmark input shared by
// the bvhkit and FCL sides of scene_bench.cpp and the tests; not part of the library.
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "bvhkit/math/random.hpp"
#include "bvhkit/math/transform.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit::bench {

struct ArmShape {
    static constexpr std::size_t links = 6;
    static constexpr std::size_t bodies = links + 1;  // the links, then the gripper
    double link_length = 0.3;                         // joint to joint
    double radius = 0.04;                             // capsule radius
    std::uint32_t around = 24;                        // capsule segments round
    std::uint32_t rings = 10;  // rings per hemisphere, pole excluded (96 * rings triangles)
    double base_height = 0.05;
    /// Largest |angle| of the y joints: a real arm's limits keep a link from folding flat onto
    /// the one before it.
    double y_limit = 2.6;
};

/// A closed capsule along z, centred on the origin, whose tips lie at +-(length / 2): two
/// hemispheres of `rings` rings each plus a pole vertex, joined by the cylinder between equators.
inline BasicTriangleMesh<double> make_capsule(double radius, double length, std::uint32_t around,
                                              std::uint32_t rings) {
    BasicTriangleMesh<double> m;
    const double half = length / 2 - radius;  // the cylinder's half length
    m.vertices.push_back({0, 0, half + radius});
    // Rows from the top pole's first ring down to the top equator, then the bottom equator down.
    for (int side = 0; side < 2; ++side)
        for (std::uint32_t r = 1; r <= rings; ++r) {
            const std::uint32_t k = side == 0 ? r : rings + 1 - r;
            const double polar = 0.5 * std::numbers::pi * double(k) / double(rings);
            const double z = (side == 0 ? 1 : -1) * (half + radius * std::cos(polar));
            const double rr = radius * std::sin(polar);
            for (std::uint32_t j = 0; j < around; ++j) {
                const double a = 2 * std::numbers::pi * double(j) / double(around);
                m.vertices.push_back({rr * std::cos(a), rr * std::sin(a), z});
            }
        }
    m.vertices.push_back({0, 0, -(half + radius)});
    const std::uint32_t rows = 2 * rings, bottom = std::uint32_t(m.vertices.size() - 1);
    const auto at = [&](std::uint32_t row, std::uint32_t j) {
        return 1 + row * around + j % around;
    };
    for (std::uint32_t j = 0; j < around; ++j) {
        m.triangles.push_back({0, at(0, j), at(0, j + 1)});
        m.triangles.push_back({bottom, at(rows - 1, j + 1), at(rows - 1, j)});
    }
    for (std::uint32_t row = 0; row + 1 < rows; ++row)
        for (std::uint32_t j = 0; j < around; ++j) {
            m.triangles.push_back({at(row, j), at(row + 1, j), at(row + 1, j + 1)});
            m.triangles.push_back({at(row, j), at(row + 1, j + 1), at(row, j + 1)});
        }
    return m;
}

/// Appends the 12 triangles of the box [lo, hi].
inline void add_box(BasicTriangleMesh<double>& m, const Vec<double, 3>& lo,
                    const Vec<double, 3>& hi) {
    const auto base = std::uint32_t(m.vertices.size());
    for (std::uint32_t c = 0; c < 8; ++c)
        m.vertices.push_back({c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]});
    // Each face as two triangles, wound outward.
    static constexpr std::uint32_t faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                                  {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (const auto& f : faces) {
        m.triangles.push_back({base + f[0], base + f[2], base + f[1]});
        m.triangles.push_back({base + f[0], base + f[3], base + f[2]});
    }
}

/// The gripper in its own frame (origin at the last link's tip, z along the link): a palm and two
/// fingers. The palm starts at the tip, so it touches the last link (an adjacent pair).
inline BasicTriangleMesh<double> make_gripper() {
    BasicTriangleMesh<double> m;
    add_box(m, {-0.08, -0.025, 0.0}, {0.08, 0.025, 0.03});
    add_box(m, {-0.08, -0.015, 0.03}, {-0.06, 0.015, 0.12});
    add_box(m, {0.06, -0.015, 0.03}, {0.08, 0.015, 0.12});
    return m;
}

/// The world poses of the six links (their capsules' centres) and of the gripper for one set of
/// joint angles: link k turns by q[k] about z (k even) or y (k odd) of the frame before it.
inline std::array<Transform<double>, ArmShape::bodies> arm_poses(
    const ArmShape& shape, const std::array<double, ArmShape::links>& q) {
    std::array<Transform<double>, ArmShape::bodies> poses;
    Mat3<double> r;
    Vec<double, 3> joint{0, 0, shape.base_height};
    for (std::size_t k = 0; k < ArmShape::links; ++k) {
        const double c = std::cos(q[k]), s = std::sin(q[k]);
        Mat3<double> turn;
        if (k % 2 == 0)
            turn.row[0] = {c, -s, 0}, turn.row[1] = {s, c, 0};
        else
            turn.row[0] = {c, 0, s}, turn.row[2] = {-s, 0, c};
        r = r * turn;
        const Vec<double, 3> axis = r.column(2);
        poses[k] = {r, joint + axis * (shape.link_length / 2)};
        joint = joint + axis * shape.link_length;
    }
    poses[ArmShape::links] = {r, joint};
    return poses;
}

/// `count` joint-angle sets, deterministic for a seed: z joints uniform in [-pi, pi], y joints in
/// [-y_limit, y_limit].
inline std::vector<std::array<double, ArmShape::links>> random_configurations(const ArmShape& shape,
                                                                              std::size_t count,
                                                                              std::uint64_t seed) {
    SplitMix64 rng(seed);
    std::vector<std::array<double, ArmShape::links>> q(count);
    for (auto& c : q)
        for (std::size_t k = 0; k < ArmShape::links; ++k)
            c[k] = k % 2 == 0 ? rng.uniform(-std::numbers::pi, std::numbers::pi)
                              : rng.uniform(-shape.y_limit, shape.y_limit);
    return q;
}

}  // namespace bvhkit::bench
