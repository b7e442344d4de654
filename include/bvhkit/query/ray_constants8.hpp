#pragma once
// The constants the eight-wide walks need, made for eight rays at once: whether the wide walk takes
// a ray (wide_ray_usable), whether it meets the tree's bounds (SlabConstants::meets), its slab
// constants (SlabConstants) and its watertight test's (WatertightRay's KnownValid form). Why:
// most camera rays around a model miss its bounds and cost nothing but these constants, which one
// ray at a time take several times the instructions they take across eight lanes. Each lane runs
// the one-ray code's IEEE operations on the same operands (the quotients, the products, the
// compares, max and min with the same operand order), so every decision and every constant is the
// one-ray code's, bit for bit; the packet tests compare the answers to the one-ray calls'.
#include <cstddef>
#include <cstdint>
#include <limits>

#include "bvhkit/math/aabb.hpp"
#include "bvhkit/math/ray.hpp"
#include "bvhkit/primitives/triangle.hpp"
#include "bvhkit/query/ray_wide.hpp"

namespace bvhkit {

#if BVHKIT_RAY_AVX2
namespace detail {

/// Eight rays' constants, one array per component, lane r for ray r.
struct EightRayConstants {
    alignas(32) float origin[3][8];
    alignas(32) float inv[3][8];
    alignas(32) float inv_far[3][8];
    alignas(32) float tmin[8];
    alignas(32) float tmax[8];
    // WatertightRay's: the origin on its kx, ky, kz axes, the shears, and d[kz].
    alignas(32) float ox[8], oy[8], oz[8], sx[8], sy[8], dz[8];
    unsigned usable = 0;               // the rays wide_ray_usable accepts
    unsigned walk = 0;                 // those of them that meet the bounds: the walk takes them
    unsigned negative[3] = {0, 0, 0};  // per axis, the rays whose direction has the sign bit
    unsigned kz_is_0 = 0, kz_is_1 = 0, swapped = 0;  // WatertightRay's axes, lane by lane

