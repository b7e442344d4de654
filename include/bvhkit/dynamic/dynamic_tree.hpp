#pragma once
// DynamicTree<T, N, UserData>: a bounding volume hierarchy of axis-aligned boxes that move, for the
// broadphase of a physics engine or a game's spatial queries (N = 2 or 3, T = float or double).
//
//   bvhkit::DynamicTree<float, 2> tree;                       // options: fat margins, insertion
//   ProxyId id = tree.create(box, user_data);                 // insert
//   tree.move(id, new_box, displacement);                     // true when the tree had to change
//   tree.find_pairs(pairs);                                   // overlapping pairs of the moved
//   tree.query(box, [](ProxyId id) { return true; });         // also query_point, ray_cast,
//   tree.destroy(id);                                         // box_cast, query_tree,
//                                                             // query_nearest
//
// Two layers. The tree below is a LinkedTree (bvh/linked_tree.hpp): leaves with a fat box and a
// proxy id, inserted next to the sibling that raises the SAH cost least and rotated on the way up.
// This class is the broadphase above it: each proxy has a stable id (a slot of a table and the
// slot's generation, so that an id outlives its proxy harmlessly) naming its tight box, its user
// data (UserData, a std::uint64_t unless chosen otherwise: an index, a handle or a pointer cast to
// an integer) and its leaf; it computes the fat boxes (fat_box.hpp: the box grown by a margin and
// stretched along the predicted displacement, so a small motion stays inside it and move() only
// updates the tight box), keeps the move buffer and finds the pairs (tree_pairs.hpp). Queries
// report a proxy when its tight box passes; the fat boxes only steer the descent.
//
// Callbacks: while a query, cast, for_each_node or pair callback of a tree runs, the calls that
// change its structure (create, destroy, move, enlarge, rebuild, optimize, clear, shift_origin,
// shrink_to_fit, find_pairs, update_pairs) throw bvhkit::Error, in every build, instead of
// reallocating the nodes under the walk; collect the changes and apply them after the call returns
// (as a physics engine's locked world does). Read-only calls (nested queries, box(), user_data())
// are fine. Many threads may run const queries on one tree at once while nothing changes it.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "bvhkit/build/build.hpp"
#include "bvhkit/bvh/linked_tree.hpp"
#include "bvhkit/dynamic/fat_box.hpp"
#include "bvhkit/dynamic/small_stack.hpp"
#include "bvhkit/dynamic/tree_nearest.hpp"
#include "bvhkit/dynamic/tree_pairs.hpp"
#include "bvhkit/dynamic/tree_queries.hpp"
#include "bvhkit/dynamic/tree_types.hpp"
#include "bvhkit/dynamic/tree_validate.hpp"
#include "bvhkit/error.hpp"

namespace bvhkit {

namespace serial_detail {
struct DynamicTreeAccess;  // io/dynamic_tree_file.hpp: saves and loads the whole state
}

template <class T, std::size_t N, class UserData = std::uint64_t>
class DynamicTree {
    static_assert(N == 2 || N == 3, "DynamicTree is for 2D and 3D boxes");

  public:
    using Scalar = T;
    using VecT = Vec<T, N>;
    using Box = Aabb<T, N>;
    using Options = DynamicTreeOptions<T>;
    static constexpr std::size_t dimension = N;

    explicit DynamicTree(const Options& options = {}) : options_(options) {
        dynamic_detail::check_options(options);
    }

    // ---------------------------------------------------------------- proxies

    /// Adds a proxy with the given (tight) box; it is in the move buffer until the next
    /// find_pairs().
    ProxyId create(const Box& box, const UserData& user_data = {}) {
        check_not_walking("DynamicTree::create");
        dynamic_detail::check_box(box, "DynamicTree::create");
        const std::int32_t slot = alloc_proxy();
        const std::int32_t leaf = tree_.make_leaf(fat_box(box, VecT{}), slot);
        Proxy& p = proxies_[std::size_t(slot)];
        p.box = box;
        p.user_data = user_data;
        p.node = leaf;
        tree_.insert(leaf, insertion());
        buffer_move(slot);
        return ProxyId(slot, p.generation);
    }

