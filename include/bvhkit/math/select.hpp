#pragma once
// min_of / max_of: std::min and std::max of two scalars, with the same answers (also for NaN and
// signed zeros), as one SSE instruction for float and double. GCC sometimes compiles std::min and
// std::max of floats to a compare and a jump, which costs a misprediction whenever the larger
// operand is unpredictable, which the geometric tests that clamp and compare on every call
// (volumes/rss.hpp) pay on most calls.
#include <algorithm>
#include <cstdint>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace bvhkit {

/// std::min(a, b), that is b < a ? b : a.
template <class T>
inline T min_of(T a, T b) {
#if defined(__SSE2__)
    // minss x, y gives x < y ? x : y.
    if constexpr (std::is_same_v<T, float>)
        return _mm_cvtss_f32(_mm_min_ss(_mm_set_ss(b), _mm_set_ss(a)));
    if constexpr (std::is_same_v<T, double>)
        return _mm_cvtsd_f64(_mm_min_sd(_mm_set_sd(b), _mm_set_sd(a)));
#endif
    return std::min(a, b);
}

/// std::max(a, b), that is a < b ? b : a.
template <class T>
inline T max_of(T a, T b) {
#if defined(__SSE2__)
    // maxss x, y gives x > y ? x : y.
    if constexpr (std::is_same_v<T, float>)
        return _mm_cvtss_f32(_mm_max_ss(_mm_set_ss(b), _mm_set_ss(a)));
    if constexpr (std::is_same_v<T, double>)
        return _mm_cvtsd_f64(_mm_max_sd(_mm_set_sd(b), _mm_set_sd(a)));
#endif
    return std::max(a, b);
}

/// A bit per lane i of v[0..3] (16-byte aligned) whose value is x: one SSE compare, for the
/// four-wide nodes and packs that mark their empty lanes with a sentinel.
[[gnu::always_inline]] inline unsigned lanes_equal(const std::uint32_t v[4], std::uint32_t x) {
#if defined(__SSE2__)
    const __m128i lanes = _mm_load_si128(reinterpret_cast<const __m128i*>(v));
    const __m128i equal = _mm_cmpeq_epi32(lanes, _mm_set1_epi32(int(x)));
    return unsigned(_mm_movemask_ps(_mm_castsi128_ps(equal)));
#else
    unsigned bits = 0;
    for (int i = 0; i < 4; ++i) bits |= unsigned(v[i] == x) << i;
    return bits;
#endif
}

/// x limited to [lo, hi] (lo <= hi), as min_of(max_of(x, lo), hi).
template <class T>
inline T clamp_of(T x, T lo, T hi) {
    return min_of(max_of(x, lo), hi);
}

}  // namespace bvhkit
