#pragma once
// Eight lanes in AVX2 registers: Float<8>, Int<8> (32-bit lanes) and Mask<8>. Each function
// carries AVX2's target, so that it inlines into a kernel compiled for AVX2 (simd/per_isa.hpp) and
// only there. See simd/simd.hpp.
#include <cstdint>

#include "bvhkit/simd/config.hpp"

#if BVHKIT_SIMD_AVX2
namespace bvhkit::simd {

template <>
struct Mask<8> {
    __m256 r;
    /// No lane set.
    BVHKIT_SIMD_INLINE_AVX2 static Mask none() { return {_mm256_setzero_ps()}; }
    /// One bit per lane, lane 0 lowest.
    BVHKIT_SIMD_INLINE_AVX2 unsigned bits() const { return unsigned(_mm256_movemask_ps(r)); }
};

template <>
struct Float<8> {
    __m256 r;
    Float() = default;
    BVHKIT_SIMD_INLINE_AVX2 explicit Float(__m256 v) : r(v) {}
    /// `x` in every lane.
    BVHKIT_SIMD_INLINE_AVX2 explicit Float(float x) : r(_mm256_set1_ps(x)) {}
    BVHKIT_SIMD_INLINE_AVX2 static Float zero() { return Float(_mm256_setzero_ps()); }
    /// From 32-byte aligned memory.
    BVHKIT_SIMD_INLINE_AVX2 static Float load(const float* p) { return Float(_mm256_load_ps(p)); }
    BVHKIT_SIMD_INLINE_AVX2 static Float load_unaligned(const float* p) {
        return Float(_mm256_loadu_ps(p));
    }
    BVHKIT_SIMD_INLINE_AVX2 void store(float* p) const { _mm256_store_ps(p, r); }
    BVHKIT_SIMD_INLINE_AVX2 void store_unaligned(float* p) const { _mm256_storeu_ps(p, r); }
    BVHKIT_SIMD_INLINE_AVX2 float first() const { return _mm256_cvtss_f32(r); }
};

template <>
struct Int<8> {
    __m256i r;
    Int() = default;
    BVHKIT_SIMD_INLINE_AVX2 explicit Int(__m256i v) : r(v) {}
    BVHKIT_SIMD_INLINE_AVX2 explicit Int(std::int32_t x) : r(_mm256_set1_epi32(x)) {}
    BVHKIT_SIMD_INLINE_AVX2 static Int lanes(std::int32_t a, std::int32_t b, std::int32_t c,
                                             std::int32_t d, std::int32_t e, std::int32_t f,
                                             std::int32_t g, std::int32_t h) {
        return Int(_mm256_setr_epi32(a, b, c, d, e, f, g, h));
    }
    BVHKIT_SIMD_INLINE_AVX2 static Int zero() { return Int(_mm256_setzero_si256()); }
    /// From 32-byte aligned memory.
    BVHKIT_SIMD_INLINE_AVX2 static Int load(const std::uint32_t* p) {
        return Int(_mm256_load_si256(reinterpret_cast<const __m256i*>(p)));
    }
    BVHKIT_SIMD_INLINE_AVX2 void store(std::uint32_t* p) const {
        _mm256_store_si256(reinterpret_cast<__m256i*>(p), r);
    }
    BVHKIT_SIMD_INLINE_AVX2 void store_unaligned(std::uint32_t* p) const {
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), r);
    }
    BVHKIT_SIMD_INLINE_AVX2 std::int32_t first() const { return _mm256_cvtsi256_si32(r); }
    /// Each lane shifted right by N, copying its sign bit; and filling with zeros.
    template <int N>
    BVHKIT_SIMD_INLINE_AVX2 Int shift_right_arithmetic() const {
        return Int(_mm256_srai_epi32(r, N));
    }
    template <int N>
    BVHKIT_SIMD_INLINE_AVX2 Int shift_right_logical() const {
        return Int(_mm256_srli_epi32(r, N));
    }
    /// vpshufd: within each half, lane i takes lane (Imm >> 2 i) & 3 of that half.
    template <int Imm>
    BVHKIT_SIMD_INLINE_AVX2 Int shuffle_in_halves() const {
        return Int(_mm256_shuffle_epi32(r, Imm));
    }
    /// vpermq: 64-bit lane i takes 64-bit lane (Imm >> 2 i) & 3.
    template <int Imm>
    BVHKIT_SIMD_INLINE_AVX2 Int permute_pairs() const {
        return Int(_mm256_permute4x64_epi64(r, Imm));
    }
};

