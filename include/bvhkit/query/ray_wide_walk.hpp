// No include guard: compiled once per instruction set by simd/per_isa.hpp, from
// query/ray_wide.hpp, which includes what this file uses.
//
// The wide walk, written once for W = 4 (detail::sse2) and W = 8 (detail::avx2): a node's clip,
// the push of its hit children (query/ray_wide_stack.hpp), the leaves' triangle tests
// (primitives/triangle_group_kernels.hpp) and the pop. The streams of query/ray_stream.hpp and
// query/ray_octant_stream.hpp take the same steps (the stream calls step; the octant stream clips
// with clip_axis and tests leaves with intersect_watertight), so that all of them round alike.

namespace bvhkit::detail::BVHKIT_SIMD_ISA {

/// One axis of the slab test: [t0, t1] narrowed to the ray's stretch between the near and far
/// planes of W boxes. max and min return their second operand when either is NaN, and the
/// accumulators never are, so a 0 * inf plane distance does not restrict the interval (as in the
/// scalar test).
template <int W>
[[gnu::always_inline]] inline void clip_axis(simd::Float<W> near, simd::Float<W> far,
                                             simd::Float<W> origin, simd::Float<W> inv,
                                             simd::Float<W> inv_far, simd::Float<W>& t0,
                                             simd::Float<W>& t1) {
    t0 = max((near - origin) * inv, t0);
    t1 = min((far - origin) * inv_far, t1);
}

/// A node's clip: set in the lanes the ray meets, whose entry distances `t0` then holds (t0 comes
/// in as the ray's tmin, t1 as its tmax). The ray's constants come as registers (origin, inv and
/// inv_far per axis) and as the rows of its near and far planes (SlabConstants::near and far).
template <int W>
[[gnu::always_inline]] inline simd::Mask<W> clip(
    const RayNode<W>& node, const simd::Float<W>* origin, const simd::Float<W>* inv,
    const simd::Float<W>* inv_far, const std::uint32_t* near_row, const std::uint32_t* far_row,
    simd::Float<W>& t0, simd::Float<W> t1) {
    using F = simd::Float<W>;
    for (int a = 0; a < 3; ++a)
        clip_axis<W>(F::load(node.lo[near_row[a]]), F::load(node.lo[far_row[a]]), origin[a], inv[a],
                     inv_far[a], t0, t1);
    return t0 <= t1;
}

// The leaf tests of the two queries: operator()(first_group, groups), which may shrink ray.tmax
// and returns true to stop the walk; any_hit says whether the order of the hit children is free.

template <int W, class Stats>
struct ClosestLeaves {
    using Group = typename WideRayView<W>::Group;
    static constexpr bool any_hit = false;  // the walk visits hit children nearest first
    const Group* groups;
    const WatertightRay<float>& prep;
    Ray<float, 3>& ray;
    TriangleHit<float>& best;
    const Group*& hit_group;
    int& hit_lane;
    Stats& stats;

    /// A hit in group g becomes the closest so far, and the range shrinks to it; at the closest
    /// so far's own t the lower triangle index is kept (closer_hit).
    auto record(std::uint32_t g) {
        return [this, g](int lane, const TriangleHit<float>& h) {
            if (hit_group != nullptr && h.t == best.t &&
                !closer_hit(h.t, groups[g].slot[lane], best.t, hit_group->slot[hit_lane]))
                [[unlikely]]
                return best.t;
            best = h;
            hit_group = groups + g;
            hit_lane = lane;
            return h.t;
        };
    }
    // Inlined into the walk: the tie rule in record() takes it past GCC's inlining budget, and a
    // call per leaf costs more than the rule.
    [[gnu::always_inline]] bool operator()(std::uint32_t first, std::uint32_t count) {
        const WatertightRayLanes<Group::lanes> lanes(prep);
        for (std::uint32_t g = first; g < first + count; ++g) {
            count_lanes(groups[g], stats);
            intersect_watertight(lanes, groups[g], ray.tmin, ray.tmax, record(g));
        }
        return false;
    }
};

template <int W, class Stats>
struct AnyLeaves {
    using Group = typename WideRayView<W>::Group;
    static constexpr bool any_hit = true;  // hit children in lane order, not by distance
    const Group* groups;
    const WatertightRay<float>& prep;
    const Ray<float, 3>& ray;
    bool& found;
    Stats& stats;