    /// Ray r's direction octant: bit a set when component a has the sign bit (-0 included, as
    /// SlabConstants reads its planes).
    int octant(int r) const {
        return int((negative[0] >> r) & 1u) | int((negative[1] >> r) & 1u) << 1 |
               int((negative[2] >> r) & 1u) << 2;
    }
    /// Ray r's WatertightRay, as WatertightRay(ray, KnownValid) makes it.
    WatertightRay<float> watertight(int r) const {
        WatertightRay<float> w;
        w.kz = (kz_is_0 >> r) & 1u ? 0u : (kz_is_1 >> r) & 1u ? 1u : 2u;
        const std::uint32_t x0 = (w.kz + 1) % 3, y0 = (w.kz + 2) % 3;
        const bool swap = (swapped >> r) & 1u;
        w.kx = swap ? y0 : x0;
        w.ky = swap ? x0 : y0;
        w.ox = ox[r];
        w.oy = oy[r];
        w.oz = oz[r];
        w.sx = sx[r];
        w.sy = sy[r];
        w.dz = double(dz[r]);
        w.valid = true;
        return w;
    }
};

/// The constants of rays[0, count) (count 1 to 8) against a tree whose bounds are `bounds`: the
/// lanes from count on are the first ray again, and are in neither mask.
[[gnu::target("avx2")]] inline void make_eight_ray_constants(const Ray<float, 3>* rays, int count,
                                                             const Aabb<float, 3>& bounds,
                                                             EightRayConstants& c) {
    using F = simd::Float<8>;
    // The rays' fields one array each (a ray is eight floats: origin, direction, tmin, tmax).
    alignas(32) float field[8][8];
    for (int r = 0; r < 8; ++r) {
        const Ray<float, 3>& ray = rays[r < count ? r : 0];
        for (int a = 0; a < 3; ++a) {
            field[a][r] = ray.origin[a];
            field[3 + a][r] = ray.direction[a];
        }
        field[6][r] = ray.tmin;
        field[7][r] = ray.tmax;
    }
    const F inf(std::numeric_limits<float>::infinity());
    const F zero = F::zero();
    F o[3], d[3], ad[3];
    for (int a = 0; a < 3; ++a) {
        o[a] = F::load(field[a]);
        d[a] = F::load(field[3 + a]);
        ad[a] = abs(d[a]);
    }
    const F tmin = F::load(field[6]), tmax = F::load(field[7]);
    // wide_ray_usable: finite, no subnormal direction component, one not zero, tmin <= tmax.
    unsigned usable = (tmin <= tmax).bits(), moves = 0;
    for (int a = 0; a < 3; ++a) {
        usable &= ((abs(o[a]) < inf) & (ad[a] < inf)).bits();
        usable &= ((ad[a] == zero) | (ad[a] >= F(std::numeric_limits<float>::min()))).bits();
        moves |= (ad[a] > zero).bits();
    }
    const unsigned all = count == 8 ? 0xFFu : (1u << count) - 1;
    c.usable = usable & moves & all;
    // SlabConstants: 1 / d, and the reciprocal scaled for the far planes.
    constexpr float s = 1.0f + 2.0f * rounding_gamma<float>(3);
    F inv[3], inv_far[3];
    for (int a = 0; a < 3; ++a) {
        inv[a] = F(1.0f) / d[a];
        inv_far[a] = inv[a] * F(s);
        o[a].store(c.origin[a]);
        inv[a].store(c.inv[a]);
        inv_far[a].store(c.inv_far[a]);
        c.negative[a] = sign_bits(d[a]);
    }
    tmin.store(c.tmin);
    tmax.store(c.tmax);
    // SlabConstants::meets: inside the bounds at tmin = 0, or the slab test with the walks'
    // rounding, per axis max(near distance, tmin) and min(far distance, tmax) first as meets
    // does, so that a NaN distance (0 * inf) gives tmin or tmax as there; the three then reduce
    // alike in any order (only a zero's sign could differ, which <= does not see).
    using I = simd::Int<8>;
    unsigned inside = (tmin == zero).bits();
    F t0[3], t1[3];
    for (int a = 0; a < 3; ++a) {
        const F lo(bounds.min[a]), hi(bounds.max[a]);
        inside &= ((lo <= o[a]) & (o[a] <= hi)).bits();
        // A negative axis (its sign bit; 1 / d has d's) meets its max plane first.
        const simd::Mask<8> neg = bits_of(d[a]).shift_right_arithmetic<31>() == I(-1);
        t0[a] = max((select(neg, hi, lo) - o[a]) * inv[a], tmin);
        t1[a] = min((select(neg, lo, hi) - o[a]) * inv_far[a], tmax);
    }
    const unsigned slab = (max(t0[0], max(t0[1], t0[2])) <= min(t1[0], min(t1[1], t1[2]))).bits();
    c.walk = c.usable & (inside | slab);
    // WatertightRay: kz the axis of the largest |d| (the first of equal ones), kx and ky the next
    // two in turn, swapped when d[kz] < 0, and the shears d[kx] / d[kz], d[ky] / d[kz].
    const simd::Mask<8> ge01 = ad[0] >= ad[1], ge02 = ad[0] >= ad[2], ge12 = ad[1] >= ad[2];
    const simd::Mask<8> kz0 = ge01 & ge02, kz1 = andnot(ge01, ge12);
    // Per lane, v's component kz, (kz + 1) % 3 and (kz + 2) % 3.
    const F dz = select(kz0, d[0], select(kz1, d[1], d[2]));
    const F dx0 = select(kz0, d[1], select(kz1, d[2], d[0]));
    const F dy0 = select(kz0, d[2], select(kz1, d[0], d[1]));
    const F oz = select(kz0, o[0], select(kz1, o[1], o[2]));
    const F ox0 = select(kz0, o[1], select(kz1, o[2], o[0]));
    const F oy0 = select(kz0, o[2], select(kz1, o[0], o[1]));
    const simd::Mask<8> swap = dz < zero;
    (select(swap, dy0, dx0) / dz).store(c.sx);
    (select(swap, dx0, dy0) / dz).store(c.sy);
    select(swap, oy0, ox0).store(c.ox);
    select(swap, ox0, oy0).store(c.oy);
    oz.store(c.oz);
    dz.store(c.dz);
    c.kz_is_0 = kz0.bits();
    c.kz_is_1 = kz1.bits();
    c.swapped = swap.bits();
}

}  // namespace detail
#endif

}  // namespace bvhkit