    /// Removes the proxy; `id` is stale from now on (its slot's next proxy gets a new generation).
    void destroy(ProxyId id) {
        check_not_walking("DynamicTree::destroy");
        check_id(id, "DynamicTree::destroy");
        const std::int32_t slot = id.index();
        Proxy& p = proxies_[std::size_t(slot)];
        tree_.detach(p.node, options_.rotate);
        tree_.free_leaf(p.node);
        p.node = dynamic_detail::kNullNode;
        p.moved = false;  // find_pairs() skips its buffer entry
        p.ended = true;   // update_pairs() ends its pairs
        if (!p.buffered) p.buffered = true, move_buffer_.push_back(slot);
        if (p.generation < ProxyId::max_generation) {
            ++p.generation;
            p.next_free = free_proxy_;
            free_proxy_ = slot;
        }  // else the slot is retired: reusing it would give a live proxy the id of a dead one
        --proxy_count_;
    }

    /// Gives proxy `id` a new box; `displacement` is its predicted motion until the next move (the
    /// fat box is stretched along it). The proxy goes into the move buffer either way. The tree is
    /// restructured (remove + insert) only when the box leaves the fat box, or when the fat box has
    /// become far larger than a fresh one would be; returns whether that happened.
    bool move(ProxyId id, const Box& box, const VecT& displacement = VecT{}) {
        const Proxy& p = set_box(id, box, displacement, "DynamicTree::move");
        const std::int32_t leaf = p.node;
        const Box fat = fat_box(box, displacement);
        if (dynamic_detail::keeps_fat_box(options_, tree_.node(leaf).box, box, fat, displacement))
            return false;
        tree_.detach(leaf, options_.rotate);
        tree_.set_leaf_box(leaf, fat);
        tree_.insert(leaf, insertion());
        return true;
    }

    /// Like move(), but when the box leaves its fat box the leaf's fat box and its ancestors' boxes
    /// are grown in place, without restructuring (cheap, for many moves in a row; quality suffers
    /// until rebuild(false) rebuilds the grown part). Returns whether anything was grown.
    bool enlarge(ProxyId id, const Box& box, const VecT& displacement = VecT{}) {
        const Proxy& p = set_box(id, box, displacement, "DynamicTree::enlarge");
        if (tree_.node(p.node).box.contains(box)) return false;
        tree_.enlarge(p.node, fat_box(box, displacement));
        return true;
    }

    /// Rebuilds the tree top-down with binned SAH. full = false rebuilds only the part above the
    /// leaves that enlarge() touched, keeping every untouched subtree as it is.
    void rebuild(bool full = true);

    /// Incremental optimization: removes and re-inserts the (at most) `max_reinsertions` leaves
    /// that look worst placed, those whose parent's area is the largest relative to their own.
    /// Returns how many.
    int optimize(int max_reinsertions);

    /// Removes every proxy and returns all memory (memory_bytes() is 0 afterwards, unless a slot
    /// has used its last generation: then the proxy table stays, every slot retired). Ids from
    /// before stay stale: a new proxy in a slot gets a later generation than any before it.
    void clear();

    /// Returns unused memory: the node pool is repacked (depth first) to exactly the nodes in use,
    /// free proxy slots past the largest live one are dropped, and the scratch
    /// storage is freed. Live proxy ids do not change. O(nodes).
    void shrink_to_fit();

