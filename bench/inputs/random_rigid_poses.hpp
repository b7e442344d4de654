#pragma once
// The random rigid poses of workload C1 (docs/workloads.md): a rotation uniform over SO(3)
// (a unit quaternion by Shoemake's method, "Uniform random rotations", 1992)
// about the centre c of the mesh's box, then an offset uniform in a cube of side one box diagonal
// centred on c. A pose maps x to R (x - c) + c + offset. Deterministic for a seed. A benchmark
// input, not part of the library: bench/, tools/ and the tests link it as bvhkit_workload_inputs.
#include <numbers>
#include <vector>

#include "bvhkit/math/aabb.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/math/transform.hpp"

namespace bvhkit {

template <class T>
std::vector<Transform<T>> random_rigid_poses(const Aabb<T, 3>& bounds, std::size_t count,
                                             std::uint64_t seed) {
    SplitMix64 rng(seed);
    const Vec3d lo(bounds.min), hi(bounds.max);
    const Vec3d c = (lo + hi) * 0.5;
    const double diagonal = length(hi - lo);
    std::vector<Transform<T>> poses;
    poses.reserve(count);
    for (std::size_t i = 0; i < count; ++i) {
        const double u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
        const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
        const double t1 = 2 * std::numbers::pi * u2, t2 = 2 * std::numbers::pi * u3;
        const Mat3<double> r = rotation_from_quaternion(b * std::cos(t2), a * std::sin(t1),
                                                        a * std::cos(t1), b * std::sin(t2));
        const Vec3d offset{rng.uniform(-0.5, 0.5) * diagonal, rng.uniform(-0.5, 0.5) * diagonal,
                           rng.uniform(-0.5, 0.5) * diagonal};
        const Vec3d t = c + offset - r * c;
        poses.push_back(Transform<T>(Transform<double>{r, t}));
    }
    return poses;
}

}  // namespace bvhkit
