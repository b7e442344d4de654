#pragma once
// The ray's test against a sibling pair: both children's boxes at once, since the traversal always
// needs both and they share one cache line.
//
// For 3D float boxes on x86 the pair is tested in SSE2 registers. The 12 plane coordinates are
// gathered per axis as (L.min, L.max, R.min, R.max); one subtract and one multiply per axis give
// plane distances, with the per-ray multipliers already carrying the sign and the conservative
// scale of the far planes (so after a shuffle the lanes hold (L.near, R.near, -s L.far, -s R.far)).
// A single chain of maxps then yields both entries and both negated exits. maxps returns its second
// operand when either is NaN, and the accumulator (second operand) never is, so a 0 * inf plane
// distance is dropped exactly as the scalar test drops it (see math/ray.hpp). Elsewhere the scalar
// slab test runs twice.
//
// The pair test and its gather are marked always_inline: GCC's inlining budget is per translation
// unit, and in a large one (the bench's) it left the test out of line, which cost camera rays
// time; a user's own large file would pay the same. Forcing more (the leaf and triangle calls, the
// scalar clip) made the walk slower in small files, so only these are forced.
#include "bvhkit/bvh/sibling_pair.hpp"
#include "bvhkit/math/ray.hpp"
#include "bvhkit/simd/simd.hpp"

namespace bvhkit {

template <class T, std::size_t N>
class RayPairTest {
  public:
    /// For the ray `slab` was made from, whose octant is `Octant`.
    template <unsigned Octant>
    RayPairTest(const RaySlabData<T, N>& slab, std::integral_constant<unsigned, Octant>)
        : slab_(slab) {}

    /// The ray's [tmin, tmax] in the form test() takes; make it again when tmax changes.
    struct Interval {
        T tmin, tmax;
    };
    static Interval interval(T tmin, T tmax) { return {tmin, tmax}; }

    /// Bit 0: the ray meets pair[0] within the interval, entering at entry[0]; bit 1: pair[1].
    template <unsigned Octant>
    unsigned test(const BvhNode<Aabb<T, N>>* pair, const Interval& interval, T entry[2]) const {
        T t1 = interval.tmax, t3 = interval.tmax;
        entry[0] = entry[1] = interval.tmin;
        const bool l = slab_.template clip<Octant>(pair[0].bounds, entry[0], t1);
        const bool r = slab_.template clip<Octant>(pair[1].bounds, entry[1], t3);
        return unsigned(l) | unsigned(r) << 1;
    }

  private:
    RaySlabData<T, N> slab_;
};

#if BVHKIT_SIMD
template <>
class RayPairTest<float, 3> {
    using F = simd::Float<4>;

  public:
    /// For the ray `slab` was made from, whose octant is `Octant` (known at compile time, so
    /// the choice of near and far planes costs nothing per ray either).
    template <unsigned Octant>
    RayPairTest(const RaySlabData<float, 3>& slab, std::integral_constant<unsigned, Octant>) {
        constexpr float s = 1.0f + 2.0f * rounding_gamma<float>(3);
        for (int i = 0; i < 3; ++i) {
            origin_[i] = F(slab.origin[i]);
            const float inv = slab.inv_direction[i];
            // Lanes hold (L.min, L.max, R.min, R.max) planes; far planes get -s * inv.
            const bool negative = (Octant >> i) & 1u;
            const float on_min = negative ? -s * inv : inv, on_max = negative ? inv : -s * inv;
            scale_[i] = F::lanes(on_min, on_max, on_min, on_max);
        }
    }

    /// (tmin, tmin, -tmax, -tmax): the accumulator's start, never NaN; make it again when tmax
    /// changes.
    using Interval = simd::Float<4>;
    static Interval interval(float tmin, float tmax) {
        return simd::shuffle<0, 0, 0, 0>(F(tmin), F(-tmax));
    }

    template <unsigned Octant>
    [[gnu::always_inline]] unsigned test(const BvhNode<Aabb3f>* pair, Interval interval,
                                         float entry[2]) const {
        const PairPlanes planes = gather_pair_planes(pair);
        const F &x = planes.axis[0], &y = planes.axis[1], &z = planes.axis[2];
        F acc = interval;
        acc = max(near_far<(Octant >> 0) & 1u>((x - origin_[0]) * scale_[0]), acc);
        acc = max(near_far<(Octant >> 1) & 1u>((y - origin_[1]) * scale_[1]), acc);
        acc = max(near_far<(Octant >> 2) & 1u>((z - origin_[2]) * scale_[2]), acc);
        const F exits = -acc.shuffle<2, 3, 2, 3>();
        entry[0] = acc.first();
        entry[1] = acc.shuffle<1, 1, 1, 1>().first();
        return (acc <= exits).bits() & 3u;
    }

  private:
    // (L.min, L.max, R.min, R.max) distances -> (L.near, R.near, L.far', R.far').
    template <unsigned Negative>
    [[gnu::always_inline]] static F near_far(F t) {
        if constexpr (Negative)
            return t.shuffle<1, 3, 0, 2>();
        else
            return t.shuffle<0, 2, 1, 3>();
    }

    F origin_[3];
    F scale_[3];
};
#endif

}  // namespace bvhkit