    /// Whether `id` names a live proxy: false once it is destroyed, also after its slot is reused.
    bool contains(ProxyId id) const {
        const std::int32_t i = id.index();
        return i >= 0 && std::size_t(i) < proxies_.size() &&
               proxies_[std::size_t(i)].node != dynamic_detail::kNullNode &&
               proxies_[std::size_t(i)].generation == id.generation();
    }
    const Box& box(ProxyId id) const { return proxies_[checked(id, "DynamicTree::box")].box; }
    const Box& fat_box(ProxyId id) const {
        return tree_.node(proxies_[checked(id, "DynamicTree::fat_box")].node).box;
    }
    const UserData& user_data(ProxyId id) const {
        return proxies_[checked(id, "DynamicTree::user_data")].user_data;
    }
    UserData& user_data(ProxyId id) {
        return proxies_[checked(id, "DynamicTree::user_data")].user_data;
    }
    /// Number of live proxies.
    std::size_t size() const { return proxy_count_; }
    bool empty() const { return proxy_count_ == 0; }
    /// One past the largest slot index ever handed out (slots are reused after destroy(), with a
    /// new generation).
    std::int32_t id_bound() const { return static_cast<std::int32_t>(proxies_.size()); }
    /// The live proxy in slot `index` (0 <= index < id_bound()), or kNullProxy when it is free.
    ProxyId proxy_at(std::int32_t index) const {
        if (index < 0 || std::size_t(index) >= proxies_.size() ||
            proxies_[std::size_t(index)].node == dynamic_detail::kNullNode)
            return kNullProxy;
        return ProxyId(index, proxies_[std::size_t(index)].generation);
    }
    const Options& options() const { return options_; }
    /// New options apply to later inserts and moves; the present fat boxes stay until they move.
    void set_options(const Options& o) {
        dynamic_detail::check_options(o);
        options_ = o;
    }

    // ---------------------------------------------------------------- queries (tree_queries.hpp)

