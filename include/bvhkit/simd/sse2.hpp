#pragma once
// Four lanes in SSE2 registers: Float<4>, Int<4> (32-bit lanes) and Mask<4> (all ones or zero
// per lane, as the compares make them). See simd/simd.hpp.
#include <cstdint>

#include "bvhkit/simd/config.hpp"

#if BVHKIT_SIMD
namespace bvhkit::simd {

template <>
struct Mask<4> {
    __m128 r;
    /// No lane set.
    BVHKIT_SIMD_INLINE static Mask none() { return {_mm_setzero_ps()}; }
    /// Every lane set where `b`, none where not.
    BVHKIT_SIMD_INLINE static Mask all(bool b) {
        return {_mm_castsi128_ps(_mm_set1_epi32(-std::int32_t(b)))};
    }
    /// Lane i set where its argument is.
    BVHKIT_SIMD_INLINE static Mask lanes(bool a, bool b, bool c, bool d) {
        return {_mm_castsi128_ps(_mm_setr_epi32(-std::int32_t(a), -std::int32_t(b),
                                                -std::int32_t(c), -std::int32_t(d)))};
    }
    /// One bit per lane, lane 0 lowest.
    BVHKIT_SIMD_INLINE unsigned bits() const { return unsigned(_mm_movemask_ps(r)); }
};

template <>
struct Float<4> {
    __m128 r;
    Float() = default;
    BVHKIT_SIMD_INLINE explicit Float(__m128 v) : r(v) {}
    /// `x` in every lane.
    BVHKIT_SIMD_INLINE explicit Float(float x) : r(_mm_set1_ps(x)) {}
    BVHKIT_SIMD_INLINE static Float lanes(float a, float b, float c, float d) {
        return Float(_mm_setr_ps(a, b, c, d));
    }
    BVHKIT_SIMD_INLINE static Float zero() { return Float(_mm_setzero_ps()); }
    /// From 16-byte aligned memory.
    BVHKIT_SIMD_INLINE static Float load(const float* p) { return Float(_mm_load_ps(p)); }
    BVHKIT_SIMD_INLINE static Float load_unaligned(const float* p) {
        return Float(_mm_loadu_ps(p));
    }
    /// (p[0], p[1], p[2], 0), reading those 12 bytes only: an 8-byte load and a 4-byte one
    /// (movlps, movss), which a store of the three floats just before forwards to without a stall.
    BVHKIT_SIMD_INLINE static Float load3(const float* p) {
        // __m64 may alias anything.
        const __m128 xy = _mm_loadl_pi(_mm_setzero_ps(), reinterpret_cast<const __m64*>(p));
        return Float(_mm_movelh_ps(xy, _mm_load_ss(p + 2)));
    }
    BVHKIT_SIMD_INLINE void store(float* p) const { _mm_store_ps(p, r); }
    BVHKIT_SIMD_INLINE void store_unaligned(float* p) const { _mm_storeu_ps(p, r); }
    BVHKIT_SIMD_INLINE float first() const { return _mm_cvtss_f32(r); }
    /// Lanes (I0, I1, I2, I3) of this one.
    template <int I0, int I1, int I2, int I3>
    BVHKIT_SIMD_INLINE Float shuffle() const {
        return Float(_mm_shuffle_ps(r, r, _MM_SHUFFLE(I3, I2, I1, I0)));
    }
    /// (lane 2, lane 3, lane 2, lane 3), by movhlps: the upper half brought down.
    BVHKIT_SIMD_INLINE Float high_half() const { return Float(_mm_movehl_ps(r, r)); }
};

template <>
struct Int<4> {
    __m128i r;
    Int() = default;
    BVHKIT_SIMD_INLINE explicit Int(__m128i v) : r(v) {}
    BVHKIT_SIMD_INLINE explicit Int(std::int32_t x) : r(_mm_set1_epi32(x)) {}
    BVHKIT_SIMD_INLINE static Int lanes(std::int32_t a, std::int32_t b, std::int32_t c,
                                        std::int32_t d) {
        return Int(_mm_setr_epi32(a, b, c, d));
    }
    BVHKIT_SIMD_INLINE static Int load(const std::uint32_t* p) {
        return Int(_mm_load_si128(reinterpret_cast<const __m128i*>(p)));
    }
    BVHKIT_SIMD_INLINE void store(std::uint32_t* p) const {
        _mm_store_si128(reinterpret_cast<__m128i*>(p), r);
    }
    /// Each lane shifted right by N, copying its sign bit.
    template <int N>
    BVHKIT_SIMD_INLINE Int shift_right_arithmetic() const {
        return Int(_mm_srai_epi32(r, N));
    }
};

// Float<4> arithmetic: lane by lane, the IEEE operations.
BVHKIT_SIMD_INLINE Float<4> operator+(Float<4> a, Float<4> b) {
    return Float<4>(_mm_add_ps(a.r, b.r));
}
BVHKIT_SIMD_INLINE Float<4> operator-(Float<4> a, Float<4> b) {
    return Float<4>(_mm_sub_ps(a.r, b.r));
}
BVHKIT_SIMD_INLINE Float<4> operator*(Float<4> a, Float<4> b) {
    return Float<4>(_mm_mul_ps(a.r, b.r));
}
BVHKIT_SIMD_INLINE Float<4> operator/(Float<4> a, Float<4> b) {
    return Float<4>(_mm_div_ps(a.r, b.r));
}
/// (a[0] + b[0], a[1], a[2], a[3]): addss, lane 0 only.
BVHKIT_SIMD_INLINE Float<4> add_first(Float<4> a, Float<4> b) {
    return Float<4>(_mm_add_ss(a.r, b.r));
}
/// minps: b where either is NaN.
BVHKIT_SIMD_INLINE Float<4> min(Float<4> a, Float<4> b) {
    return Float<4>(_mm_min_ps(a.r, b.r));
}
/// maxps: b where either is NaN.
BVHKIT_SIMD_INLINE Float<4> max(Float<4> a, Float<4> b) {
    return Float<4>(_mm_max_ps(a.r, b.r));
}
/// -a: the sign bit flipped.
BVHKIT_SIMD_INLINE Float<4> operator-(Float<4> a) {
    return Float<4>(_mm_xor_ps(a.r, _mm_set1_ps(-0.0f)));
}
/// (a[I0], a[I1], b[I2], b[I3]).
template <int I0, int I1, int I2, int I3>
BVHKIT_SIMD_INLINE Float<4> shuffle(Float<4> a, Float<4> b) {
    return Float<4>(_mm_shuffle_ps(a.r, b.r, _MM_SHUFFLE(I3, I2, I1, I0)));
}
/// |a|: the sign bit cleared.
BVHKIT_SIMD_INLINE Float<4> abs(Float<4> a) {
    return Float<4>(_mm_andnot_ps(_mm_set1_ps(-0.0f), a.r));
}
/// Lanes of `yes` where `m` is set, of `no` elsewhere (by and/andnot/or: SSE2 has no blend).
BVHKIT_SIMD_INLINE Float<4> select(Mask<4> m, Float<4> yes, Float<4> no) {
    return Float<4>(_mm_or_ps(_mm_and_ps(m.r, yes.r), _mm_andnot_ps(m.r, no.r)));
}

/// Lanes of `a` where `m` is set, +0 elsewhere (andps); and where `m` is not set (andnps).
BVHKIT_SIMD_INLINE Float<4> where(Mask<4> m, Float<4> a) {
    return Float<4>(_mm_and_ps(m.r, a.r));
}
BVHKIT_SIMD_INLINE Float<4> where_not(Mask<4> m, Float<4> a) {
    return Float<4>(_mm_andnot_ps(m.r, a.r));
}

// Compares: ordered, so false in a lane where either is NaN.
BVHKIT_SIMD_INLINE Mask<4> operator<=(Float<4> a, Float<4> b) {
    return {_mm_cmple_ps(a.r, b.r)};
}
BVHKIT_SIMD_INLINE Mask<4> operator<(Float<4> a, Float<4> b) {
    return {_mm_cmplt_ps(a.r, b.r)};
}
BVHKIT_SIMD_INLINE Mask<4> operator>(Float<4> a, Float<4> b) {
    return {_mm_cmpgt_ps(a.r, b.r)};
}
BVHKIT_SIMD_INLINE Mask<4> operator>=(Float<4> a, Float<4> b) {
    return {_mm_cmpge_ps(a.r, b.r)};
}
BVHKIT_SIMD_INLINE Mask<4> operator==(Float<4> a, Float<4> b) {
    return {_mm_cmpeq_ps(a.r, b.r)};
}

BVHKIT_SIMD_INLINE Mask<4> operator&(Mask<4> a, Mask<4> b) {
    return {_mm_and_ps(a.r, b.r)};
}
BVHKIT_SIMD_INLINE Mask<4> operator|(Mask<4> a, Mask<4> b) {
    return {_mm_or_ps(a.r, b.r)};
}

// Int<4>: 32-bit lanes.
BVHKIT_SIMD_INLINE Int<4> operator+(Int<4> a, Int<4> b) {
    return Int<4>(_mm_add_epi32(a.r, b.r));
}
BVHKIT_SIMD_INLINE Int<4> operator-(Int<4> a, Int<4> b) {
    return Int<4>(_mm_sub_epi32(a.r, b.r));
}
BVHKIT_SIMD_INLINE Int<4> operator&(Int<4> a, Int<4> b) {
    return Int<4>(_mm_and_si128(a.r, b.r));
}
BVHKIT_SIMD_INLINE Mask<4> operator==(Int<4> a, Int<4> b) {
    return {_mm_castsi128_ps(_mm_cmpeq_epi32(a.r, b.r))};
}

/// The bits of each lane, as integers; and back.
BVHKIT_SIMD_INLINE Int<4> bits_of(Float<4> a) {
    return Int<4>(_mm_castps_si128(a.r));
}
/// Each lane converted to an integer, rounding toward zero (cvttps2dq; out of range: INT_MIN).
BVHKIT_SIMD_INLINE Int<4> truncate(Float<4> a) {
    return Int<4>(_mm_cvttps_epi32(a.r));
}
/// A lane all ones where `a` has its sign bit.
BVHKIT_SIMD_INLINE Mask<4> sign_mask(Int<4> a) {
    return {_mm_castsi128_ps(_mm_srai_epi32(a.r, 31))};
}

}  // namespace bvhkit::simd
#endif
