#pragma once
// DynamicTree<T, N, UserData>: a bounding volume hierarchy of axis-aligned boxes that move, for the
// broadphase of a physics engine or a game's spatial queries (N = 2 or 3, T = float or double).
//
//   bvhkit::DynamicTree<float, 2> tree;                       // options: fat margins, insertion
//   ProxyId id = tree.create(box, user_data);                 // insert
//   tree.move(id, new_box, displacement);                     // true when the tree had to change
//   tree.find_pairs(pairs);                                   // overlapping pairs of the moved
//   tree.query(box, [](ProxyId id) { return true; });         // also query_point, ray_cast,
//   tree.destroy(id);                                         // box_cast, query_tree
//
// Layout: all nodes live in one array (a pool with a free list) and refer to each other by index,
// so the pool can grow without invalidating anything. Each proxy has a stable id into a second
// table holding its tight box, its user data (UserData, a std::uint64_t unless chosen otherwise: an
// index, a handle or a pointer cast to an integer) and its leaf node.
//
// Fat boxes: a leaf stores the proxy's box grown by a margin and stretched along the predicted
// displacement, so a small motion stays inside it and move() only updates the tight box.
//
// Insertion (tree_insertion.hpp): the sibling that minimizes the SAH cost increase, found by branch
// and bound (or the greedy descent of the classic dynamic AABB trees), then a walk up to the root
// refitting each ancestor and applying the best of the four rotations. Removal replaces the leaf's
// parent by its sibling and walks up alike.
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

#include "bvhkit/dynamic/small_stack.hpp"
#include "bvhkit/dynamic/tree_insertion.hpp"
#include "bvhkit/dynamic/tree_pairs.hpp"
#include "bvhkit/dynamic/tree_queries.hpp"
#include "bvhkit/dynamic/tree_rebuild.hpp"
#include "bvhkit/dynamic/tree_types.hpp"
#include "bvhkit/dynamic/tree_validate.hpp"
#include "bvhkit/error.hpp"