    /// Every proxy whose box overlaps `box` (touching counts). callback(ProxyId) -> bool, false
    /// stops.
    template <class F>
    void query(const Box& box, F&& callback, QueryStats* stats = nullptr) const {
        dynamic_detail::check_not_nan(box.min, "box.min", "DynamicTree::query");
        dynamic_detail::check_not_nan(box.max, "box.max", "DynamicTree::query");
        for (std::size_t i = 0; i < N; ++i)
            if (box.min[i] > box.max[i]) return;  // empty: overlaps nothing
        const Guard guard(walks_);
        dynamic_detail::query_box(view(), box, callback, stats);
    }
    /// Every proxy whose box contains `p`. callback(ProxyId) -> bool, false stops.
    ///
    /// Query input: a NaN anywhere (box, point, origin, direction, translation, max_fraction)
    /// throws bvhkit::Error before the walk (a NaN compares false and would match everything).
    /// A query box may be infinite (-inf..inf finds every proxy) or empty (min > max: nothing);
    /// ray origins and directions and cast boxes must be finite; max_fraction may be inf.
    template <class F>
    void query_point(const VecT& p, F&& callback, QueryStats* stats = nullptr) const {
        dynamic_detail::check_not_nan(p, "p", "DynamicTree::query_point");
        const Guard guard(walks_);
        dynamic_detail::query_point(view(), p, callback, stats);
    }
    /// The segment origin + s * direction, s in [0, max_fraction], against the proxies' boxes.
    /// callback(ProxyId, T max_fraction) -> T, or callback(const CastInput<T, N>&, ProxyId) -> T to
    /// get the ray (origin, translation = direction, current max_fraction) for exact clipping:
    /// < 0 ignore and go on, 0 stop, > 0 clip to that fraction (a larger one than the current
    /// max fraction leaves it: the segment never grows). `stats` counts the node boxes tested.
    template <class F>
    void ray_cast(const VecT& origin, const VecT& direction, T max_fraction, F&& callback,
                  QueryStats* stats = nullptr) const {
        dynamic_detail::check_vector(origin, "origin", "DynamicTree::ray_cast");
        dynamic_detail::check_vector(direction, "direction", "DynamicTree::ray_cast");
        check_fraction(max_fraction, "DynamicTree::ray_cast");
        const Guard guard(walks_);
        dynamic_detail::cast(view(), dynamic_detail::CastSegment<T, N>(origin, direction),
                             CastInput<T, N>{origin, direction, VecT{}, max_fraction}, callback,
                             stats);
    }
    /// `box` swept by s * translation, s in [0, max_fraction]: a ray cast from the box's centre
    /// against every box grown by the cast box's half extents. Same callback as ray_cast().
    template <class F>
    void box_cast(const Box& box, const VecT& translation, T max_fraction, F&& callback,
                  QueryStats* stats = nullptr) const {
        dynamic_detail::check_box(box, "DynamicTree::box_cast");
        dynamic_detail::check_vector(translation, "translation", "DynamicTree::box_cast");
        check_fraction(max_fraction, "DynamicTree::box_cast");
        const Guard guard(walks_);
        const VecT centre = safe_centroid(box);
        dynamic_detail::cast(
            view(), dynamic_detail::CastSegment<T, N>(centre, translation),
            CastInput<T, N>{centre, translation, box.max * T(0.5) - box.min * T(0.5), max_fraction},
            callback, stats);
    }
    /// Proxies best first from `p`: in increasing distance of their tight boxes, each while that
    /// distance is within the running bound (inclusive). callback(ProxyId, W box_distance_squared)
    /// -> W, the new squared bound (kept when smaller; a negative value stops), with W =
    /// NearestWalkScalar<T> (tree_nearest.hpp). For a caller that measures its own shapes (the
    /// closest point over a scene).
    template <class F>
    void query_nearest(const VecT& p, F&& callback, QueryStats* stats = nullptr) const {
        using W = NearestWalkScalar<T>;
        dynamic_detail::check_not_nan(p, "p", "DynamicTree::query_nearest");
        const Guard guard(walks_);
        // One heap per thread, kept between walks; a walk started from inside another's callback
        // on the same thread gets its own.
        thread_local std::vector<dynamic_detail::NearestEntry<W>> shared_heap;
        thread_local bool shared_heap_busy = false;
        std::vector<dynamic_detail::NearestEntry<W>> own_heap;
        const bool nested = shared_heap_busy;
        shared_heap_busy = true;
        struct Release {
            bool nested;
            ~Release() {
                if (!nested) shared_heap_busy = false;
            }
        } release{nested};
        dynamic_detail::nearest_first(view(), p, std::numeric_limits<W>::infinity(), callback,
                                      nested ? own_heap : shared_heap, stats);
    }
    /// Every pair (proxy of this tree, proxy of `other`) whose boxes overlap.
    /// callback(ProxyId mine, ProxyId theirs) -> bool, false stops.
    template <class U2, class F>
    void query_tree(const DynamicTree<T, N, U2>& other, F&& callback,
                    QueryStats* stats = nullptr) const {
        const Guard guard(walks_), other_guard(other.walks_);
        dynamic_detail::query_tree(view(), other.view(), callback, stats);
    }

    // ---------------------------------------------------------------- pair finding

