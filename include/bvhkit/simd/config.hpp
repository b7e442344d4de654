#pragma once
// What the SIMD layer compiles: the four-lane types wherever SSE2 is (every x86-64), the eight-lane
// types where a function target attribute can ask for AVX2 (GCC and Clang on x86-64).
#if defined(__SSE2__)
#include <immintrin.h>
#define BVHKIT_SIMD 1
#else
#define BVHKIT_SIMD 0
#endif

#if BVHKIT_SIMD && defined(__x86_64__) && defined(__GNUC__)
#define BVHKIT_SIMD_AVX2 1
#else
#define BVHKIT_SIMD_AVX2 0
#endif

// The attributes of the layer's functions: always inlined, and for eight lanes AVX2's target.
#define BVHKIT_SIMD_INLINE [[gnu::always_inline]] inline
#define BVHKIT_SIMD_INLINE_AVX2 [[gnu::target("avx2"), gnu::always_inline]] inline

namespace bvhkit::simd {

template <int W>
struct Float;
template <int W>
struct Int;
template <int W>
struct Mask;

#if BVHKIT_SIMD
/// Asks for the cache line at `p` (a hint: `p` need not be valid).
BVHKIT_SIMD_INLINE void prefetch(const void* p) {
    _mm_prefetch(static_cast<const char*>(p), _MM_HINT_T0);
}
#endif

}  // namespace bvhkit::simd
