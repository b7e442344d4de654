#pragma once
// Morton codes (Morton 1966; their use for BVHs: Lauterbach et al. 2009): each centroid quantized
// in the box of all centroids, the bits of its coordinates interleaved, so that sorting by code
// puts primitives that are close in space close in the order. Used by LBVH (lbvh.hpp) and by the
// bottom-up builder (bottom_up.hpp) for its initial order.
//
// 64-bit codes: 21 bits per axis in 3D, 31 in 2D. Ties (equal codes) are broken by primitive
// index, so the order is a total order and the same with any number of threads.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "bvhkit/exec/executor.hpp"
#include "bvhkit/math/aabb.hpp"

namespace bvhkit {

/// Spreads the low 21 bits of x so that two zero bits follow each (3D interleave).
inline std::uint64_t morton_spread3(std::uint64_t x) {
    x &= 0x1FFFFFu;
    x = (x | x << 32) & 0x1F00000000FFFFull;
    x = (x | x << 16) & 0x1F0000FF0000FFull;
    x = (x | x << 8) & 0x100F00F00F00F00Full;
    x = (x | x << 4) & 0x10C30C30C30C30C3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
}

/// Spreads the low 31 bits of x so that one zero bit follows each (2D interleave).
inline std::uint64_t morton_spread2(std::uint64_t x) {
    x &= 0x7FFFFFFFu;
    x = (x | x << 16) & 0x0000FFFF0000FFFFull;
    x = (x | x << 8) & 0x00FF00FF00FF00FFull;
    x = (x | x << 4) & 0x0F0F0F0F0F0F0F0Full;
    x = (x | x << 2) & 0x3333333333333333ull;
    x = (x | x << 1) & 0x5555555555555555ull;
    return x;
}

template <class T, std::size_t N>
std::uint64_t morton_code(const Vec<T, N>& c, const Aabb<T, N>& bounds) {
    constexpr unsigned bits = N == 3 ? 21 : 31;
    constexpr double cells = double(1u << bits);
    std::uint64_t q[N];
    for (std::size_t a = 0; a < N; ++a) {
        const double extent = double(bounds.max[a]) - double(bounds.min[a]);
        const double t = extent > 0 ? (double(c[a]) - double(bounds.min[a])) / extent : 0.0;
        // Clamped with comparisons that send NaN (an infinite extent) to 0, before converting.
        const double x = t * cells;
        q[a] = x > 0.0 ? static_cast<std::uint64_t>(x < cells - 1.0 ? x : cells - 1.0) : 0u;
    }
    if constexpr (N == 3) {
        return morton_spread3(q[0]) << 2 | morton_spread3(q[1]) << 1 | morton_spread3(q[2]);
    } else {
        return morton_spread2(q[0]) << 1 | morton_spread2(q[1]);
    }
}

/// A primitive with its code; ordered by code, then index.
struct MortonItem {
    std::uint64_t code;
    std::uint32_t index;
    friend bool operator<(const MortonItem& a, const MortonItem& b) {
        return a.code != b.code ? a.code < b.code : a.index < b.index;
    }
};

/// The primitives `indices` sorted by the Morton codes of their centroids.
template <class T, std::size_t N>
std::vector<MortonItem> morton_order(std::span<const Vec<T, N>> centroids,
                                     std::span<const std::uint32_t> indices, const Executor& exec) {
    Aabb<T, N> bounds;
    for (std::uint32_t i : indices) bounds.grow(centroids[i]);
    std::vector<MortonItem> items(indices.size());
    exec.parallel_for(indices.size(), 4096, [&](std::size_t b, std::size_t e) {
        for (std::size_t k = b; k < e; ++k)
            items[k] = {morton_code(centroids[indices[k]], bounds), indices[k]};
    });
    // The order is total (no equal items), so a parallel sort gives the serial result.
    exec.sort_total(items.begin(), items.end(), std::less<>());
    return items;
}

}  // namespace bvhkit
