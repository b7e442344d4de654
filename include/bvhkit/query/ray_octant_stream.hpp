#pragma once
// Rays of one direction octant walking the eight-wide layout together: occlusion batches, and
// the packets of coherent rays (camera rays, shadow rays towards one light) for closest hits.
//
// Up to 32 rays whose directions share their signs go down the tree as one walk: each stack entry
// carries a 32-bit mask of the rays still to visit it. At a node every such ray is clipped against
// the node's eight boxes (the near and far planes are the same rows for the whole octant), and the
// hit lanes are gathered into one register of per-child ray masks, a ray's bit or-ed into the
// lanes it hits, so the walk pushes each hit child once, with the rays that hit it. At a leaf each
// of its rays tests the leaf's groups: for occlusion a ray that hits is done and leaves every
// mask; for a closest hit its tmax shrinks, and later clips and pops drop it where it can no
// longer reach. The node's boxes, the push and the pop are paid once for all of its rays rather
// than once per ray (the ray-stream traversal of Tsakok 2009 and Fuetterling et al. 2015, with
// incoherent rays sorted by octant as Embree's stream calls do; for coherent rays, the packets
// of Wald et al. 2001).
//
// Each ray's clip is the eight-wide walk's arithmetic (clip_axis), lane for lane, and its leaf
// tests are the walk's: a ray reaches a leaf here whenever the one-ray walk, not stopping early,
// would, so the any-hit answer is the one-ray call's; the closest hit is too, by the tie rule of
// closer_hit (query/ray_wide.hpp). Design in docs/rays.md ("Octant streams and packets"),
// figures in docs/benchmarks.md.
#include <cstddef>
#include <cstdint>
#include <limits>

#include "bvhkit/query/ray_constants8.hpp"
#include "bvhkit/query/ray_wide.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

#if BVHKIT_RAY_AVX2
namespace detail {

/// Rays an octant stream holds: one bit each in a 32-bit mask, so at most 32 (tuning.hpp).
inline constexpr int octant_stream_size = tuning::octant_stream_size;
static_assert(octant_stream_size >= 1 && octant_stream_size <= 32);

/// Whether octant streams serve an occlusion batch on `tree` better than the interleaved walks of
/// query/ray_stream.hpp: below tuning::octant_streams_below_layout_bytes. Above it a node's rays
/// are few and the walk waits for memory, which the interleaving hides better.
inline bool octant_streams_pay(WideRayView<8> tree) {
    return tree.bytes() < tuning::octant_streams_below_layout_bytes;
}

/// The rays of one octant, their slab constants one array per component, and their answers.
struct OctantStream {
    alignas(32) float origin[3][octant_stream_size];
    alignas(32) float inv[3][octant_stream_size];
    alignas(32) float inv_far[3][octant_stream_size];
    alignas(32) float tmin[octant_stream_size];
    // A closest hit's shrinks as it hits; whole blocks of eight for rays_reaching.
    alignas(32) float tmax[(octant_stream_size + 7) / 8 * 8];
    WatertightRay<float> prep[octant_stream_size];
    std::size_t index[octant_stream_size];  // the ray's place in the batch
    // A closest hit's answer: the hit, and where its triangle lies (hit_group null on none).
    TriangleHit<float> best[octant_stream_size];
    const TriangleGroup8* hit_group[octant_stream_size];
    int hit_lane[octant_stream_size];
    int count = 0;

