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
#include "bvhkit/simd/simd.hpp"

namespace bvhkit {

#if BVHKIT_SIMD
namespace detail {

struct WideEntry {
    std::uint32_t child, groups;  // groups > 0: a leaf
    float t;
};

/// The stack of the walk of width W.
template <int W>
struct WideStack;

/// The four-wide walk's stack: each level pushes at most three entries, and a wide tree is no
/// deeper than the binary tree it came from (max_bvh_depth).
template <>
struct WideStack<4> {
    WideEntry entry[3 * max_bvh_depth + 1];
};
using WideStack4 = WideStack<4>;

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
    simd::prefetch(next);
    simd::prefetch(next + 64);
    simd::prefetch(next + 128);
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
        simd::prefetch(line(e));
    }
    ask_for_next(current, line);
}

/// take_hits for any hit, which needs no distance order: the hit lanes are visited in lane order,
/// the first becomes `current` and the others are pushed last lane first, so that they pop in
/// lane order (the layout's order for occlusion rays, query/ray_wide_occlusion_order.hpp). Sorting
/// by distance cost instructions and mispredicted branches and bought nothing: no entry is ever
/// dropped for being farther than a hit, the walk stops at the first one.
template <class Line>
[[gnu::always_inline]] inline void take_hits_unordered(unsigned mask, const float* entry,
                                                       const RayNode<4>& node, WideEntry& current,
                                                       WideEntry* stack, std::uint32_t& size,
                                                       Line&& line) {
    const int first = __builtin_ctz(mask);
    mask &= mask - 1;
    current = WideEntry{node.child[first], node.groups[first], entry[first]};
    for (; mask; mask &= ~(1u << (31 - __builtin_clz(mask)))) {  // the last lane deepest
        const int c = 31 - __builtin_clz(mask);
        const WideEntry e{node.child[c], node.groups[c], entry[c]};
        stack[size++] = e;
        simd::prefetch(line(e));
    }
    ask_for_next(current, line);
}

/// What the walk of width four does after a node's clip that hit the lanes of `mask`, whose
/// entry distances `entry` holds: take_hits, or take_hits_unordered for any hit.
template <bool AnyHit, class Line>
[[gnu::always_inline]] inline void push_hits(simd::Float<4> entry, simd::Mask<4>, unsigned mask,
                                             const RayNode<4>& node, WideEntry& current,
                                             WideStack<4>& stack, std::uint32_t& size,
                                             Line&& line) {
    alignas(16) float t[4];
    entry.store(t);
    if constexpr (AnyHit)
        take_hits_unordered(mask, t, node, current, stack.entry, size, line);
    else
        take_hits(mask, t, node, current, stack.entry, size, line);
}

/// Pops the next entry the ray can still reach; false when none is left.
[[gnu::always_inline]] inline bool pop(WideStack<4>& stack, std::uint32_t& size, float tmax,
                                       WideEntry& current) {
    do {
        if (size == 0) return false;
        current = stack.entry[--size];
    } while (current.t > tmax);
    return true;
}

/// The four-wide walk asks for nothing more after a pop: its pushes asked for every entry.
template <class Line>
[[gnu::always_inline]] inline void ask_for_top(const WideStack<4>&, std::uint32_t, Line&&) {}

#if BVHKIT_SIMD_AVX2
/// The eight-wide walks' stack, one array per field of its entries.
template <>
struct WideStack<8> {
    // Each level pushes at most seven entries (max_bvh_depth levels), and a push writes eight
    // slots.
    static constexpr std::size_t capacity = 7 * std::size_t(max_bvh_depth) + 8;
    alignas(32) std::uint32_t child[capacity];
    alignas(32) std::uint32_t groups[capacity];
    alignas(32) float t[capacity];

    /// A walk starts with slot 0 set (to the root), so that the slot ask_for_top8 reads is always
    /// one the walk wrote.
    WideStack() {
        child[0] = 0;
        groups[0] = 0;
        t[0] = 0.0f;
    }
    WideEntry entry(std::uint32_t i) const { return WideEntry{child[i], groups[i], t[i]}; }
};
using WideStack8 = WideStack<8>;

