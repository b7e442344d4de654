#pragma once
// TriangleGroup4 and TriangleGroup8: four or eight float triangles side by side (each corner
// coordinate an array of four or eight), and the watertight ray test of Woop, Benthin and Wald
// 2013 run on all of them at once, in SSE or AVX registers.
//
// The test keeps the scalar test's answers (primitives/triangle.hpp). The corners are moved to the
// ray's origin and sheared with the same float operations as the scalar code. The edge
// functions are then formed in float, as a filter: rounding is monotonic, so fl(a b) - fl(c d) is
// never of the opposite sign to a b - c d (at worst it is zero; overflow to inf keeps the order
// too), and a lane whose float edge functions have strictly mixed signs has mixed exact signs,
// which the scalar test rejects. Every other lane, padding excluded, is finished in double by
// watertight_finish on the same sheared floats, so a hit, its t and barycentrics are the scalar
// test's.
#include <cstdint>

#include "bvhkit/primitives/triangle.hpp"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace bvhkit {

/// L triangles side by side: L = 4 for the SSE test, 8 for the AVX test.
template <int L>
struct alignas(4 * L) TriangleGroup {
    static constexpr int lanes = L;
    float corner[9][L];  // corner[3 * k + axis][lane]: corner k (p0, p1, p2) of the lane's triangle
    std::uint32_t slot[L];  // the lane's triangle (the caller's index); invalid_index pads

    /// Puts `tri` in `lane` as triangle `index`.
    void set(int lane, const Triangle<float>& tri, std::uint32_t index) {
        const Vec<float, 3>* p[3] = {&tri.p0, &tri.p1, &tri.p2};
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a) corner[3 * k + a][lane] = (*p[k])[a];
        slot[lane] = index;
    }
    /// The triangle in `lane`, as set.
    Triangle<float> triangle(int lane) const {
        Triangle<float> t;
        Vec<float, 3>* p[3] = {&t.p0, &t.p1, &t.p2};
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a) (*p[k])[a] = corner[3 * k + a][lane];
        return t;
    }
    /// An empty lane: never tested.
    void clear(int lane) {
        for (auto& c : corner) c[lane] = 0.0f;
        slot[lane] = invalid_index;
    }
};
using TriangleGroup4 = TriangleGroup<4>;
using TriangleGroup8 = TriangleGroup<8>;

#if defined(__SSE2__)
/// The ray's constants of the watertight test, as SSE registers.
struct WatertightRay4 {
    const WatertightRay<float>& ray;
    __m128 ox, oy, oz, sx, sy;

    explicit WatertightRay4(const WatertightRay<float>& r)
        : ray(r),
          ox(_mm_set1_ps(r.ox)),
          oy(_mm_set1_ps(r.oy)),
          oz(_mm_set1_ps(r.oz)),
          sx(_mm_set1_ps(r.sx)),
          sy(_mm_set1_ps(r.sy)) {}
};

namespace detail {
// Lanes whose float edge function x0 y1 - y0 x1 is below zero, and above: an exact sign.
[[gnu::always_inline]] inline void edge_signs(__m128 x0, __m128 y1, __m128 y0, __m128 x1,
                                              __m128& negative, __m128& positive) {
    const __m128 e = _mm_sub_ps(_mm_mul_ps(x0, y1), _mm_mul_ps(y0, x1));
    negative = _mm_or_ps(negative, _mm_cmplt_ps(e, _mm_setzero_ps()));
    positive = _mm_or_ps(positive, _mm_cmpgt_ps(e, _mm_setzero_ps()));
}
}  // namespace detail

/// Tests the ray against the group's triangles; for each hit with t in [tmin, tmax] calls
/// on_hit(lane, hit), which returns the new tmax (the caller's closest so far, or anything to go
/// on). The lanes are finished in order 0..3 with tmax shrinking as they hit.
template <class OnHit>
[[gnu::always_inline]] inline void intersect_watertight4(const WatertightRay4& r,
                                                         const TriangleGroup4& g, float tmin,
                                                         float& tmax, OnHit&& on_hit) {
    const WatertightRay<float>& s = r.ray;
    // Indices in size_t: 3 k + axis cannot wrap, so the compiler folds 3 k into the address.
    const auto corner = [&](std::size_t k, std::size_t axis) {
        return _mm_load_ps(g.corner[3 * k + axis]);
    };
    __m128 x[3], y[3], z[3];
    for (int k = 0; k < 3; ++k) {
        z[k] = _mm_sub_ps(corner(k, s.kz), r.oz);
        x[k] = _mm_sub_ps(_mm_sub_ps(corner(k, s.kx), r.ox), _mm_mul_ps(r.sx, z[k]));
        y[k] = _mm_sub_ps(_mm_sub_ps(corner(k, s.ky), r.oy), _mm_mul_ps(r.sy, z[k]));
    }
    __m128 negative = _mm_setzero_ps(), positive = _mm_setzero_ps();
    detail::edge_signs(x[2], y[1], y[2], x[1], negative, positive);  // eu = cx by - cy bx
    detail::edge_signs(x[0], y[2], y[0], x[2], negative, positive);  // ev = ax cy - ay cx
    detail::edge_signs(x[1], y[0], y[1], x[0], negative, positive);  // ew = bx ay - by ax
    const __m128i pad = _mm_cmpeq_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(g.slot)),
                                        _mm_set1_epi32(-1));
    const unsigned rejected =
        unsigned(_mm_movemask_ps(_mm_or_ps(_mm_and_ps(negative, positive), _mm_castsi128_ps(pad))));
    if (rejected == 0xFu) return;
    alignas(16) float v[9][4];
    for (int k = 0; k < 3; ++k) {
        _mm_store_ps(v[3 * k], x[k]);
        _mm_store_ps(v[3 * k + 1], y[k]);
        _mm_store_ps(v[3 * k + 2], z[k]);
    }
    for (int lane = 0; lane < 4; ++lane) {
        if ((rejected >> lane) & 1u) continue;
        TriangleHit<float> h;
        const ShearedTriangle<float> sheared{v[0][lane], v[1][lane], v[2][lane],
                                             v[3][lane], v[4][lane], v[5][lane],
                                             v[6][lane], v[7][lane], v[8][lane]};
        if (watertight_finish(s, sheared, tmin, tmax, h)) tmax = on_hit(lane, h);
    }
}