    /// Adds lane r of `c` (a ray the walk takes), ray i of the batch: the same constants.
    void add(const EightRayConstants& c, int r, std::size_t i) {
        const int at = count++;
        for (int a = 0; a < 3; ++a) {
            origin[a][at] = c.origin[a][r];
            inv[a][at] = c.inv[a][r];
            inv_far[a][at] = c.inv_far[a][r];
        }
        tmin[at] = c.tmin[r];
        tmax[at] = c.tmax[r];
        prep[at] = c.watertight(r);
        index[at] = i;
        hit_group[at] = nullptr;
        hit_lane[at] = 0;
    }
};

/// The rays of `mask` (of the stream's) whose range still reaches t: tmax[r] >= t. Reads tmax
/// in blocks of eight up to the count's: the walk sets the last block's unused slots.
[[gnu::target("avx2")]] inline std::uint32_t rays_reaching(const OctantStream& s, float t,
                                                           std::uint32_t mask) {
    using F = simd::Float<8>;
    std::uint32_t reach = 0;
    for (int q = 0; q < (s.count + 7) / 8; ++q)
        reach |= (F(t) <= F::load(s.tmax + 8 * q)).bits() << (8 * q);
    return mask & reach;
}

/// Walks the stream's rays (all of octant `octant`) through `tree`, for the first hit of each
/// (AnyHit) or its closest hit; calls done(r, found) once for each ray r of the stream (for a
/// closest hit, the hit is in s.best, s.hit_group and s.hit_lane).
///
/// The closest hit visits a node's hit children in one order for all of its rays: by the least
/// entry distance any of its rays has into the child (the packet order of Wald et al. 2001, with
/// the interval's near end standing for the packet). Each ray still clips every box with its own
/// tmax, and a popped entry keeps only the rays whose tmax reaches that least entry distance. So
/// a ray tests every leaf the one-ray walk would test at or before its closest t, perhaps in
/// another order; closer_hit (query/ray_wide.hpp) makes the answer the same in any order.
template <bool AnyHit, class Done>
[[gnu::target("avx2")]] void walk_octant_stream(WideRayView<8> tree, OctantStream& s, int octant,
                                                Done&& done) {
    struct Entry {
        std::uint32_t child, groups, rays;  // groups > 0: a leaf; rays: the mask of its rays
        float t;                            // closest hit: the least entry distance of its rays
    };
    const RayNode<8>* nodes = tree.nodes.data();
    const TriangleGroup8* groups = tree.groups.data();
    std::uint32_t near[3], far[3];  // SlabConstants' rows, the same for every ray of the octant
    for (int a = 0; a < 3; ++a) {
        const bool negative = (octant >> a) & 1;
        near[a] = std::uint32_t(a + (negative ? 3 : 0));
        far[a] = std::uint32_t(a + (negative ? 0 : 3));
    }
    const std::uint32_t all = s.count == 32 ? ~0u : (1u << s.count) - 1;
    for (int r = s.count; r % 8 != 0; ++r) s.tmax[r] = 0.0f;  // read by rays_reaching, unused
    std::uint32_t live = all;                                 // any hit: rays not yet blocked
    Entry stack[(8 - 1) * max_bvh_depth + 1];
    std::uint32_t size = 0;
    Entry current{0, 0, all, 0.0f};
    while (true) {
        if (current.groups == 0) {
            const RayNode<8>& node = nodes[current.child];
            using F = simd::Float<8>;
            using I = simd::Int<8>;
            F near_planes[3], far_planes[3];
            for (int a = 0; a < 3; ++a) {
                near_planes[a] = F::load(node.lo[near[a]]);
                far_planes[a] = F::load(node.lo[far[a]]);
            }
            // Lane c: the rays that hit child c, and the least entry distance into it.
            I rays_of = I::zero();
            F entry(std::numeric_limits<float>::infinity());
            for (std::uint32_t m = current.rays; m; m &= m - 1) {
                const int r = __builtin_ctz(m);
                F t0(s.tmin[r]), t1(s.tmax[r]);
                for (int a = 0; a < 3; ++a)  // the walk's clip, for this ray
                    avx2::clip_axis<8>(near_planes[a], far_planes[a], F(s.origin[a][r]),
                                       F(s.inv[a][r]), F(s.inv_far[a][r]), t0, t1);
                rays_of = rays_of | (simd::bits_of(t0 <= t1) & I(int(1u << r)));
                // Missed lanes count too: the least stays below every hitting ray's entry.
                if constexpr (!AnyHit) entry = min(t0, entry);
            }
            unsigned children = (rays_of == I::zero()).bits() ^ 0xFFu;
            if (children != 0) {
                alignas(32) std::uint32_t mask[8];
                alignas(32) float t[8];
                rays_of.store(mask);
                entry.store(t);
                int order[8], n = 0;
                for (; children; children &= children - 1) {
                    // Nearest first (insertion by t; equal ones keep lane order).
                    const int c = __builtin_ctz(children);
                    int j = n++;
                    if constexpr (!AnyHit)
                        for (; j > 0 && t[order[j - 1]] > t[c]; --j) order[j] = order[j - 1];
                    order[j] = c;
                }
                // The nearest goes on, the others wait, the farthest deepest (occlusion: in lane
                // order, the layout's order for occlusion rays).
                const int first = order[0];
                current = Entry{node.child[first], node.groups[first], mask[first], t[first]};
                // The next entry's first three lines, as the walk asks for them, so that they
                // arrive while the stream finishes this node.
                ask_for_next(WideEntry{current.child, current.groups, 0},
                             [&](const WideEntry& e) { return entry_address(nodes, groups, e); });
                for (int j = n - 1; j > 0; --j) {
                    const int c = order[j];
                    const Entry e{node.child[c], node.groups[c], mask[c], t[c]};
                    stack[size++] = e;
                    simd::prefetch(entry_address(nodes, groups, WideEntry{e.child, e.groups, 0}));
                }
                continue;
            }
        } else {
            for (std::uint32_t m = current.rays; m; m &= m - 1) {
                const int r = __builtin_ctz(m);
                const avx2::WatertightRayLanes<8> lanes(s.prep[r]);
                if constexpr (AnyHit) {
                    // AnyLeaves' tests, for this ray.
                    bool found = false;
                    const auto record = [&](int, const TriangleHit<float>& h) {
                        found = true;
                        return h.t;
                    };
                    for (std::uint32_t g = current.child;
                         g < current.child + current.groups && !found; ++g) {
                        float tmax = s.tmax[r];
                        avx2::intersect_watertight(lanes, groups[g], s.tmin[r], tmax, record);
                    }
                    if (found) live &= ~(1u << r);
                } else {
                    // ClosestLeaves' tests, for this ray.
                    for (std::uint32_t g = current.child; g < current.child + current.groups; ++g) {
                        const auto record = [&](int lane, const TriangleHit<float>& h) {
                            if (s.hit_group[r] != nullptr &&
                                !closer_hit(h.t, groups[g].slot[lane], s.best[r].t,
                                            s.hit_group[r]->slot[s.hit_lane[r]]))
                                return s.best[r].t;
                            s.best[r] = h;
                            s.hit_group[r] = groups + g;
                            s.hit_lane[r] = lane;
                            return h.t;
                        };
                        avx2::intersect_watertight(lanes, groups[g], s.tmin[r], s.tmax[r], record);
                    }
                }
            }
            if (AnyHit && live == 0) break;
        }
        // The next entry that still has rays to walk it.
        do {
            if (size == 0) goto done;
            current = stack[--size];
            current.rays = AnyHit ? current.rays & live : rays_reaching(s, current.t, current.rays);
        } while (current.rays == 0);
    }
done:
    for (int r = 0; r < s.count; ++r)
        done(r, AnyHit ? ((live >> r) & 1) == 0 : s.hit_group[r] != nullptr);
}

/// Sorts a batch's rays into one stream per octant, walks a stream whenever it fills, and the
/// part-full ones at the end, for any hits (AnyHit) or closest hits. done(stream, r, found) gets
/// the answer of each stream's ray r (its batch index is stream.index[r]). About 30 KB: kept on
/// the calling thread's stack for one batch.
template <bool AnyHit>
class OctantStreams {
  public:
    /// Adds the rays of `c` that the walk takes (c.walk), lane r ray first + r of the batch; walks
    /// each stream that fills.
    template <class Done>
    void add_eight(WideRayView<8> tree, const EightRayConstants& c, std::size_t first,
                   Done&& done) {
        for (unsigned m = c.walk; m; m &= m - 1) {
            const int r = __builtin_ctz(m);
            const int octant = c.octant(r);
            OctantStream& s = streams_[octant];
            s.add(c, r, first + std::size_t(r));
            if (s.count == octant_stream_size) walk(tree, s, octant, done);
        }
    }
    /// Walks the rays still waiting.
    template <class Done>
    void finish(WideRayView<8> tree, Done&& done) {
        for (int octant = 0; octant < 8; ++octant)
            if (streams_[octant].count > 0) walk(tree, streams_[octant], octant, done);
    }

  private:
    template <class Done>
    static void walk(WideRayView<8> tree, OctantStream& s, int octant, Done& done) {
        walk_octant_stream<AnyHit>(tree, s, octant, [&](int r, bool found) { done(s, r, found); });
        s.count = 0;
    }

    OctantStream streams_[8];
};

}  // namespace detail
#endif

}  // namespace bvhkit