    /// Any hit ends the search.
    auto record() {
        return [this](int, const TriangleHit<float>& h) {
            found = true;
            return h.t;
        };
    }
    bool operator()(std::uint32_t first, std::uint32_t count) {
        const WatertightRayLanes<Group::lanes> lanes(prep);
        for (std::uint32_t g = first; g < first + count && !found; ++g) {
            count_lanes(groups[g], stats);
            float tmax = ray.tmax;
            intersect_watertight(lanes, groups[g], ray.tmin, tmax, record());
        }
        return found;
    }
};

template <int W, class OnHit, class Stats>
struct AllLeaves {
    using Group = typename WideRayView<W>::Group;
    static constexpr bool any_hit = true;  // every hit is wanted: the order of the children is free
    const Group* groups;
    const WatertightRay<float>& prep;
    const Ray<float, 3>& ray;
    OnHit& on_hit;  // on_hit(group, lane, hit) -> bool, false to stop
    bool stopped = false;
    Stats& stats;

    bool operator()(std::uint32_t first, std::uint32_t count) {
        const WatertightRayLanes<Group::lanes> lanes(prep);
        for (std::uint32_t g = first; g < first + count && !stopped; ++g) {
            count_lanes(groups[g], stats);
            float tmax = ray.tmax;  // never narrowed: each hit in the ray's range is reported
            intersect_watertight(lanes, groups[g], ray.tmin, tmax,
                                 [&](int lane, const TriangleHit<float>& h) {
                                     if (!stopped && !on_hit(groups[g], lane, h)) stopped = true;
                                     return ray.tmax;
                                 });
        }
        return stopped;
    }
};

/// A ray's slab constants in every lane: made once for a one-ray walk, once a step in a stream.
template <int W>
struct WalkRay {
    simd::Float<W> origin[3], inv[3], inv_far[3];

    [[gnu::always_inline]] explicit WalkRay(const SlabConstants& k) {
        for (int a = 0; a < 3; ++a) {
            origin[a] = simd::Float<W>(k.origin[a]);
            inv[a] = simd::Float<W>(k.inv[a]);
            inv_far[a] = simd::Float<W>(k.inv_far[a]);
        }
    }
};

/// The ray's registers in a one-ray walk: broadcast once, tmax again after each leaf.
template <int W>
struct HeldRegisters {
    const Ray<float, 3>& ray;
    WalkRay<W> constants;
    simd::Float<W> tmin, tmax;

    [[gnu::always_inline]] HeldRegisters(const SlabConstants& k, const Ray<float, 3>& r)
        : ray(r), constants(k), tmin(r.tmin), tmax(r.tmax) {}
    [[gnu::always_inline]] const WalkRay<W>& slab() const { return constants; }
    [[gnu::always_inline]] simd::Float<W> entry() const { return tmin; }
    [[gnu::always_inline]] simd::Float<W> exit() const { return tmax; }
    [[gnu::always_inline]] void after_leaf() { tmax = simd::Float<W>(ray.tmax); }
};

/// The registers of a ray in a stream: broadcast at each node, since a stream keeps nothing in
/// registers between one ray's steps.
template <int W>
struct FreshRegisters {
    const SlabConstants& k;
    const Ray<float, 3>& ray;