    /// The overlapping pairs (of the tight boxes) that involve a proxy moved or created since the
    /// last call, each once, as (a, b) with a < b, sorted. Clears the move buffer. (It leaves
    /// update_pairs()'s persistent set stale: its next call compares against all pairs.)
    void find_pairs(std::vector<ProxyPair>& out) {
        check_not_walking("DynamicTree::find_pairs");
        const Guard guard(walks_);
        dynamic_detail::collect_moved_pairs(view(), move_buffer_, out);
        end_pair_step();
        pairs_valid_ = false;
    }
    /// Same pairs, handed to callback(ProxyId a, ProxyId b) in order.
    template <class F>
    void find_pairs(F&& callback) {
        find_pairs(pair_scratch_);
        const Guard guard(walks_);  // the callback must not change pair_scratch_ either
        for (const ProxyPair& p : pair_scratch_) callback(p.a, p.b);
    }
    /// Pair events: calls on_end(a, b) for every pair (a < b) of tight boxes that overlapped at the
    /// last call and no longer does (or whose proxy was destroyed), then on_begin(a, b) for every
    /// pair that overlaps now and did not, each sorted by (a, b). Pairs that persist are not
    /// reported. Keeps a sorted persistent pair set; the work is one query per moved proxy plus a
    /// linear merge. An end event names the proxies that were in the pair: an id destroyed since
    /// is stale (contains(id) is false; its slot may hold a new proxy, under another id), so the
    /// caller can tell it from a live one and never gets the new proxy's user data for it. A
    /// slot destroyed and created again in one step gives an end (old id) and a begin (new id).
    /// clear() forgets the set silently.
    template <class Begin, class End>
    void update_pairs(Begin&& on_begin, End&& on_end) {
        check_not_walking("DynamicTree::update_pairs");
        const Guard guard(walks_);
        const bool stale = !pairs_valid_;
        if (stale) {  // after find_pairs(): every pair of the set is checked again
            for (std::size_t slot = 0; slot < proxies_.size(); ++slot)
                if (proxies_[slot].node != dynamic_detail::kNullNode)
                    buffer_move(std::int32_t(slot));
            pairs_valid_ = true;
        }
        dynamic_detail::collect_moved_pairs(view(), move_buffer_, pair_scratch_);
        auto& ends = pair_ends_;
        auto& begins = pair_begins_;
        ends.swap(pending_ends_);  // pairs of ids dropped by shrink_to_fit()
        pending_ends_.clear();
        begins.clear();
        const auto touched = [this, stale](ProxyId id) {
            return stale || proxies_[std::size_t(id.index())].buffered;
        };
        const auto ended = [this](ProxyId id) { return proxies_[std::size_t(id.index())].ended; };
        dynamic_detail::step_pair_set(pairs_, pair_scratch_, touched, ended, pair_next_, ends,
                                      begins);
        pairs_.swap(pair_next_);
        end_pair_step();
        std::sort(ends.begin(), ends.end());
        for (const ProxyPair& p : ends) on_end(p.a, p.b);
        for (const ProxyPair& p : begins) on_begin(p.a, p.b);
    }
    /// The pairs overlapping as of the last update_pairs() (sorted).
    const std::vector<ProxyPair>& current_pairs() const { return pairs_; }

    /// Ids waiting in the move buffer: each at most once (moved, created, or destroyed since the
    /// last pair step), so never more than id_bound(), however many moves come between pair steps.
    std::size_t move_buffer_size() const { return move_buffer_.size(); }

    // ---------------------------------------------------------------- checks and measures

    /// Checks every invariant; throws bvhkit::Error naming the first one broken.
    void validate() const {
        const std::size_t leaves = tree_.validate(
            "DynamicTree::validate",
            [this](std::int32_t i, const Node& n) { dynamic_detail::check_leaf(n, i, proxies_); });
        dynamic_detail::validate_proxies(dynamic_detail::ProxyParts<T, N, UserData>{
            tree_, proxies_, move_buffer_, free_proxy_, proxy_count_, leaves});
    }
    int height() const { return tree_.height(); }
    /// Sum of the areas (perimeters in 2D) of the internal nodes.
    double sah_cost() const { return tree_.sah_cost(); }
    /// sah_cost() over the root's area: how much larger than the root the internal nodes are in
    /// all.
    double area_ratio() const {
        if (tree_.root() == dynamic_detail::kNullNode || tree_.node(tree_.root()).is_leaf())
            return 0;
        const double root_area = linked::box_area(tree_.node(tree_.root()).box);
        return root_area > 0 ? sah_cost() / root_area : 0;
    }
    std::size_t memory_bytes() const {
        return tree_.memory_bytes() + proxies_.capacity() * sizeof(Proxy) +
               move_buffer_.capacity() * sizeof(std::int32_t) +
               pair_scratch_.capacity() * sizeof(ProxyPair) +
               optimize_scratch_.capacity() * sizeof(optimize_scratch_[0]) +
               (pairs_.capacity() + pending_ends_.capacity() + pair_next_.capacity() +
                pair_ends_.capacity() + pair_begins_.capacity()) *
                   sizeof(ProxyPair);
    }
    TreeStats stats() const {
        TreeStats s;
        s.proxies = proxy_count_;
        s.nodes = tree_.node_count();
        s.node_capacity = tree_.capacity();
        s.height = height();
        s.sah_cost = sah_cost();
        s.area_ratio = area_ratio();
        s.memory_bytes = memory_bytes();
        return s;
    }
    /// Moves the origin of the world to `new_origin`: every box b becomes b - new_origin (games do
    /// this to keep coordinates small far from the start). Throws bvhkit::Error, changing nothing,
    /// when a proxy's box would leave the finite range; fat and internal boxes are clamped to it.
    void shift_origin(const VecT& new_origin);

