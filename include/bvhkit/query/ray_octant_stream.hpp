#pragma once
// Occlusion rays of one direction octant walking the eight-wide layout together.
//
// Up to 32 rays whose directions share their signs go down the tree as one walk: each stack entry
// carries a 32-bit mask of the rays still to visit it. At a node every such ray is clipped against
// the node's eight boxes (the near and far planes are the same rows for the whole octant), and the
// hit lanes are gathered into one register of per-child ray masks, a ray's bit or-ed into the
// lanes it hits, so the walk pushes each hit child once, with the rays that hit it. At a leaf each
// of its rays tests the leaf's groups; a ray that hits is done and leaves every mask. The node's
// boxes, the push and the pop are paid once for all of its rays rather than once per ray (the
// ray-stream traversal of Tsakok 2009 and Fuetterling et al. 2015, with incoherent rays sorted
// by octant as Embree's stream calls do).
//
// Each ray's clip is the eight-wide walk's arithmetic (clip_axis), lane for lane, and its leaf
// tests are the walk's: a ray
// reaches a leaf here exactly when the one-ray walk, not stopping early, would, so the any-hit
// answer is the one-ray call's. Design in docs/rays.md ("Occlusion in octant streams"), figures in
// docs/benchmarks.md.
#include <cstddef>
#include <cstdint>

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

/// The rays of one octant, their slab constants one array per component.
struct OctantStream {
    alignas(32) float origin[3][octant_stream_size];
    alignas(32) float inv[3][octant_stream_size];
    alignas(32) float inv_far[3][octant_stream_size];
    alignas(32) float tmin[octant_stream_size];
    alignas(32) float tmax[octant_stream_size];
    WatertightRay<float> prep[octant_stream_size];
    std::size_t index[octant_stream_size];  // the ray's place in the batch
    int count = 0;

    /// Adds a ray wide_ray_usable accepts, with its slab constants k.
    void add(const Ray<float, 3>& ray, const SlabConstants& k, std::size_t i) {
        const int r = count++;
        for (int a = 0; a < 3; ++a) {
            origin[a][r] = k.origin[a];
            inv[a][r] = k.inv[a];
            inv_far[a][r] = k.inv_far[a];
        }
        tmin[r] = ray.tmin;
        tmax[r] = ray.tmax;
        prep[r] = WatertightRay<float>(ray, WatertightRay<float>::KnownValid{});
        index[r] = i;
    }
};

/// The octant of a ray's direction: bit a set when component a's sign bit is (-0 included, as
/// SlabConstants reads its planes).
inline int direction_octant(const SlabConstants& k) {
    return int(k.near[0] >= 3) | int(k.near[1] >= 3) << 1 | int(k.near[2] >= 3) << 2;
}

/// Walks the stream's rays (all of octant `octant`) through `tree`; calls blocked(index, bool)
/// once for each.
template <class Blocked>
[[gnu::target("avx2")]] void occlude_octant_stream(WideRayView<8> tree, const OctantStream& s,
                                                   int octant, Blocked&& blocked) {
    struct Entry {
        std::uint32_t child, groups, rays;  // groups > 0: a leaf; rays: the mask of its rays
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
    std::uint32_t live = all;  // rays not yet blocked
    Entry stack[(8 - 1) * max_bvh_depth + 1];
    std::uint32_t size = 0;
    Entry current{0, 0, all};
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
            // Lane c: the rays that hit child c.
            I rays_of = I::zero();
            for (std::uint32_t m = current.rays; m; m &= m - 1) {
                const int r = __builtin_ctz(m);
                F t0(s.tmin[r]), t1(s.tmax[r]);
                for (int a = 0; a < 3; ++a)  // the walk's clip, for this ray
                    avx2::clip_axis<8>(near_planes[a], far_planes[a], F(s.origin[a][r]),
                                       F(s.inv[a][r]), F(s.inv_far[a][r]), t0, t1);
                rays_of = rays_of | (simd::bits_of(t0 <= t1) & I(int(1u << r)));
            }
            unsigned children = (rays_of == I::zero()).bits() ^ 0xFFu;
            if (children != 0) {
                alignas(32) std::uint32_t mask[8];
                rays_of.store(mask);
                // Any order serves occlusion: the first hit child goes on, the others wait.
                const int first = __builtin_ctz(children);
                children &= children - 1;
                current = Entry{node.child[first], node.groups[first], mask[first]};
                // The next entry's first three lines, as the walk asks for them, so that they
                // arrive while the stream finishes this node.
                ask_for_next(WideEntry{current.child, current.groups, 0},
                             [&](const WideEntry& e) { return entry_address(nodes, groups, e); });
                for (; children; children &= children - 1) {
                    const int c = __builtin_ctz(children);
                    const Entry e{node.child[c], node.groups[c], mask[c]};
                    stack[size++] = e;
                    simd::prefetch(entry_address(nodes, groups, WideEntry{e.child, e.groups, 0}));
                }
                continue;
            }
        } else {
            for (std::uint32_t m = current.rays; m; m &= m - 1) {
                const int r = __builtin_ctz(m);
                bool found = false;
                const auto record = [&](int, const TriangleHit<float>& h) {
                    found = true;
                    return h.t;
                };
                // AnyLeaves' tests, for this ray.
                const avx2::WatertightRayLanes<8> lanes(s.prep[r]);
                for (std::uint32_t g = current.child; g < current.child + current.groups && !found;
                     ++g) {
                    float tmax = s.tmax[r];
                    avx2::intersect_watertight(lanes, groups[g], s.tmin[r], tmax, record);
                }
                if (found) live &= ~(1u << r);
            }
            if (live == 0) break;
        }
        // The next entry that still has live rays.
        do {
            if (size == 0) goto done;
            current = stack[--size];
            current.rays &= live;
        } while (current.rays == 0);
    }
done:
    for (int r = 0; r < s.count; ++r) blocked(s.index[r], ((live >> r) & 1) == 0);
}

/// Sorts a batch's rays into one stream per octant, walks a stream whenever it fills, and the
/// part-full ones at the end. blocked(index, bool) gets each ray's answer. 26 KB: kept on the
/// calling thread's stack for one batch.
class OctantStreams {
  public:
    /// Adds ray i (one wide_ray_usable accepts, with its slab constants k); walks its octant's
    /// stream if that is now full.
    template <class Blocked>
    void add(WideRayView<8> tree, const Ray<float, 3>& ray, const SlabConstants& k, std::size_t i,
             Blocked&& blocked) {
        const int octant = direction_octant(k);
        OctantStream& s = streams_[octant];
        s.add(ray, k, i);
        if (s.count == octant_stream_size) {
            occlude_octant_stream(tree, s, octant, blocked);
            s.count = 0;
        }
    }
    /// Walks the rays still waiting.
    template <class Blocked>
    void finish(WideRayView<8> tree, Blocked&& blocked) {
        for (int octant = 0; octant < 8; ++octant) {
            OctantStream& s = streams_[octant];
            if (s.count > 0) occlude_octant_stream(tree, s, octant, blocked);
            s.count = 0;
        }
    }

  private:
    OctantStream streams_[8];
};

}  // namespace detail
#endif

}  // namespace bvhkit
