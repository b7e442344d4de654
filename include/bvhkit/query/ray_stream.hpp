#pragma once
// Batches of rays through the eight-wide layout with several rays in flight on one thread.
//
// One ray at a time, each step of the walk needs the node or leaf the step before chose, so once
// the tree outgrows the caches the walk waits for memory at nearly every step, and out-of-order
// execution cannot reach into the next ray (hundreds of instructions on). Here a stream keeps
// eight rays' walks at once: each in turn takes one step (a node's clip, or a leaf's groups),
// asks for the lines of the entry it will take next, and yields, so that those lines arrive while
// the other seven work (the interleaving of independent pointer chases of Kocberber, Falsafi and
// Grot 2015, "Asynchronous memory access chaining").
//
// Each ray's walk is the eight-wide walk's, step for step, with the same arithmetic (the walk's
// clip, push and leaf tests, query/ray_wide_walk.hpp): the answers are the one-by-one calls', bit
// for bit; only the order in which the rays' steps run is interleaved. Design in docs/rays.md
// ("Streams"), figures in docs/benchmarks.md.
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "bvhkit/query/ray_wide.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

#if BVHKIT_RAY_AVX2
namespace detail {

/// Rays a stream keeps in flight (tuning.hpp).
inline constexpr int stream_width = tuning::stream_width;

/// Whether a stream pays for `tree`: once its layout is tuning::stream_from_layout_bytes or more.
/// A layout that stays in a core's L2 has little latency to hide, and the walks' interleaving
/// costs it some (the branch history of one ray's walk no longer predicts its next step).
inline bool stream_pays(WideRayView<8> tree) {
    return tree.bytes() >= tuning::stream_from_layout_bytes;
}

/// One ray's walk in a stream: its constants and its stack, kept in memory between its steps
/// (5.6 KB, nearly all of it the stack, of which a walk touches only the top: a stream's eight
/// take 45 KB of the calling thread's stack).
struct StreamRay {
    SlabConstants k;
    WatertightRay<float> prep;
    Ray<float, 3> ray;  // ray.tmax shrinks to the closest hit so far
    WideEntry current;
    std::uint32_t size = 0;
    std::size_t index = 0;  // the ray's place in the batch
    TriangleHit<float> best{};
    const TriangleGroup8* hit_group = nullptr;  // closest hit: where the hit lies; null on none
    int hit_lane = 0;
    bool found = false;  // any hit
    bool live = false;   // walking
    WideStack8 stack;
};

/// Walks rays through `tree`, stream_width at a time. start(StreamRay&) -> bool fills a slot with
/// the next ray that needs a walk (its index, ray, SlabConstants and WatertightRay) or returns
/// false when there is none; finish(const StreamRay&) takes a ray whose walk ended (start may
/// pass it rays it answers without a walk: the slot then holds no hit). AnyHit: stop
/// at the first hit, children in lane order (the walk with AnyLeaves); else the closest hit
/// (ClosestLeaves).
template <bool AnyHit, class Start, class Finish>
[[gnu::target("avx2")]] void stream8(WideRayView<8> tree, StreamRay* slots, Start&& start,
                                     Finish&& finish) {
    const RayNode<8>* nodes = tree.nodes.data();
    const TriangleGroup8* groups = tree.groups.data();
    const auto line = [&](const WideEntry& e) { return entry_address(nodes, groups, e); };
    // Asks for the lines of the entry a ray takes next, from line `from` on: a node's four, or up
    // to ten of a leaf's (two groups of eight; the rest of a leaf of up to six arrive while the
    // first are tested).
    const auto ask = [&](const WideEntry& e, std::uint32_t from) {
        const char* p = line(e);
        const std::uint32_t lines = e.groups == 0 ? 4 : std::min<std::uint32_t>(10, 5 * e.groups);
        for (std::uint32_t q = from; q < lines; ++q) simd::prefetch(p + 64 * q);
    };
    const auto begin = [&](StreamRay& s) {
        s.size = 0;
        s.hit_group = nullptr;
        s.found = false;
        s.live = start(s);
        if (s.live) s.current = WideEntry{0, 0, s.ray.tmin};
        return s.live;
    };
    int live = 0;
    for (int j = 0; j < stream_width; ++j) live += begin(slots[j]);
    NoStats stats;
    while (live > 0)
        for (int j = 0; j < stream_width; ++j) {
            StreamRay& s = slots[j];
            if (!s.live) continue;
            // The walk's step with the slot's ray; a push asks for the next entry's first three
            // lines, the rest of them here, and a pop for all of them.
            avx2::FreshRegisters<8> registers{s.k, s.ray};
            const auto pushed = [&] { ask(s.current, 3); };
            const auto popped = [&] { ask(s.current, 0); };
            bool going;
            if constexpr (AnyHit) {
                avx2::AnyLeaves<8, NoStats> leaves{groups, s.prep, s.ray, s.found, stats};
                going = avx2::step(nodes, registers, s.k, s.ray, s.current, s.stack, s.size, leaves,
                                   stats, line, pushed, popped);
            } else {
                avx2::ClosestLeaves<8, NoStats> leaves{groups,      s.prep,     s.ray, s.best,
                                                       s.hit_group, s.hit_lane, stats};
                going = avx2::step(nodes, registers, s.k, s.ray, s.current, s.stack, s.size, leaves,
                                   stats, line, pushed, popped);
            }
            if (going) continue;
            finish(s);
            live -= !begin(s);
        }
}

}  // namespace detail
#endif

}  // namespace bvhkit
