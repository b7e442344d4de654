#pragma once
// The ray sets of workload R (docs/workloads.md), deterministic so every library and every
// run traces the same rays. A benchmark input, not part of the library: bench/, tools/ and the
// tests link it as bvhkit_workload_inputs (bench/CMakeLists.txt).
#include <cstdint>
#include <vector>

#include "bvhkit/math/ray.hpp"

namespace bvhkit {

/// R1: a pinhole camera framing `bounds`: 60 degree vertical field of view, looking at the box
/// centre from the direction (0.5, 0.35, 1), far enough that the bounding sphere fits the view; y
/// is up. One ray per pixel centre, row by row from the top. Directions are unit length.
std::vector<Ray3f> camera_rays(const Aabb3f& bounds, std::uint32_t width, std::uint32_t height);

/// R2: origins uniform in `bounds`, directions uniform on the unit sphere, tmin 0, tmax inf.
std::vector<Ray3f> random_rays(const Aabb3f& bounds, std::size_t count, std::uint64_t seed = 1);

}  // namespace bvhkit