/// Asks for the first line of the entry on top of a stack of `size` entries (slot 0 when it is
/// empty): the one the walk pops next, whose line then arrives while the walk is still below
/// the current entry. Asked after every push and pop of the one-ray eight-wide walk: random rays,
/// whose next entry is rarely in the caches, gain more than camera rays, which find their lines
/// there, lose (docs/benchmarks.md, "Ray measurements").
template <class Line>
[[gnu::always_inline]] inline void ask_for_top8(const WideStack8& stack, std::uint32_t size,
                                                Line&& line) {
    simd::prefetch(line(stack.entry(size - (size != 0))));
}

/// One compare-exchange layer of eight keys: each lane against the `partner` lane a shuffle
/// brought, keeping the larger key in the lanes set in `Larger`.
template <int Larger>
BVHKIT_SIMD_INLINE_AVX2 simd::Int<8> compare_exchange8(simd::Int<8> v, simd::Int<8> partner) {
    return simd::blend<Larger>(min(v, partner), max(v, partner));
}

/// Eight keys in descending order: a bitonic sorting network of six layers, the partners lane ^ 1,
/// ^ 2 and ^ 4. The first three layers sort blocks of two and four alternately down and up; the
/// last three merge all eight downwards.
BVHKIT_SIMD_INLINE_AVX2 simd::Int<8> sort8_descending(simd::Int<8> v) {
    v = compare_exchange8<0x99>(v, v.shuffle_in_halves<0xB1>());
    v = compare_exchange8<0xC3>(v, v.shuffle_in_halves<0x4E>());
    v = compare_exchange8<0xA5>(v, v.shuffle_in_halves<0xB1>());
    v = compare_exchange8<0x0F>(v, v.permute_pairs<0x4E>());
    v = compare_exchange8<0x33>(v, v.shuffle_in_halves<0x4E>());
    v = compare_exchange8<0x55>(v, v.shuffle_in_halves<0xB1>());
    return v;
}

/// The lanes of each eight-bit mask in decreasing order, four bits a lane (the mask's k-th
/// highest set bit in bits 4k..4k+3).
inline constexpr std::array<std::uint32_t, 256> set_lanes_descending = [] {
    std::array<std::uint32_t, 256> table{};
    for (unsigned mask = 0; mask < 256; ++mask)
        for (unsigned lane = 8, k = 0; lane-- > 0;)
            if ((mask >> lane) & 1u) table[mask] |= lane << (4 * k++);
    return table;
}();

/// Lane `lane` of `entry`, `lane` in every lane of the index.
BVHKIT_SIMD_INLINE_AVX2 float lane_of(simd::Float<8> entry, simd::Int<8> lane) {
    return permute(entry, lane).first();
}

/// Lane `first` of `node` becomes the walk's next entry, at its distance in `entry`; its first
/// lines are asked for.
template <class Line>
BVHKIT_SIMD_INLINE_AVX2 void go_to_lane8(const RayNode<8>& node, simd::Float<8> entry, int first,
                                         WideEntry& current, Line&& line) {
    current = WideEntry{node.child[first], node.groups[first], lane_of(entry, simd::Int<8>(first))};
    ask_for_next(current, line);
}

/// Writes the node's lanes, in the order `order` lists them, to slots [at, at + 8) of `stack`.
BVHKIT_SIMD_INLINE_AVX2 void put8(WideStack8& stack, std::uint32_t at, simd::Int<8> order,
                                  const RayNode<8>& node, simd::Float<8> entry) {
    permute(simd::Int<8>::load(node.child), order).store_unaligned(stack.child + at);
    permute(simd::Int<8>::load(node.groups), order).store_unaligned(stack.groups + at);
    permute(entry, order).store_unaligned(stack.t + at);
}

