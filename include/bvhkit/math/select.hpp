#pragma once
// min_of / max_of: std::min and std::max of two scalars, with the same answers (also for NaN and
// signed zeros), as one SSE instruction for float and double (simd/scalar.hpp). GCC sometimes
// compiles std::min and std::max of floats to a compare and a jump, which costs a misprediction
// whenever the larger operand is unpredictable, which the geometric tests that clamp and compare on
// every call (volumes/rss.hpp) pay on most calls.
#include <algorithm>
#include <cstdint>
#include <type_traits>

#include "bvhkit/simd/scalar.hpp"
#include "bvhkit/simd/sse2.hpp"

namespace bvhkit {

/// std::min(a, b), that is b < a ? b : a.
template <class T>
inline T min_of(T a, T b) {
#if BVHKIT_SIMD
    if constexpr (std::is_same_v<T, float> || std::is_same_v<T, double>)
        return simd::min_scalar(b, a);
#endif
    return std::min(a, b);
}

/// std::max(a, b), that is a < b ? b : a.
template <class T>
inline T max_of(T a, T b) {
#if BVHKIT_SIMD
    if constexpr (std::is_same_v<T, float> || std::is_same_v<T, double>)
        return simd::max_scalar(b, a);
#endif
    return std::max(a, b);
}

/// A bit per lane i of v[0..3] (16-byte aligned) whose value is x: one SSE compare, for the
/// four-wide nodes and packs that mark their empty lanes with a sentinel.
[[gnu::always_inline]] inline unsigned lanes_equal(const std::uint32_t v[4], std::uint32_t x) {
#if BVHKIT_SIMD
    return (simd::Int<4>::load(v) == simd::Int<4>(std::int32_t(x))).bits();
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
