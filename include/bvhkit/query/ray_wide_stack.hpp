#pragma once
// What the wide walks (query/ray_wide.hpp, query/ray_stream.hpp) do after a node's clip: the hit
// children that are not visited next go on a stack with their entry distances, and pop later,
// nearest first for a closest hit, unless farther than the closest hit found by then.
//
// The four-wide walk pushes them one by one (take_hits). The eight-wide walks push all of a node's
// hit children at once, with no branch on how many they are or on their order: the branches of a
// push one by one (the number of hit children, which of two is nearer, where an entry goes in the
// stack) are taken by the data, and were nearly half of a random ray's mispredicted branches
// (docs/benchmarks.md, "Ray measurements"). Their stack holds its entries one array per field, so
// that eight entries go on in one vector store a field, in the order a sorting network gives them
// (a bitonic network of six compare-exchange layers, Batcher 1968).
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>

#include "bvhkit/bvh/bvh.hpp"  // max_bvh_depth
#include "bvhkit/query/ray_wide_layout.hpp"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace bvhkit {

#if defined(__SSE2__)
namespace detail {

struct WideEntry {
    std::uint32_t child, groups;  // groups > 0: a leaf
    float t;
};

/// The four-wide walk's stack: each level pushes at most three entries, and a wide tree is no
/// deeper than the binary tree it came from (max_bvh_depth).
using WideStack4 = WideEntry[3 * max_bvh_depth + 1];

/// Where entry `e` starts: its node, or its leaf's first group. Both addresses, then a select
/// without a branch: a branch on the kind of entry was mispredicted at about one push in four.
template <class Node, class Group>
[[gnu::always_inline]] inline const char* entry_address(const Node* nodes, const Group* groups,
                                                        const WideEntry& e) {
    // In integers: the address of the kind the entry is not may lie past its array's end.
    const std::uintptr_t node = reinterpret_cast<std::uintptr_t>(nodes) + e.child * sizeof(Node);
    const std::uintptr_t group = reinterpret_cast<std::uintptr_t>(groups) + e.child * sizeof(Group);
    const std::uintptr_t is_node = std::uintptr_t(0) - std::uintptr_t(e.groups == 0);
    return reinterpret_cast<const char*>((node & is_node) | (group & ~is_node));
}

/// Asks for the first three lines of `e`, the entry a walk takes next (a node's boxes; most of a
/// leaf's first group).
template <class Line>
[[gnu::always_inline]] inline void ask_for_next(const WideEntry& e, Line&& line) {
    const char* next = line(e);
    _mm_prefetch(next, _MM_HINT_T0);
    _mm_prefetch(next + 64, _MM_HINT_T0);
    _mm_prefetch(next + 128, _MM_HINT_T0);
}

/// After a four-wide node's clip: the nearest hit lane of `mask` becomes `current`, the others are
/// pushed, kept in order of distance so that they pop nearest first. Every entry's first line is
/// asked for now: most pushed entries are read later, and the walk misses the caches at most
/// nodes.
template <class Line>
[[gnu::always_inline]] inline void take_hits(unsigned mask, const float* entry,
                                             const RayNode<4>& node, WideEntry& current,
                                             WideEntry* stack, std::uint32_t& size, Line&& line) {
    const int first = __builtin_ctz(mask);
    mask &= mask - 1;
    current = WideEntry{node.child[first], node.groups[first], entry[first]};
    const std::uint32_t base = size;
    for (; mask; mask &= mask - 1) {
        const int c = __builtin_ctz(mask);
        WideEntry e{node.child[c], node.groups[c], entry[c]};
        if (e.t < current.t) std::swap(e, current);
        std::uint32_t i = size++;
        for (; i > base && stack[i - 1].t < e.t; --i) stack[i] = stack[i - 1];
        stack[i] = e;
        _mm_prefetch(line(e), _MM_HINT_T0);
    }
    ask_for_next(current, line);
}

/// take_hits for any hit, which needs no order: the first hit lane becomes `current`, the others
/// are pushed as they come. Sorting them cost instructions and mispredicted branches and bought
/// nothing: no entry is ever dropped for being farther than a hit, the walk stops at the first one.
template <class Line>
[[gnu::always_inline]] inline void take_hits_unordered(unsigned mask, const float* entry,
                                                       const RayNode<4>& node, WideEntry& current,
                                                       WideEntry* stack, std::uint32_t& size,
                                                       Line&& line) {
    const int first = __builtin_ctz(mask);
    mask &= mask - 1;
    current = WideEntry{node.child[first], node.groups[first], entry[first]};
    for (; mask; mask &= mask - 1) {
        const int c = __builtin_ctz(mask);
        const WideEntry e{node.child[c], node.groups[c], entry[c]};
        stack[size++] = e;
        _mm_prefetch(line(e), _MM_HINT_T0);
    }
    ask_for_next(current, line);
}

/// Pops the next entry the ray can still reach; false when none is left.
[[gnu::always_inline]] inline bool pop(WideEntry* stack, std::uint32_t& size, float tmax,
                                       WideEntry& current) {
    do {
        if (size == 0) return false;
        current = stack[--size];
    } while (current.t > tmax);
    return true;
}

#if BVHKIT_RAY_AVX2
/// The eight-wide walks' stack, one array per field of its entries.
struct WideStack8 {
    // Each level pushes at most seven entries (max_bvh_depth levels), and a push writes eight
    // slots.
    static constexpr std::size_t capacity = 7 * std::size_t(max_bvh_depth) + 8;
    alignas(32) std::uint32_t child[capacity];
    alignas(32) std::uint32_t groups[capacity];
    alignas(32) float t[capacity];

