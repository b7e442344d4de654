#pragma once
// Sibling pairs in SIMD registers. The two children of a node are adjacent 32-byte nodes (one cache
// line), and every traversal tests both, so for 3D float boxes on x86 the pair's 12 plane
// coordinates are gathered into three four-lane registers (simd::Float<4>), one per axis, lanes
// (L.min, L.max, R.min, R.max): four loads and seven shuffles. The ray test
// (query/ray_pair_test.hpp) and the point distance below start from it. Elsewhere the same answers
// come from the scalar code.
#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/simd/simd.hpp"

namespace bvhkit {

#if BVHKIT_SIMD
struct PairPlanes {
    simd::Float<4> axis[3];  // per axis: (L.min, L.max, R.min, R.max)
};

[[gnu::always_inline]] inline PairPlanes gather_pair_planes(const BvhNode<Aabb3f>* pair) {
    using F = simd::Float<4>;
    // Node layout in floats: min xyz (0-2), max xyz (3-5), first, count; the right node at 8-15.
    const float* p = reinterpret_cast<const float*>(pair);
    const F a = F::load_unaligned(p), b = F::load_unaligned(p + 4);
    const F c = F::load_unaligned(p + 8), d = F::load_unaligned(p + 12);
    PairPlanes out;
    out.axis[0] = simd::shuffle<0, 3, 0, 3>(a, c);
    out.axis[1] =
        simd::shuffle<0, 2, 0, 2>(simd::shuffle<1, 1, 0, 0>(a, b), simd::shuffle<1, 1, 0, 0>(c, d));
    out.axis[2] =
        simd::shuffle<0, 2, 0, 2>(simd::shuffle<2, 2, 1, 1>(a, b), simd::shuffle<2, 2, 1, 1>(c, d));
    return out;
}
#endif

/// Squared distances from p to both boxes of a sibling pair (0 inside), as Aabb::distance_squared.
template <class T, std::size_t N>
inline void pair_distances_squared(const BvhNode<Aabb<T, N>>* pair, const Vec<T, N>& p, T out[2]) {
#if BVHKIT_SIMD
    if constexpr (std::is_same_v<T, float> && N == 3) {
        using F = simd::Float<4>;
        // Per axis: (min - p, p - max) for each box, the larger of the two clamped at 0, squared.
        const PairPlanes planes = gather_pair_planes(pair);
        const F sign = F::lanes(1.0f, -1.0f, 1.0f, -1.0f);
        F sum = F::zero();
        for (int a = 0; a < 3; ++a) {
            const F g = (planes.axis[a] - F(p[a])) * sign;
            const F gap = max(max(g, g.shuffle<1, 0, 3, 2>()), F::zero());
            sum = sum + gap * gap;
        }
        out[0] = sum.first();
        out[1] = sum.shuffle<2, 2, 2, 2>().first();
        return;
    }
#endif
    out[0] = pair[0].bounds.distance_squared(p);
    out[1] = pair[1].bounds.distance_squared(p);
}

}  // namespace bvhkit