BVHKIT_SIMD_INLINE_AVX2 Float<8> operator+(Float<8> a, Float<8> b) {
    return Float<8>(_mm256_add_ps(a.r, b.r));
}
BVHKIT_SIMD_INLINE_AVX2 Float<8> operator-(Float<8> a, Float<8> b) {
    return Float<8>(_mm256_sub_ps(a.r, b.r));
}
BVHKIT_SIMD_INLINE_AVX2 Float<8> operator*(Float<8> a, Float<8> b) {
    return Float<8>(_mm256_mul_ps(a.r, b.r));
}
/// The IEEE quotient in every lane, as the scalar division and Float<4>'s give it.
BVHKIT_SIMD_INLINE_AVX2 Float<8> operator/(Float<8> a, Float<8> b) {
    return Float<8>(_mm256_div_ps(a.r, b.r));
}
/// |a|: the sign bit cleared.
BVHKIT_SIMD_INLINE_AVX2 Float<8> abs(Float<8> a) {
    return Float<8>(_mm256_andnot_ps(_mm256_set1_ps(-0.0f), a.r));
}
/// Lanes of `yes` where `m` is set, of `no` elsewhere.
BVHKIT_SIMD_INLINE_AVX2 Float<8> select(Mask<8> m, Float<8> yes, Float<8> no) {
    return Float<8>(_mm256_blendv_ps(no.r, yes.r, m.r));
}
/// The lanes' sign bits, lane 0 lowest (-0 and negative NaNs included).
BVHKIT_SIMD_INLINE_AVX2 unsigned sign_bits(Float<8> a) {
    return unsigned(_mm256_movemask_ps(a.r));
}
/// vminps: b where either is NaN.
BVHKIT_SIMD_INLINE_AVX2 Float<8> min(Float<8> a, Float<8> b) {
    return Float<8>(_mm256_min_ps(a.r, b.r));
}
/// vmaxps: b where either is NaN.
BVHKIT_SIMD_INLINE_AVX2 Float<8> max(Float<8> a, Float<8> b) {
    return Float<8>(_mm256_max_ps(a.r, b.r));
}
/// result[i] = a[index[i] & 7].
BVHKIT_SIMD_INLINE_AVX2 Float<8> permute(Float<8> a, Int<8> index) {
    return Float<8>(_mm256_permutevar8x32_ps(a.r, index.r));
}

// Compares: ordered and quiet, so false in a lane where either is NaN.
BVHKIT_SIMD_INLINE_AVX2 Mask<8> operator<=(Float<8> a, Float<8> b) {
    return {_mm256_cmp_ps(a.r, b.r, _CMP_LE_OQ)};
}
BVHKIT_SIMD_INLINE_AVX2 Mask<8> operator<(Float<8> a, Float<8> b) {
    return {_mm256_cmp_ps(a.r, b.r, _CMP_LT_OQ)};
}
BVHKIT_SIMD_INLINE_AVX2 Mask<8> operator>(Float<8> a, Float<8> b) {
    return {_mm256_cmp_ps(a.r, b.r, _CMP_GT_OQ)};
}
BVHKIT_SIMD_INLINE_AVX2 Mask<8> operator>=(Float<8> a, Float<8> b) {
    return {_mm256_cmp_ps(a.r, b.r, _CMP_GE_OQ)};
}
BVHKIT_SIMD_INLINE_AVX2 Mask<8> operator==(Float<8> a, Float<8> b) {
    return {_mm256_cmp_ps(a.r, b.r, _CMP_EQ_OQ)};
}