    [[gnu::always_inline]] WalkRay<W> slab() const { return WalkRay<W>(k); }
    [[gnu::always_inline]] simd::Float<W> entry() const { return simd::Float<W>(ray.tmin); }
    [[gnu::always_inline]] simd::Float<W> exit() const { return simd::Float<W>(ray.tmax); }
    [[gnu::always_inline]] void after_leaf() {}
};

/// One step of the walk from `current`, the step both the one-ray walk and the streams take: a
/// node's clip and the push of its hit children (then after_push()), or a leaf's tests
/// (on_leaf(first_group, groups), which may shrink ray.tmax and returns true to stop) and a pop
/// (then after_pop()). `registers` (HeldRegisters or FreshRegisters) gives the ray's constants
/// and its [tmin, tmax] in every lane. Returns false when the walk is over: a leaf stopped it, or
/// nothing the ray can reach is left.
template <int W, class Registers, class OnLeaf, class Stats, class Line, class AfterPush,
          class AfterPop>
[[gnu::always_inline]] inline bool step(const RayNode<W>* nodes, Registers& registers,
                                        const SlabConstants& k, const Ray<float, 3>& ray,
                                        WideEntry& current, WideStack<W>& stack,
                                        std::uint32_t& size, OnLeaf& on_leaf, Stats& stats,
                                        Line&& line, AfterPush&& after_push, AfterPop&& after_pop) {
    if (current.groups == 0) {
        const RayNode<W>& node = nodes[current.child];
        for (std::uint32_t c : node.child)  // boxes measured, as the binary walk counts
            if (c != invalid_index) stats.node();
        const auto& r = registers.slab();
        simd::Float<W> entry = registers.entry();
        const simd::Mask<W> hit =
            clip<W>(node, r.origin, r.inv, r.inv_far, k.near, k.far, entry, registers.exit());
        const unsigned mask = hit.bits();
        if (mask != 0) {
            push_hits<OnLeaf::any_hit>(entry, hit, mask, node, current, stack, size, line);
            after_push();
            return true;
        }
    } else {
        if (on_leaf(current.child, current.groups)) return false;
        registers.after_leaf();
    }
    if (!pop(stack, size, ray.tmax, current)) return false;
    after_pop();
    return true;
}

/// The walk of `tree` for `ray`: steps until the walk is over. After each push and pop it asks
/// for the line of the entry on top of the stack (ask_for_top).
template <int W, class OnLeaf, class Stats>
void walk(WideRayView<W> tree, Ray<float, 3>& ray, const SlabConstants& k, WideStack<W>& stack,
          OnLeaf& on_leaf, Stats& stats) {
    HeldRegisters<W> registers(k, ray);
    const RayNode<W>* nodes = tree.nodes.data();
    const auto* groups = tree.groups.data();
    const auto line = [&](const WideEntry& e) { return entry_address(nodes, groups, e); };
    std::uint32_t size = 0;
    WideEntry current{0, 0, ray.tmin};
    const auto ask = [&] { ask_for_top(stack, size, line); };
    while (step(nodes, registers, k, ray, current, stack, size, on_leaf, stats, line, ask, ask)) {
    }
}

/// closest_hit_wide's walk.
template <int W, class Stats>
bool closest_hit(WideRayView<W> tree, const Ray<float, 3>& ray_in, const SlabConstants& k,
                 const WatertightRay<float>& prep, TriangleHit<float>& best,
                 const typename WideRayView<W>::Group*& hit_group, int& hit_lane, Stats& stats) {
    Ray<float, 3> ray = ray_in;
    hit_group = nullptr;
    hit_lane = 0;
    ClosestLeaves<W, Stats> leaves{tree.groups.data(), prep, ray, best, hit_group, hit_lane, stats};
    WideStack<W> stack;
    walk(tree, ray, k, stack, leaves, stats);
    return hit_group != nullptr;
}

/// any_hit_wide's walk.
template <int W, class Stats>
bool any_hit(WideRayView<W> tree, const Ray<float, 3>& ray_in, const SlabConstants& k,
             const WatertightRay<float>& prep, Stats& stats) {
    Ray<float, 3> ray = ray_in;
    bool found = false;
    AnyLeaves<W, Stats> leaves{tree.groups.data(), prep, ray, found, stats};
    WideStack<W> stack;
    walk(tree, ray, k, stack, leaves, stats);
    return found;
}

/// all_hits_wide's walk.
template <int W, class OnHit, class Stats>
void all_hits(WideRayView<W> tree, const Ray<float, 3>& ray_in, const SlabConstants& k,
              const WatertightRay<float>& prep, OnHit& on_hit, Stats& stats) {
    Ray<float, 3> ray = ray_in;
    AllLeaves<W, OnHit, Stats> leaves{tree.groups.data(), prep, ray, on_hit, false, stats};
    WideStack<W> stack;
    walk(tree, ray, k, stack, leaves, stats);
}

}  // namespace bvhkit::detail::BVHKIT_SIMD_ISA
