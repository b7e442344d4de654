#pragma once
// One-lane minimum and maximum in an SSE register (minss, maxss, minsd, maxsd): x < y ? x : y and
// x > y ? x : y, with y where either is NaN, as the instructions define them. GCC sometimes
// compiles a scalar std::min to a compare and a jump; these are one instruction whatever the
// operands (math/select.hpp).
#include "bvhkit/simd/config.hpp"

#if BVHKIT_SIMD
namespace bvhkit::simd {

BVHKIT_SIMD_INLINE float min_scalar(float x, float y) {
    return _mm_cvtss_f32(_mm_min_ss(_mm_set_ss(x), _mm_set_ss(y)));
}
BVHKIT_SIMD_INLINE double min_scalar(double x, double y) {
    return _mm_cvtsd_f64(_mm_min_sd(_mm_set_sd(x), _mm_set_sd(y)));
}
BVHKIT_SIMD_INLINE float max_scalar(float x, float y) {
    return _mm_cvtss_f32(_mm_max_ss(_mm_set_ss(x), _mm_set_ss(y)));
}
BVHKIT_SIMD_INLINE double max_scalar(double x, double y) {
    return _mm_cvtsd_f64(_mm_max_sd(_mm_set_sd(x), _mm_set_sd(y)));
}

}  // namespace bvhkit::simd
#endif
