#pragma once
// Sibling pairs in SIMD registers. The two children of a node are adjacent 32-byte nodes (one cache
// line), and every traversal tests both, so for 3D float boxes on x86 the pair's 12 plane
// coordinates are gathered into three SSE registers, one per axis, lanes (L.min, L.max, R.min,
// R.max): four loads and seven shuffles. The ray test (query/ray_pair_test.hpp) and the point
// distance below start from it. Elsewhere the same answers come from the scalar code.
#include "bvhkit/bvh/bvh.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace bvhkit {

#if defined(__SSE2__)
struct PairPlanes {
    __m128 axis[3];  // per axis: (L.min, L.max, R.min, R.max)
};

[[gnu::always_inline]] inline PairPlanes gather_pair_planes(const BvhNode<Aabb3f>* pair) {
    // Node layout in floats: min xyz (0-2), max xyz (3-5), first, count; the right node at 8-15.
    const float* p = reinterpret_cast<const float*>(pair);
    const __m128 a = _mm_loadu_ps(p), b = _mm_loadu_ps(p + 4);
    const __m128 c = _mm_loadu_ps(p + 8), d = _mm_loadu_ps(p + 12);
    PairPlanes out;
    out.axis[0] = _mm_shuffle_ps(a, c, _MM_SHUFFLE(3, 0, 3, 0));
    out.axis[1] =
        _mm_shuffle_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(0, 0, 1, 1)),
                       _mm_shuffle_ps(c, d, _MM_SHUFFLE(0, 0, 1, 1)), _MM_SHUFFLE(2, 0, 2, 0));
    out.axis[2] =
        _mm_shuffle_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(1, 1, 2, 2)),
                       _mm_shuffle_ps(c, d, _MM_SHUFFLE(1, 1, 2, 2)), _MM_SHUFFLE(2, 0, 2, 0));
    return out;
}
#endif

/// Squared distances from p to both boxes of a sibling pair (0 inside), as Aabb::distance_squared.
template <class T, std::size_t N>
inline void pair_distances_squared(const BvhNode<Aabb<T, N>>* pair, const Vec<T, N>& p, T out[2]) {
#if defined(__SSE2__)
    if constexpr (std::is_same_v<T, float> && N == 3) {
        // Per axis: (min - p, p - max) for each box, the larger of the two clamped at 0, squared.
        const PairPlanes planes = gather_pair_planes(pair);
        const __m128 sign = _mm_setr_ps(1.0f, -1.0f, 1.0f, -1.0f);
        __m128 sum = _mm_setzero_ps();
        for (int a = 0; a < 3; ++a) {
            const __m128 g = _mm_mul_ps(_mm_sub_ps(planes.axis[a], _mm_set1_ps(p[a])), sign);
            const __m128 gap = _mm_max_ps(
                _mm_max_ps(g, _mm_shuffle_ps(g, g, _MM_SHUFFLE(2, 3, 0, 1))), _mm_setzero_ps());
            sum = _mm_add_ps(sum, _mm_mul_ps(gap, gap));
        }
        out[0] = _mm_cvtss_f32(sum);
        out[1] = _mm_cvtss_f32(_mm_shuffle_ps(sum, sum, _MM_SHUFFLE(2, 2, 2, 2)));
        return;
    }
#endif
    out[0] = pair[0].bounds.distance_squared(p);
    out[1] = pair[1].bounds.distance_squared(p);
}

}  // namespace bvhkit