    /// A walk starts with slot 0 set (to the root), so that the slot ask_for_top8 reads is always
    /// one the walk wrote.
    WideStack8() {
        child[0] = 0;
        groups[0] = 0;
        t[0] = 0.0f;
    }
    WideEntry entry(std::uint32_t i) const { return WideEntry{child[i], groups[i], t[i]}; }
};

/// Asks for the first line of the entry on top of a stack of `size` entries (slot 0 when it is
/// empty): the one the walk pops next, whose line then arrives while the walk is still below
/// the current entry. Asked after every push and pop of the one-ray eight-wide walk: random rays,
/// whose next entry is rarely in the caches, gain more than camera rays, which find their lines
/// there, lose (docs/benchmarks.md, "Ray measurements").
template <class Line>
[[gnu::always_inline]] inline void ask_for_top8(const WideStack8& stack, std::uint32_t size,
                                                Line&& line) {
    _mm_prefetch(line(stack.entry(size - (size != 0))), _MM_HINT_T0);
}

/// One compare-exchange layer of eight keys: each lane against the `partner` lane a shuffle
/// brought, keeping the larger key in the lanes set in `Larger`.
template <int Larger>
[[gnu::target("avx2"), gnu::always_inline]] inline __m256i compare_exchange8(__m256i v,
                                                                             __m256i partner) {
    return _mm256_blend_epi32(_mm256_min_epi32(v, partner), _mm256_max_epi32(v, partner), Larger);
}

/// Eight keys in descending order: a bitonic sorting network of six layers, the partners lane ^ 1,
/// ^ 2 and ^ 4. The first three layers sort blocks of two and four alternately down and up; the
/// last three merge all eight downwards.
[[gnu::target("avx2"), gnu::always_inline]] inline __m256i sort8_descending(__m256i v) {
    v = compare_exchange8<0x99>(v, _mm256_shuffle_epi32(v, 0xB1));
    v = compare_exchange8<0xC3>(v, _mm256_shuffle_epi32(v, 0x4E));
    v = compare_exchange8<0xA5>(v, _mm256_shuffle_epi32(v, 0xB1));
    v = compare_exchange8<0x0F>(v, _mm256_permute4x64_epi64(v, 0x4E));
    v = compare_exchange8<0x33>(v, _mm256_shuffle_epi32(v, 0x4E));
    v = compare_exchange8<0x55>(v, _mm256_shuffle_epi32(v, 0xB1));
    return v;
}

/// The lanes of each eight-bit mask in increasing order, four bits a lane (lane k of the mask's
/// set bits in bits 4k..4k+3).
inline constexpr std::array<std::uint32_t, 256> set_lanes = [] {
    std::array<std::uint32_t, 256> table{};
    for (unsigned mask = 0; mask < 256; ++mask)
        for (unsigned lane = 0, k = 0; lane < 8; ++lane)
            if ((mask >> lane) & 1u) table[mask] |= lane << (4 * k++);
    return table;
}();

/// Lane `lane` of `entry`, `lane` in every lane of the index.
[[gnu::target("avx2"), gnu::always_inline]] inline float lane_of(__m256 entry, __m256i lane) {
    return _mm256_cvtss_f32(_mm256_permutevar8x32_ps(entry, lane));
}

/// Lane `first` of `node` becomes the walk's next entry, at its distance in `entry`; its first
/// lines are asked for.
template <class Line>
[[gnu::target("avx2"), gnu::always_inline]] inline void go_to_lane8(const RayNode<8>& node,
                                                                    __m256 entry, int first,
                                                                    WideEntry& current,
                                                                    Line&& line) {
    current =
        WideEntry{node.child[first], node.groups[first], lane_of(entry, _mm256_set1_epi32(first))};
    ask_for_next(current, line);
}

/// Writes the node's lanes, in the order `order` lists them, to slots [at, at + 8) of `stack`.
[[gnu::target("avx2"), gnu::always_inline]] inline void put8(WideStack8& stack, std::uint32_t at,
                                                             __m256i order, const RayNode<8>& node,
                                                             __m256 entry) {
    const __m256i child = _mm256_load_si256(reinterpret_cast<const __m256i*>(node.child));
    const __m256i groups = _mm256_load_si256(reinterpret_cast<const __m256i*>(node.groups));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(stack.child + at),
                        _mm256_permutevar8x32_epi32(child, order));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(stack.groups + at),
                        _mm256_permutevar8x32_epi32(groups, order));
    _mm256_storeu_ps(stack.t + at, _mm256_permutevar8x32_ps(entry, order));
}

