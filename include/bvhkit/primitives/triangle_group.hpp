#pragma once
// TriangleGroup4 and TriangleGroup8: four or eight float triangles side by side (each corner
// coordinate an array of four or eight), and the watertight ray test of Woop, Benthin and Wald
// 2013 run on all of them at once, in SSE or AVX registers (the kernel, written once for both
// widths, is in primitives/triangle_group_kernels.hpp).
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
#include "bvhkit/simd/simd.hpp"

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

}  // namespace bvhkit

// The test itself, once per instruction set (simd/per_isa.hpp): detail::sse2::intersect_watertight
// for four lanes, detail::avx2::intersect_watertight for eight.
#define BVHKIT_SIMD_KERNELS "bvhkit/primitives/triangle_group_kernels.hpp"
#include "bvhkit/simd/per_isa.hpp"  // IWYU pragma: keep