#if defined(__x86_64__) && defined(__GNUC__)
/// intersect_watertight4 on eight triangles in AVX registers, for the eight-wide walk, which
/// carries the same target. Lane by lane the same float operations as the four-abreast test (no
/// FMA: the target does not enable it, so nothing is contracted), and the surviving lanes are
/// finished by watertight_finish in lane order with tmax shrinking as they hit: the same answers
/// as testing lanes 0-3 and then 4-7 four abreast.
template <class OnHit>
[[gnu::target("avx2"), gnu::always_inline]] inline void intersect_watertight8(
    const WatertightRay<float>& s, const TriangleGroup8& g, float tmin, float& tmax,
    OnHit&& on_hit) {
    const __m256 ox = _mm256_set1_ps(s.ox), oy = _mm256_set1_ps(s.oy), oz = _mm256_set1_ps(s.oz);
    const __m256 sx = _mm256_set1_ps(s.sx), sy = _mm256_set1_ps(s.sy);
    __m256 x[3], y[3], z[3];
    // Indices in size_t: row + axis cannot wrap, so the compiler folds the row into the address
    // (with uint32_t it computed and shifted each of the nine indices on every pass).
    const std::size_t kx = s.kx, ky = s.ky, kz = s.kz;
    for (std::size_t k = 0; k < 3; ++k) {
        const std::size_t row = 3 * k;
        z[k] = _mm256_sub_ps(_mm256_load_ps(g.corner[row + kz]), oz);
        x[k] = _mm256_sub_ps(_mm256_sub_ps(_mm256_load_ps(g.corner[row + kx]), ox),
                             _mm256_mul_ps(sx, z[k]));
        y[k] = _mm256_sub_ps(_mm256_sub_ps(_mm256_load_ps(g.corner[row + ky]), oy),
                             _mm256_mul_ps(sy, z[k]));
    }
    const __m256 zero = _mm256_setzero_ps();
    __m256 negative = zero, positive = zero;
    const int xi[3][4] = {
        {2, 1, 2, 1}, {0, 2, 0, 2}, {1, 0, 1, 0}};  // eu, ev, ew as in the SSE test
    for (const auto& e : xi) {
        const __m256 f =
            _mm256_sub_ps(_mm256_mul_ps(x[e[0]], y[e[1]]), _mm256_mul_ps(y[e[2]], x[e[3]]));
        negative = _mm256_or_ps(negative, _mm256_cmp_ps(f, zero, _CMP_LT_OQ));
        positive = _mm256_or_ps(positive, _mm256_cmp_ps(f, zero, _CMP_GT_OQ));
    }
    const __m256i pad = _mm256_cmpeq_epi32(
        _mm256_load_si256(reinterpret_cast<const __m256i*>(g.slot)), _mm256_set1_epi32(-1));
    unsigned live = ~unsigned(_mm256_movemask_ps(_mm256_or_ps(_mm256_and_ps(negative, positive),
                                                              _mm256_castsi256_ps(pad)))) &
                    0xFFu;
    if (live == 0) return;
    alignas(32) float v[9][8];
    for (int k = 0; k < 3; ++k) {
        _mm256_store_ps(v[3 * k], x[k]);
        _mm256_store_ps(v[3 * k + 1], y[k]);
        _mm256_store_ps(v[3 * k + 2], z[k]);
    }
    for (; live; live &= live - 1) {
        const int lane = __builtin_ctz(live);
        TriangleHit<float> h;
        const ShearedTriangle<float> sheared{v[0][lane], v[1][lane], v[2][lane],
                                             v[3][lane], v[4][lane], v[5][lane],
                                             v[6][lane], v[7][lane], v[8][lane]};
        if (watertight_finish(s, sheared, tmin, tmax, h)) tmax = on_hit(lane, h);
    }
}
#endif
#endif

}  // namespace bvhkit