/// take_hits for the eight-wide walks: the nearest hit lane becomes `current`, the other hit lanes
/// go on the stack farthest first, so that they pop nearest first. `entry` holds the lanes' entry
/// distances, `hit` is all ones in the hit lanes, `mask` their bits (not 0). Each lane's key is
/// its distance's bits, turned to order as signed integers (a negative float's other bits
/// reversed), with the lane in the lowest three bits: the keys are distinct, and distances that
/// differ only in those three bits go by lane.
template <class Line>
[[gnu::target("avx2"), gnu::always_inline]] inline void push_nearest_first8(
    __m256 entry, __m256 hit, unsigned mask, const RayNode<8>& node, WideEntry& current,
    WideStack8& stack, std::uint32_t& size, Line&& line) {
    if ((mask & (mask - 1)) == 0) {
        // One hit child, nothing to push: a branch that coherent rays predict, and the next node's
        // address sooner than by the reduction below. Without it camera rays ran slower, and
        // random rays gained little.
        go_to_lane8(node, entry, __builtin_ctz(mask), current, line);
        return;
    }
    const __m256i seven = _mm256_set1_epi32(7);
    __m256i bits = _mm256_castps_si256(entry);
    bits = _mm256_xor_si256(bits, _mm256_srli_epi32(_mm256_srai_epi32(bits, 31), 1));
    const __m256i key = _mm256_or_si256(_mm256_andnot_si256(seven, bits),
                                        _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    const __m256i is_hit = _mm256_castps_si256(hit);
    constexpr std::int32_t least = std::numeric_limits<std::int32_t>::min();
    constexpr std::int32_t most = std::numeric_limits<std::int32_t>::max();
    // Farthest first, the missed lanes (least keys) after the hits; the nearest lands in slot
    // size + hits - 1, above the new top.
    const __m256i order = _mm256_and_si256(
        sort8_descending(_mm256_blendv_epi8(_mm256_set1_epi32(least), key, is_hit)), seven);
    put8(stack, size, order, node, entry);
    size += std::uint32_t(__builtin_popcount(mask)) - 1;
    // The nearest lane again, by a reduction that does not wait for the sort: it is the walk's
    // next step.
    __m256i nearest = _mm256_blendv_epi8(_mm256_set1_epi32(most), key, is_hit);
    nearest = _mm256_min_epi32(nearest, _mm256_permute4x64_epi64(nearest, 0x4E));
    nearest = _mm256_min_epi32(nearest, _mm256_shuffle_epi32(nearest, 0x4E));
    nearest = _mm256_min_epi32(nearest, _mm256_shuffle_epi32(nearest, 0xB1));
    go_to_lane8(node, entry, _mm256_cvtsi256_si32(nearest) & 7, current, line);
}

/// take_hits_unordered for the eight-wide walks: the first hit lane becomes `current`, the others
/// go on the stack in lane order.
template <class Line>
[[gnu::target("avx2"), gnu::always_inline]] inline void push_in_lane_order8(
    __m256 entry, unsigned mask, const RayNode<8>& node, WideEntry& current, WideStack8& stack,
    std::uint32_t& size, Line&& line) {
    const int first = __builtin_ctz(mask);
    const unsigned rest = mask & (mask - 1);
    const __m256i order =
        _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32(std::int32_t(set_lanes[rest])),
                                           _mm256_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28)),
                         _mm256_set1_epi32(7));
    put8(stack, size, order, node, entry);
    size += std::uint32_t(__builtin_popcount(rest));
    go_to_lane8(node, entry, first, current, line);
}

/// pop for the eight-wide walks' stack.
[[gnu::always_inline]] inline bool pop8(const WideStack8& stack, std::uint32_t& size, float tmax,
                                        WideEntry& current) {
    do {
        if (size == 0) return false;
        current = stack.entry(--size);
    } while (current.t > tmax);
    return true;
}
#endif

}  // namespace detail
#endif

}  // namespace bvhkit