    /// Visits every node: visitor(const Box& box, int depth, bool is_leaf, ProxyId proxy) (for
    /// drawing and debugging; depth 0 is the root).
    template <class F>
    void for_each_node(F&& visitor) const {
        if (tree_.root() == dynamic_detail::kNullNode) return;
        const Guard guard(walks_);
        struct Item {
            std::int32_t node, depth;
        };
        dynamic_detail::SmallStack<Item> stack;
        stack.push({tree_.root(), 0});
        while (!stack.empty()) {
            const Item it = stack.pop();
            const Node& n = tree_.node(it.node);
            visitor(n.box, int(it.depth), n.is_leaf(),
                    n.is_leaf() ? dynamic_detail::proxy_id(view(), n.value()) : kNullProxy);
            if (!n.is_leaf()) {
                stack.push({n.child2, it.depth + 1});
                stack.push({n.child1, it.depth + 1});
            }
        }
    }

  private:
    template <class, std::size_t, class>
    friend class DynamicTree;
    friend struct serial_detail::DynamicTreeAccess;
    using Node = dynamic_detail::Node<T, N>;
    using Proxy = dynamic_detail::Proxy<T, N, UserData>;
    using Guard = dynamic_detail::WalkCounter::Guard;

    dynamic_detail::TreeView<T, N, UserData> view() const {
        return {tree_.nodes(), proxies_.data(), tree_.root()};
    }

    Box fat_box(const Box& box, const VecT& displacement) const {
        return dynamic_detail::fat_box(options_, box, displacement);
    }
    InsertionOptions insertion() const {
        InsertionOptions o;
        o.strategy = options_.insertion;
        o.rotate = options_.rotate;
        return o;
    }

    /// The structural calls throw while a walk of this tree runs (they would reallocate or relink
    /// the nodes under it): from a query, cast, for_each_node or pair callback.
    void check_not_walking(const char* where) const {
        if (walks_.active())
            throw Error(std::string(where) +
                        ": called while a query, cast, for_each_node or pair callback of this "
                        "tree is running; collect the changes and apply them after it returns");
    }

    static void check_fraction(T max_fraction, const char* where) {
        if (std::isnan(max_fraction))
            throw Error(std::string(where) + ": max_fraction is nan (must be a number; >= 0 " +
                        "to find anything, inf for an unbounded ray)");
    }

    void check_id(ProxyId id, const char* where) const {
        if (contains(id)) return;
        const std::int32_t i = id.index();
        const bool handed_out = i >= 0 && std::size_t(i) < proxies_.size() &&
                                id.generation() <= proxies_[std::size_t(i)].generation;
        throw Error(std::string(where) + ": proxy id " + to_string(id) +
                    (handed_out ? " was destroyed (a stale id)" : " is unknown"));
    }
    std::size_t checked(ProxyId id, const char* where) const {
        check_id(id, where);
        return std::size_t(id.index());
    }
    /// The generation a slot's next proxy would get (max_generation + 1: none, it is retired).
    static std::uint64_t next_generation(const Proxy& p) {
        return std::uint64_t(p.generation) +
               (p.node != dynamic_detail::kNullNode || p.generation == ProxyId::max_generation);
    }

