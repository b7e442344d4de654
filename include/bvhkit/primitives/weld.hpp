#pragma once
// Welding by position: many files split a vertex where texture or normal seams run, so the
// triangles around it name different copies of one point. Queries that need the surface's
// connectivity (pseudonormals, closedness) give every copy one id.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace bvhkit {

/// A welded id per vertex of `mesh` (an IndexedTriangleMesh): vertices at exactly the same
/// position share one; ids run from 0 in the order of positions.
template <class M>
std::vector<std::uint32_t> weld_vertices(const M& mesh) {
    std::vector<std::uint32_t> by_position(mesh.vertex_count());
    for (std::uint32_t i = 0; i < by_position.size(); ++i) by_position[i] = i;
    // The key orders coordinates totally, NaN included (a NaN under operator< would make the
    // sort undefined): IEEE bits made monotonic, -0 as +0, every NaN as one value.
    const auto ordered = [](double x) {
        if (std::isnan(x)) return std::numeric_limits<std::uint64_t>::max();
        const auto b = std::bit_cast<std::uint64_t>(x == 0 ? 0.0 : x);
        return (b >> 63) ? ~b : b | (std::uint64_t(1) << 63);
    };
    const auto key = [&](std::uint32_t i) {
        const auto v = mesh.vertex(i);
        return std::array<std::uint64_t, 3>{ordered(double(v[0])), ordered(double(v[1])),
                                            ordered(double(v[2]))};
    };
    std::sort(by_position.begin(), by_position.end(),
              [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
    std::vector<std::uint32_t> weld(mesh.vertex_count());
    std::uint32_t ids = 0;
    for (std::size_t k = 0; k < by_position.size(); ++k) {
        if (k > 0 && key(by_position[k]) != key(by_position[k - 1])) ++ids;
        weld[by_position[k]] = ids;
    }
    return weld;
}

}  // namespace bvhkit
