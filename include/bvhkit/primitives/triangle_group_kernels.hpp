// No include guard: compiled once per instruction set by simd/per_isa.hpp, from
// primitives/triangle_group.hpp, which includes what this file uses.
//
// The watertight test of a ray against the W triangles of a TriangleGroup<W>, W = 4 or 8, lane by
// lane the same float operations as the scalar test's shear (no FMA: neither target enables it, so
// nothing is contracted), and the surviving lanes finished by watertight_finish in lane order with
// tmax shrinking as they hit: testing lanes 0-3 and then 4-7 four abreast gives the answers of
// testing all eight at once.

namespace bvhkit::detail::BVHKIT_SIMD_ISA {

/// The ray's constants of the watertight test, in every lane.
template <int W>
struct WatertightRayLanes {
    const WatertightRay<float>& ray;
    simd::Float<W> ox, oy, oz, sx, sy;

    explicit WatertightRayLanes(const WatertightRay<float>& r)
        : ray(r), ox(r.ox), oy(r.oy), oz(r.oz), sx(r.sx), sy(r.sy) {}
};

/// Tests the ray against the group's triangles; for each hit with t in [tmin, tmax] calls
/// on_hit(lane, hit), which returns the new tmax (the caller's closest so far, or anything to go
/// on). The lanes are finished in increasing order with tmax shrinking as they hit.
template <int W, class OnHit>
[[gnu::always_inline]] inline void intersect_watertight(const WatertightRayLanes<W>& r,
                                                        const TriangleGroup<W>& g, float tmin,
                                                        float& tmax, OnHit&& on_hit) {
    using F = simd::Float<W>;
    const WatertightRay<float>& s = r.ray;
    F x[3], y[3], z[3];
    // Indices in size_t: row + axis cannot wrap, so the compiler folds the row into the address
    // (with uint32_t it computed and shifted each of the nine indices on every pass).
    const std::size_t kx = s.kx, ky = s.ky, kz = s.kz;
#pragma GCC unroll 3
    for (std::size_t k = 0; k < 3; ++k) {
        const std::size_t row = 3 * k;
        z[k] = F::load(g.corner[row + kz]) - r.oz;
        x[k] = (F::load(g.corner[row + kx]) - r.ox) - r.sx * z[k];
        y[k] = (F::load(g.corner[row + ky]) - r.oy) - r.sy * z[k];
    }
    // The edge functions eu = cx by - cy bx, ev = ax cy - ay cx, ew = bx ay - by ax in float: a
    // lane with one strictly below zero and one strictly above misses (an exact sign). Written
    // out: over a table of operands the compiler kept x and y in memory.
    const F zero = F::zero();
    simd::Mask<W> negative = simd::Mask<W>::none(), positive = negative;
    const auto edge = [&](F x0, F y1, F y0, F x1) {
        const F f = x0 * y1 - y0 * x1;
        negative = negative | (f < zero);
        positive = positive | (f > zero);
    };
    edge(x[2], y[1], y[2], x[1]);
    edge(x[0], y[2], y[0], x[2]);
    edge(x[1], y[0], y[1], x[0]);
    const simd::Mask<W> pad = simd::Int<W>::load(g.slot) == simd::Int<W>(-1);
    unsigned live = ~((negative & positive) | pad).bits() & ((1u << W) - 1);
    if (live == 0) return;
    alignas(4 * W) float v[9][W];
    for (int k = 0; k < 3; ++k) {
        x[k].store(v[3 * k]);
        y[k].store(v[3 * k + 1]);
        z[k].store(v[3 * k + 2]);
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

}  // namespace bvhkit::detail::BVHKIT_SIMD_ISA