namespace bvhkit {

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
        check_options(options);
    }

    // ---------------------------------------------------------------- proxies

    /// Adds a proxy with the given (tight) box; it is in the move buffer until the next
    /// find_pairs().
    ProxyId create(const Box& box, const UserData& user_data = {}) {
        check_not_walking("DynamicTree::create");
        dynamic_detail::check_box(box, "DynamicTree::create");
        const ProxyId id = alloc_proxy();
        const std::int32_t leaf = alloc_node();
        Node& n = nodes_[leaf];
        n.box = fat_box(box, VecT{});
        n.parent = n.child1 = dynamic_detail::kNullNode;
        n.child2 = id;
        n.height = 0;
        n.enlarged = 0;
        Proxy& p = proxies_[id];
        p.box = box;
        p.user_data = user_data;
        p.node = leaf;
        insert_leaf(leaf);
        buffer_move(id);
        return id;
    }

    void destroy(ProxyId id) {
        check_not_walking("DynamicTree::destroy");
        check_id(id, "DynamicTree::destroy");
        Proxy& p = proxies_[id];
        remove_leaf(p.node);
        free_node(p.node);
        p.node = dynamic_detail::kNullNode;
        p.moved = false;  // find_pairs() skips its buffer entry
        p.ended = true;   // update_pairs() ends its pairs
        if (!p.buffered) p.buffered = true, move_buffer_.push_back(id);
        p.next_free = free_proxy_;
        free_proxy_ = id;
        --proxy_count_;
    }

    /// Gives proxy `id` a new box; `displacement` is its predicted motion until the next move (the
    /// fat box is stretched along it). The proxy goes into the move buffer either way. The tree is
    /// restructured (remove + insert) only when the box leaves the fat box, or when the fat box has
    /// become far larger than a fresh one would be; returns whether that happened.
    bool move(ProxyId id, const Box& box, const VecT& displacement = VecT{}) {
        check_not_walking("DynamicTree::move");
        check_id(id, "DynamicTree::move");
        dynamic_detail::check_box(box, "DynamicTree::move");
        dynamic_detail::check_vector(displacement, "displacement", "DynamicTree::move");
        Proxy& p = proxies_[id];
        p.box = box;
        buffer_move(id);
        const std::int32_t leaf = p.node;
        const Box fat = fat_box(box, displacement);
        const Box& current = nodes_[leaf].box;
        if (current.contains(box)) {
            // Still inside; keep it unless it is much too large (say after a fast move that
            // stopped): the limit is the fresh fat box grown by three more margins and predictions.
            const VecT slack = VecT(T(3) * margin(box)) +
                               abs(displacement) * (T(3) * options_.displacement_multiplier);
            if (Box(fat.min - slack, fat.max + slack).contains(current)) return false;
        }
        remove_leaf(leaf);
        nodes_[leaf].box = fat;
        nodes_[leaf].enlarged = 0;
        insert_leaf(leaf);
        return true;
    }

    /// Like move(), but when the box leaves its fat box the leaf's fat box and its ancestors' boxes
    /// are grown in place, without restructuring (cheap, for many moves in a row; quality suffers
    /// until rebuild(false) rebuilds the grown part). Returns whether anything was grown.
    bool enlarge(ProxyId id, const Box& box, const VecT& displacement = VecT{}) {
        check_not_walking("DynamicTree::enlarge");
        check_id(id, "DynamicTree::enlarge");
        dynamic_detail::check_box(box, "DynamicTree::enlarge");
        dynamic_detail::check_vector(displacement, "displacement", "DynamicTree::enlarge");
        Proxy& p = proxies_[id];
        p.box = box;
        buffer_move(id);
        std::int32_t i = p.node;
        if (nodes_[i].box.contains(box)) return false;
        const Box fat = fat_box(box, displacement);
        nodes_[i].box = fat;
        nodes_[i].enlarged = 1;
        // Grow the ancestors and mark them. Invariant: the parent of an enlarged node is enlarged,
        // so the walk can stop at the first ancestor that was enlarged already and contains the new
        // box.
        for (i = nodes_[i].parent; i != dynamic_detail::kNullNode; i = nodes_[i].parent) {
            Node& n = nodes_[i];
            if (n.enlarged && n.box.contains(fat)) break;
            n.box.grow(fat);
            n.enlarged = 1;
        }
        return true;
    }

    /// Rebuilds the tree top-down with binned SAH. full = false rebuilds only the part above the
    /// leaves that enlarge() touched, keeping every untouched subtree as it is.
    void rebuild(bool full = true) {
        check_not_walking("DynamicTree::rebuild");
        if (root_ == dynamic_detail::kNullNode) return;
        auto& items = build_.items;
        items.clear();
        dynamic_detail::SmallStack<std::int32_t> stack;
        stack.push(root_);
        while (!stack.empty()) {
            const std::int32_t i = stack.pop();
            Node& n = nodes_[i];
            if (n.is_leaf() || (!full && !n.enlarged)) {
                n.enlarged = 0;
                items.push_back({dynamic_detail::safe_centroid(n.box), i});
            } else {
                stack.push(n.child1);
                stack.push(n.child2);
                free_node(i);
            }
        }
        // The freed internal nodes are exactly as many as the build needs, so alloc never grows the
        // pool.
        root_ = dynamic_detail::build_binned_sah(nodes_.data(), build_,
                                                 [this] { return alloc_node(); });
    }

    /// Incremental optimization: removes and re-inserts the (at most) `max_reinsertions` leaves
    /// that look worst placed, those whose parent's area is the largest relative to their own.
    /// Returns how many.
    int optimize(int max_reinsertions) {
        check_not_walking("DynamicTree::optimize");
        if (max_reinsertions <= 0 || proxy_count_ < 3) return 0;
        auto& cand = optimize_scratch_;
        cand.clear();
        for (std::int32_t id = 0; id < static_cast<std::int32_t>(proxies_.size()); ++id) {
            const std::int32_t leaf = proxies_[id].node;
            if (leaf == dynamic_detail::kNullNode || leaf == root_) continue;
            const double own = std::max(dynamic_detail::box_area(nodes_[leaf].box),
                                        double(std::numeric_limits<T>::min()));
            const double ratio = dynamic_detail::box_area(nodes_[nodes_[leaf].parent].box) / own;
            cand.push_back({ratio == ratio ? ratio : 0.0, leaf});  // inf / inf: not a candidate
        }
        const std::size_t k =
            std::min<std::size_t>(cand.size(), static_cast<std::size_t>(max_reinsertions));
        const auto worse = [](const auto& a, const auto& b) {
            return a.first != b.first ? a.first > b.first : a.second < b.second;
        };
        std::nth_element(cand.begin(), cand.begin() + static_cast<std::ptrdiff_t>(k) - 1,
                         cand.end(), worse);
        std::sort(cand.begin(), cand.begin() + static_cast<std::ptrdiff_t>(k), worse);
        for (std::size_t i = 0; i < k; ++i) {
            remove_leaf(cand[i].second);
            insert_leaf(cand[i].second);
        }
        return static_cast<int>(k);
    }

    /// Removes every proxy and returns all memory (memory_bytes() is 0 afterwards).
    void clear() {
        check_not_walking("DynamicTree::clear");
        release(nodes_);
        release(proxies_);
        release(move_buffer_);
        release(pairs_);
        release(pending_ends_);
        pairs_valid_ = true;
        release_scratch();
        root_ = free_node_ = free_proxy_ = dynamic_detail::kNullNode;
        node_count_ = proxy_count_ = 0;
    }

    /// Returns unused memory: the node pool is repacked (depth first) to exactly the nodes in use,
    /// free proxy slots past the largest live id are dropped, and the scratch
    /// storage is freed. Live proxy ids do not change. O(nodes).
    void shrink_to_fit() {
        check_not_walking("DynamicTree::shrink_to_fit");
        std::size_t keep = proxies_.size();
        while (keep > 0 && proxies_[keep - 1].node == dynamic_detail::kNullNode) --keep;
        if (keep < proxies_.size()) {
            // Pairs naming a dropped id end at the next update_pairs().
            std::size_t kept = 0;
            for (const ProxyPair& p : pairs_)
                if (std::size_t(p.b) >= keep)
                    pending_ends_.push_back(p);
                else
                    pairs_[kept++] = p;
            pairs_.resize(kept);
            // Destroyed ids past the end leave the move buffer (find_pairs skips them anyway).
            move_buffer_.erase(
                std::remove_if(move_buffer_.begin(), move_buffer_.end(),
                               [keep](ProxyId id) { return std::size_t(id) >= keep; }),
                move_buffer_.end());
            proxies_.resize(keep);
            free_proxy_ = dynamic_detail::kNullNode;  // relist the free slots, smallest id first
            for (std::size_t id = keep; id-- > 0;)
                if (proxies_[id].node == dynamic_detail::kNullNode)
                    proxies_[id].next_free = free_proxy_, free_proxy_ = std::int32_t(id);
        }
        proxies_.shrink_to_fit();
        std::vector<Node> packed;
        packed.reserve(node_count_);
        root_ = dynamic_detail::compact_nodes(
            nodes_, root_, packed, [this](ProxyId p, int leaf) { proxies_[p].node = leaf; });
        nodes_.swap(packed);
        free_node_ = dynamic_detail::kNullNode;
        move_buffer_.shrink_to_fit();
        pairs_.shrink_to_fit();
        release_scratch();
    }

    bool contains(ProxyId id) const {
        return id >= 0 && id < static_cast<ProxyId>(proxies_.size()) &&
               proxies_[id].node != dynamic_detail::kNullNode;
    }
    const Box& box(ProxyId id) const { return proxies_[checked(id, "DynamicTree::box")].box; }
    const Box& fat_box(ProxyId id) const {
        return nodes_[proxies_[checked(id, "DynamicTree::fat_box")].node].box;
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
    /// One past the largest proxy id ever handed out (ids are reused after destroy()).
    ProxyId id_bound() const { return static_cast<ProxyId>(proxies_.size()); }
    const Options& options() const { return options_; }
    /// New options apply to later inserts and moves; the present fat boxes stay until they move.
    void set_options(const Options& o) {
        check_options(o);
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
    /// < 0 ignore and go on, 0 stop, > 0 clip to that fraction.
    template <class F>
    void ray_cast(const VecT& origin, const VecT& direction, T max_fraction, F&& callback,
                  QueryStats* stats = nullptr) const {
        dynamic_detail::check_vector(origin, "origin", "DynamicTree::ray_cast");
        dynamic_detail::check_vector(direction, "direction", "DynamicTree::ray_cast");
        check_fraction(max_fraction, "DynamicTree::ray_cast");
        const Guard guard(walks_);
        dynamic_detail::cast(view(), dynamic_detail::Segment<T, N>(origin, direction),
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
        const VecT centre = dynamic_detail::safe_centroid(box);
        dynamic_detail::cast(
            view(), dynamic_detail::Segment<T, N>(centre, translation),
            CastInput<T, N>{centre, translation, box.max * T(0.5) - box.min * T(0.5), max_fraction},
            callback, stats);
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
    /// linear merge. An id destroyed and created again in one step gives an end and a begin. The
    /// ids in an end event may name proxies destroyed since. clear() forgets the set silently.
    template <class Begin, class End>
    void update_pairs(Begin&& on_begin, End&& on_end) {
        check_not_walking("DynamicTree::update_pairs");
        const Guard guard(walks_);
        const bool stale = !pairs_valid_;
        if (stale) {  // after find_pairs(): every pair of the set is checked again
            for (std::size_t id = 0; id < proxies_.size(); ++id)
                if (proxies_[id].node != dynamic_detail::kNullNode) buffer_move(ProxyId(id));
            pairs_valid_ = true;
        }
        dynamic_detail::collect_moved_pairs(view(), move_buffer_, pair_scratch_);
        auto& ends = pair_ends_;
        auto& begins = pair_begins_;
        ends.swap(pending_ends_);  // pairs of ids dropped by shrink_to_fit()
        pending_ends_.clear();
        begins.clear();
        const auto touched = [this, stale](ProxyId id) { return stale || proxies_[id].buffered; };
        const auto ended = [this](ProxyId id) { return proxies_[id].ended; };
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
        dynamic_detail::validate_tree(dynamic_detail::TreeParts<T, N, UserData>{
            nodes_, proxies_, move_buffer_, root_, free_node_, free_proxy_, node_count_,
            proxy_count_});
    }
    int height() const { return root_ == dynamic_detail::kNullNode ? 0 : nodes_[root_].height; }
    /// Sum of the areas (perimeters in 2D) of the internal nodes.
    double sah_cost() const {
        double s = 0;
        for (const Node& n : nodes_)
            if (n.height > 0) s += dynamic_detail::box_area(n.box);
        return s;
    }
    /// sah_cost() over the root's area: how much larger than the root the internal nodes are in
    /// all.
    double area_ratio() const {
        if (root_ == dynamic_detail::kNullNode || nodes_[root_].is_leaf()) return 0;
        const double root_area = dynamic_detail::box_area(nodes_[root_].box);
        return root_area > 0 ? sah_cost() / root_area : 0;
    }
    std::size_t memory_bytes() const {
        return nodes_.capacity() * sizeof(Node) + proxies_.capacity() * sizeof(Proxy) +
               move_buffer_.capacity() * sizeof(ProxyId) + heap_.capacity() * sizeof(heap_[0]) +
               float_heap_.capacity() * sizeof(float_heap_[0]) +
               pair_scratch_.capacity() * sizeof(ProxyPair) +
               build_.items.capacity() * sizeof(build_.items[0]) +
               build_.tasks.capacity() * sizeof(build_.tasks[0]) +
               build_.created.capacity() * sizeof(std::int32_t) +
               optimize_scratch_.capacity() * sizeof(optimize_scratch_[0]) +
               (pairs_.capacity() + pending_ends_.capacity() + pair_next_.capacity() +
                pair_ends_.capacity() + pair_begins_.capacity()) *
                   sizeof(ProxyPair);
    }
    TreeStats stats() const {
        TreeStats s;
        s.proxies = proxy_count_;
        s.nodes = node_count_;
        s.node_capacity = nodes_.size();
        s.height = height();
        s.sah_cost = sah_cost();
        s.area_ratio = area_ratio();
        s.memory_bytes = memory_bytes();
        return s;
    }
    /// Moves the origin of the world to `new_origin`: every box b becomes b - new_origin (games do
    /// this to keep coordinates small far from the start). Throws bvhkit::Error, changing nothing,
    /// when a proxy's box would leave the finite range; fat and internal boxes are clamped to it.
    void shift_origin(const VecT& new_origin) {
        check_not_walking("DynamicTree::shift_origin");
        dynamic_detail::check_vector(new_origin, "new_origin", "DynamicTree::shift_origin");
        for (std::size_t id = 0; id < proxies_.size(); ++id) {
            const Proxy& p = proxies_[id];
            if (p.node == dynamic_detail::kNullNode) continue;
            const Box b(p.box.min - new_origin, p.box.max - new_origin);
            for (std::size_t i = 0; i < N; ++i)
                if (!std::isfinite(b.min[i]) || !std::isfinite(b.max[i]))
                    throw Error("DynamicTree::shift_origin: new_origin[" + std::to_string(i) +
                                "] = " + dynamic_detail::format_value(double(new_origin[i])) +
                                " would move proxy " + std::to_string(id) +
                                "'s box outside the finite range");
        }
        constexpr T big = std::numeric_limits<T>::max();
        for (Node& n : nodes_)
            if (n.height >= 0)
                n.box = Box(bvhkit::max(n.box.min - new_origin, VecT(-big)),
                            bvhkit::min(n.box.max - new_origin, VecT(big)));
        for (Proxy& p : proxies_)
            if (p.node != dynamic_detail::kNullNode)
                p.box = Box(p.box.min - new_origin, p.box.max - new_origin);
    }

    /// Visits every node: visitor(const Box& box, int depth, bool is_leaf, ProxyId proxy) (for
    /// drawing and debugging; depth 0 is the root).
    template <class F>
    void for_each_node(F&& visitor) const {
        if (root_ == dynamic_detail::kNullNode) return;
        const Guard guard(walks_);
        struct Item {
            std::int32_t node, depth;
        };
        dynamic_detail::SmallStack<Item> stack;
        stack.push({root_, 0});
        while (!stack.empty()) {
            const Item it = stack.pop();
            const Node& n = nodes_[it.node];
            visitor(n.box, int(it.depth), n.is_leaf(), n.is_leaf() ? n.proxy() : kNullProxy);
            if (!n.is_leaf()) {
                stack.push({n.child2, it.depth + 1});
                stack.push({n.child1, it.depth + 1});
            }
        }
    }

  private:
    template <class, std::size_t, class>
    friend class DynamicTree;
    using Node = dynamic_detail::Node<T, N>;
    using Proxy = dynamic_detail::Proxy<T, N, UserData>;
    using Guard = dynamic_detail::WalkCounter::Guard;

    dynamic_detail::TreeView<T, N, UserData> view() const {
        return {nodes_.data(), proxies_.data(), root_};
    }

    static void check_options(const Options& o) {
        const auto bad = [](const char* name, T v) {
            return Error(std::string("DynamicTree options: ") + name + " = " +
                         dynamic_detail::format_value(double(v)) + " (must be finite and >= 0)");
        };
        if (!(std::isfinite(o.margin_absolute) && o.margin_absolute >= 0))
            throw bad("margin_absolute", o.margin_absolute);
        if (!(std::isfinite(o.margin_relative) && o.margin_relative >= 0))
            throw bad("margin_relative", o.margin_relative);
        if (!(std::isfinite(o.displacement_multiplier) && o.displacement_multiplier >= 0))
            throw bad("displacement_multiplier", o.displacement_multiplier);
    }

    static VecT abs(const VecT& v) {
        VecT r;
        for (std::size_t i = 0; i < N; ++i) r[i] = std::abs(v[i]);
        return r;
    }
    /// The fat margin of a box: may be inf (the extent of a box spanning +-FLT_MAX overflows) but
    /// never NaN, since a zero relative margin is not multiplied by that extent.
    T margin(const Box& box) const {
        T m = options_.margin_absolute;
        if (options_.margin_relative > T(0)) {
            T e = T(0);
            for (std::size_t i = 0; i < N; ++i) e = std::max(e, box.max[i] - box.min[i]);
            m += options_.margin_relative * e;
        }
        return m;
    }
    /// The box grown by the margin on every side, then stretched along the predicted displacement,
    /// then clamped to the finite range: any finite box gets a finite fat box that contains it.
    Box fat_box(const Box& box, const VecT& displacement) const {
        constexpr T big = std::numeric_limits<T>::max();
        const T m = margin(box);
        Box fat;
        for (std::size_t i = 0; i < N; ++i) {
            T lo = box.min[i] - m, hi = box.max[i] + m;
            const T s = options_.displacement_multiplier * displacement[i];  // +-inf, never NaN
            if (s < 0)
                lo += s;
            else
                hi += s;
            fat.min[i] = std::max(lo, -big);
            fat.max[i] = std::min(hi, big);
        }
        return fat;
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
        if (!contains(id))
            throw Error(std::string(where) + ": proxy id " + std::to_string(id) +
                        (id >= 0 && id < static_cast<ProxyId>(proxies_.size()) ? " was destroyed"
                                                                               : " is unknown"));
    }
    ProxyId checked(ProxyId id, const char* where) const {
        check_id(id, where);
        return id;
    }

    template <class V>
    static void release(V& v) {
        V().swap(v);
    }
    void release_scratch() {
        release(heap_);
        release(float_heap_);
        release(pair_scratch_);
        release(build_.items);
        release(build_.tasks);
        release(build_.created);
        release(optimize_scratch_);
        release(pair_next_);
        release(pair_ends_);
        release(pair_begins_);
    }

    /// Clears the move buffer and its flags after a pair step.
    void end_pair_step() {
        for (const ProxyId q : move_buffer_) {
            Proxy& p = proxies_[q];
            p.moved = p.buffered = p.ended = false;
        }
        move_buffer_.clear();
    }

    void buffer_move(ProxyId id) {
        Proxy& p = proxies_[id];
        p.moved = true;
        if (p.buffered) return;  // a reused id may still be there from before its destroy
        p.buffered = true;
        move_buffer_.push_back(id);
    }

    // ---- pools

    std::int32_t alloc_node() {
        if (free_node_ == dynamic_detail::kNullNode) {
            // Grow the pool and chain the new nodes into the free list (indices stay valid).
            const std::size_t old = nodes_.size();
            const std::size_t cap = std::max<std::size_t>(16, old * 2);
            if (cap > std::size_t(INT32_MAX)) throw Error("DynamicTree: more than 2^31 nodes");
            nodes_.resize(cap);
            for (std::size_t i = old; i < cap; ++i) {
                nodes_[i].height = -1;
                nodes_[i].parent = i + 1 < cap ? std::int32_t(i + 1) : dynamic_detail::kNullNode;
            }
            free_node_ = std::int32_t(old);
        }
        const std::int32_t i = free_node_;
        free_node_ = nodes_[i].parent;
        ++node_count_;
        return i;
    }
    void free_node(std::int32_t i) {
        nodes_[i].height = -1;
        nodes_[i].enlarged = 0;
        nodes_[i].parent = free_node_;
        free_node_ = i;
        --node_count_;
    }
    ProxyId alloc_proxy() {
        ProxyId id = free_proxy_;
        if (id == dynamic_detail::kNullNode) {
            if (proxies_.size() >= std::size_t(INT32_MAX))
                throw Error("DynamicTree: more than 2^31 proxies");
            id = static_cast<ProxyId>(proxies_.size());
            proxies_.emplace_back();
        } else {
            free_proxy_ = proxies_[id].next_free;
        }
        proxies_[id].next_free = dynamic_detail::kNullNode;
        proxies_[id].moved = false;  // `buffered` and `ended` stay: the id may wait in the buffer
        ++proxy_count_;
        return id;
    }

    // ---- structure

    /// Puts the (detached) leaf into the tree next to the best sibling, then walks up.
    void insert_leaf(std::int32_t leaf) {
        if (root_ == dynamic_detail::kNullNode) {
            root_ = leaf;
            nodes_[leaf].parent = dynamic_detail::kNullNode;
            return;
        }
        const std::int32_t parent = alloc_node();  // first: it may grow (move) the pool
        const Box box = nodes_[leaf].box;
        const bool float_costs = dynamic_detail::float_costs_fit(unite(nodes_[root_].box, box));
        const std::int32_t sibling =
            float_costs ? find_sibling<float>(box) : find_sibling<double>(box);
        const std::int32_t old_parent = nodes_[sibling].parent;
        Node& p = nodes_[parent];
        p.parent = old_parent;
        p.child1 = sibling;
        p.child2 = leaf;
        p.enlarged = 0;
        nodes_[sibling].parent = parent;
        nodes_[leaf].parent = parent;
        dynamic_detail::refit(nodes_.data(), parent);
        if (old_parent == dynamic_detail::kNullNode) {
            root_ = parent;
            return;
        }
        Node& op = nodes_[old_parent];
        (op.child1 == sibling ? op.child1 : op.child2) = parent;
        walk_up(old_parent, float_costs);
    }

    template <class Cost>
    std::int32_t find_sibling(const Box& box) {
        if (options_.insertion == InsertionStrategy::Greedy)
            return dynamic_detail::find_sibling_greedy<Cost>(nodes_.data(), root_, box);
        if (options_.insertion == InsertionStrategy::Guided)
            return dynamic_detail::find_sibling_guided<Cost>(nodes_.data(), root_, box);
        if constexpr (std::is_same_v<Cost, float>) {
            return dynamic_detail::find_sibling_branch_and_bound<Cost>(nodes_.data(), root_, box,
                                                                       float_heap_);
        } else {
            return dynamic_detail::find_sibling_branch_and_bound<Cost>(nodes_.data(), root_, box,
                                                                       heap_);
        }
    }

    /// Takes the leaf out of the tree (the node stays allocated): its parent is freed and replaced
    /// by the leaf's sibling, then the ancestors are refitted and rotated.
    void remove_leaf(std::int32_t leaf) {
        if (leaf == root_) {
            root_ = dynamic_detail::kNullNode;
            return;
        }
        const std::int32_t parent = nodes_[leaf].parent;
        const std::int32_t grand = nodes_[parent].parent;
        const std::int32_t sibling =
            nodes_[parent].child1 == leaf ? nodes_[parent].child2 : nodes_[parent].child1;
        free_node(parent);
        nodes_[leaf].parent = dynamic_detail::kNullNode;
        nodes_[sibling].parent = grand;
        if (grand == dynamic_detail::kNullNode) {
            root_ = sibling;
            return;
        }
        Node& g = nodes_[grand];
        (g.child1 == parent ? g.child1 : g.child2) = sibling;
        walk_up(grand, dynamic_detail::float_costs_fit(nodes_[root_].box));
    }

    /// Refit (and rotate, when enabled) the nodes from i up: to the root, or to the first node
    /// above i whose box, height and enlarged flag stay and that does not rotate, since nothing
    /// above it changes then but the rotations that its unchanged subtree would offer (a heuristic
    /// either way; stopping there halves the cost of a move in a crowd). `float_costs`: every box
    /// on the way lies in bounds for which float_costs_fit() holds.
    void walk_up(std::int32_t i, bool float_costs) {
        Node* nodes = nodes_.data();
        for (const std::int32_t first = i; i != dynamic_detail::kNullNode; i = nodes[i].parent) {
            Node& n = nodes[i];
            const Box before = n.box;
            const std::int32_t child1 = n.child1, child2 = n.child2;
            const std::int32_t height = n.height;
            const std::uint32_t enlarged = n.enlarged;
            dynamic_detail::refit(nodes, i);
            if (options_.rotate) {
                if (float_costs) {
                    dynamic_detail::rotate<float>(nodes, i);
                } else {
                    dynamic_detail::rotate<double>(nodes, i);
                }
            }
            if (i != first && n.child1 == child1 && n.child2 == child2 && n.height == height &&
                n.enlarged == enlarged && n.box == before)
                break;
        }
    }

    Options options_;
    std::vector<Node> nodes_;
    std::vector<Proxy> proxies_;
    std::vector<ProxyId> move_buffer_;
    std::int32_t root_ = dynamic_detail::kNullNode;
    std::int32_t free_node_ = dynamic_detail::kNullNode;
    std::int32_t free_proxy_ = dynamic_detail::kNullNode;
    std::size_t node_count_ = 0;
    std::size_t proxy_count_ = 0;
    // Scratch storage kept between calls so that steady use allocates nothing.
    std::vector<dynamic_detail::SiblingCandidate<double>>
        heap_;  // insertion scratch, per cost type
    std::vector<dynamic_detail::SiblingCandidate<float>> float_heap_;
    std::vector<ProxyPair> pair_scratch_;
    dynamic_detail::BuildScratch<T, N> build_;
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