    template <class V>
    static void release(V& v) {
        V().swap(v);
    }
    void release_scratch() {
        tree_.release_scratch();
        release(pair_scratch_);
        release(optimize_scratch_);
        release(pair_next_);
        release(pair_ends_);
        release(pair_begins_);
    }

    /// Clears the move buffer and its flags after a pair step.
    void end_pair_step() {
        for (const std::int32_t q : move_buffer_) {
            Proxy& p = proxies_[q];
            p.moved = p.buffered = p.ended = false;
        }
        move_buffer_.clear();
    }

    /// The first step of move() and enlarge(): the checks, the new tight box, the move buffer.
    const Proxy& set_box(ProxyId id, const Box& box, const VecT& displacement, const char* where) {
        check_not_walking(where);
        const std::size_t slot = checked(id, where);
        dynamic_detail::check_box(box, where);
        dynamic_detail::check_vector(displacement, "displacement", where);
        proxies_[slot].box = box;
        buffer_move(std::int32_t(slot));
        return proxies_[slot];
    }

    void buffer_move(std::int32_t slot) {
        Proxy& p = proxies_[std::size_t(slot)];
        p.moved = true;
        if (p.buffered) return;  // a reused slot may still be there from before its destroy
        p.buffered = true;
        move_buffer_.push_back(slot);
    }

    // ---- pools

    std::int32_t alloc_proxy() {
        std::int32_t slot = free_proxy_;
        if (slot == dynamic_detail::kNullNode) {
            if (proxies_.size() >= std::size_t(INT32_MAX))
                throw Error("DynamicTree: more than 2^31 proxies");
            slot = static_cast<std::int32_t>(proxies_.size());
            proxies_.emplace_back();
            proxies_.back().generation = generation_floor_;
        } else {
            free_proxy_ = proxies_[std::size_t(slot)].next_free;
        }
        Proxy& p = proxies_[std::size_t(slot)];
        p.next_free = dynamic_detail::kNullNode;
        p.moved = false;  // `buffered` and `ended` stay: the slot may wait in the buffer
        ++proxy_count_;
        return slot;
    }

    Options options_;
    LinkedTree<T, N> tree_;  // leaves: the fat boxes, valued by proxy id
    std::vector<Proxy> proxies_;
    std::vector<std::int32_t> move_buffer_;  // slot indices
    std::int32_t free_proxy_ = dynamic_detail::kNullNode;
    // The generation of a slot appended to the table: past every one a dropped slot handed out.
    std::uint32_t generation_floor_ = 0;
    std::size_t proxy_count_ = 0;
    // Scratch storage kept between calls so that steady use allocates nothing.
    std::vector<ProxyPair> pair_scratch_;
    std::vector<std::pair<double, std::int32_t>> optimize_scratch_;
    // update_pairs(): the persistent pair set, whether it is current (find_pairs() makes it
    // stale), ends owed for ids shrink_to_fit() dropped, and scratch.
    std::vector<ProxyPair> pairs_, pending_ends_, pair_next_, pair_ends_, pair_begins_;
    bool pairs_valid_ = true;
    dynamic_detail::WalkCounter walks_;
};

using DynamicTree2f = DynamicTree<float, 2>;
using DynamicTree3f = DynamicTree<float, 3>;
using DynamicTree2d = DynamicTree<double, 2>;
using DynamicTree3d = DynamicTree<double, 3>;

}  // namespace bvhkit

#include "bvhkit/dynamic/tree_upkeep.hpp"  // rebuild, optimize, clear, shrink_to_fit, shift_origin