/// take_hits for the eight-wide walks: the nearest hit lane becomes `current`, the other hit lanes
/// go on the stack farthest first, so that they pop nearest first. `entry` holds the lanes' entry
/// distances, `hit` is all ones in the hit lanes, `mask` their bits (not 0). Each lane's key is
/// its distance's bits, turned to order as signed integers (a negative float's other bits
/// reversed), with the lane in the lowest three bits: the keys are distinct, and distances that
/// differ only in those three bits go by lane.
template <class Line>
BVHKIT_SIMD_INLINE_AVX2 void push_nearest_first8(simd::Float<8> entry, simd::Mask<8> hit,
                                                 unsigned mask, const RayNode<8>& node,
                                                 WideEntry& current, WideStack8& stack,
                                                 std::uint32_t& size, Line&& line) {
    if ((mask & (mask - 1)) == 0) {
        // One hit child, nothing to push: a branch that coherent rays predict, and the next node's
        // address sooner than by the reduction below. Without it camera rays ran slower, and
        // random rays gained little.
        go_to_lane8(node, entry, __builtin_ctz(mask), current, line);
        return;
    }
    using Int = simd::Int<8>;
    const Int seven(7);
    Int bits = simd::bits_of(entry);
    bits = bits ^ bits.shift_right_arithmetic<31>().shift_right_logical<1>();
    const Int key = andnot(seven, bits) | Int::lanes(0, 1, 2, 3, 4, 5, 6, 7);
    constexpr std::int32_t least = std::numeric_limits<std::int32_t>::min();
    constexpr std::int32_t most = std::numeric_limits<std::int32_t>::max();
    // Farthest first, the missed lanes (least keys) after the hits; the nearest lands in slot
    // size + hits - 1, above the new top.
    const Int order = sort8_descending(select(hit, key, Int(least))) & seven;
    put8(stack, size, order, node, entry);
    size += std::uint32_t(__builtin_popcount(mask)) - 1;
    // The nearest lane again, by a reduction that does not wait for the sort: it is the walk's
    // next step.
    Int nearest = select(hit, key, Int(most));
    nearest = min(nearest, nearest.permute_pairs<0x4E>());
    nearest = min(nearest, nearest.shuffle_in_halves<0x4E>());
    nearest = min(nearest, nearest.shuffle_in_halves<0xB1>());
    go_to_lane8(node, entry, nearest.first() & 7, current, line);
}

/// take_hits_unordered for the eight-wide walks: the first hit lane becomes `current`, the others
/// go on the stack last lane first, so that they pop in lane order.
template <class Line>
BVHKIT_SIMD_INLINE_AVX2 void push_in_lane_order8(simd::Float<8> entry, unsigned mask,
                                                 const RayNode<8>& node, WideEntry& current,
                                                 WideStack8& stack, std::uint32_t& size,
                                                 Line&& line) {
    const int first = __builtin_ctz(mask);
    const unsigned rest = mask & (mask - 1);
    const simd::Int<8> order =
        shift_right_logical(simd::Int<8>(std::int32_t(set_lanes_descending[rest])),
                            simd::Int<8>::lanes(0, 4, 8, 12, 16, 20, 24, 28)) &
        simd::Int<8>(7);
    put8(stack, size, order, node, entry);
    size += std::uint32_t(__builtin_popcount(rest));
    go_to_lane8(node, entry, first, current, line);
}

/// What the walk of width eight does after a node's clip: push_nearest_first8, or
/// push_in_lane_order8 for any hit.
template <bool AnyHit, class Line>
BVHKIT_SIMD_INLINE_AVX2 void push_hits(simd::Float<8> entry, simd::Mask<8> hit, unsigned mask,
                                       const RayNode<8>& node, WideEntry& current,
                                       WideStack8& stack, std::uint32_t& size, Line&& line) {
    if constexpr (AnyHit)
        push_in_lane_order8(entry, mask, node, current, stack, size, line);
    else
        push_nearest_first8(entry, hit, mask, node, current, stack, size, line);
}

/// pop for the eight-wide walks' stack.
[[gnu::always_inline]] inline bool pop(const WideStack8& stack, std::uint32_t& size, float tmax,
                                       WideEntry& current) {
    do {
        if (size == 0) return false;
        current = stack.entry(--size);
    } while (current.t > tmax);
    return true;
}

/// ask_for_top8, the name the walk calls for either width.
template <class Line>
[[gnu::always_inline]] inline void ask_for_top(const WideStack8& stack, std::uint32_t size,
                                               Line&& line) {
    ask_for_top8(stack, size, line);
}
#endif

}  // namespace detail
#endif

}  // namespace bvhkit