BVHKIT_SIMD_INLINE_AVX2 Mask<8> operator&(Mask<8> a, Mask<8> b) {
    return {_mm256_and_ps(a.r, b.r)};
}
BVHKIT_SIMD_INLINE_AVX2 Mask<8> operator|(Mask<8> a, Mask<8> b) {
    return {_mm256_or_ps(a.r, b.r)};
}
/// The lanes set in `b` and not in `a`.
BVHKIT_SIMD_INLINE_AVX2 Mask<8> andnot(Mask<8> a, Mask<8> b) {
    return {_mm256_andnot_ps(a.r, b.r)};
}

BVHKIT_SIMD_INLINE_AVX2 Int<8> operator&(Int<8> a, Int<8> b) {
    return Int<8>(_mm256_and_si256(a.r, b.r));
}
BVHKIT_SIMD_INLINE_AVX2 Int<8> operator|(Int<8> a, Int<8> b) {
    return Int<8>(_mm256_or_si256(a.r, b.r));
}
BVHKIT_SIMD_INLINE_AVX2 Int<8> operator^(Int<8> a, Int<8> b) {
    return Int<8>(_mm256_xor_si256(a.r, b.r));
}
/// ~a & b.
BVHKIT_SIMD_INLINE_AVX2 Int<8> andnot(Int<8> a, Int<8> b) {
    return Int<8>(_mm256_andnot_si256(a.r, b.r));
}
/// Each lane of `a` shifted right by its lane of `n`, filling with zeros.
BVHKIT_SIMD_INLINE_AVX2 Int<8> shift_right_logical(Int<8> a, Int<8> n) {
    return Int<8>(_mm256_srlv_epi32(a.r, n.r));
}
BVHKIT_SIMD_INLINE_AVX2 Int<8> min(Int<8> a, Int<8> b) {
    return Int<8>(_mm256_min_epi32(a.r, b.r));
}
BVHKIT_SIMD_INLINE_AVX2 Int<8> max(Int<8> a, Int<8> b) {
    return Int<8>(_mm256_max_epi32(a.r, b.r));
}
/// Lane i of `b` where bit i of Imm is set, of `a` elsewhere.
template <int Imm>
BVHKIT_SIMD_INLINE_AVX2 Int<8> blend(Int<8> a, Int<8> b) {
    return Int<8>(_mm256_blend_epi32(a.r, b.r, Imm));
}
/// Lanes of `yes` where `m` is set, of `no` elsewhere.
BVHKIT_SIMD_INLINE_AVX2 Int<8> select(Mask<8> m, Int<8> yes, Int<8> no) {
    return Int<8>(_mm256_blendv_epi8(no.r, yes.r, _mm256_castps_si256(m.r)));
}
/// result[i] = a[index[i] & 7].
BVHKIT_SIMD_INLINE_AVX2 Int<8> permute(Int<8> a, Int<8> index) {
    return Int<8>(_mm256_permutevar8x32_epi32(a.r, index.r));
}
BVHKIT_SIMD_INLINE_AVX2 Mask<8> operator==(Int<8> a, Int<8> b) {
    return {_mm256_castsi256_ps(_mm256_cmpeq_epi32(a.r, b.r))};
}

/// The bits of each lane, as integers; and a mask as integers.
BVHKIT_SIMD_INLINE_AVX2 Int<8> bits_of(Float<8> a) {
    return Int<8>(_mm256_castps_si256(a.r));
}
BVHKIT_SIMD_INLINE_AVX2 Int<8> bits_of(Mask<8> a) {
    return Int<8>(_mm256_castps_si256(a.r));
}

}  // namespace bvhkit::simd
#endif
