#pragma once
// The small types shared by the dynamic tree's parts: ids, the proxy record, the options (fat
// margins, insertion strategy) and the statistics a query or the whole tree can report.
#include <atomic>
#include <compare>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

#include "bvhkit/bvh/linked_tree.hpp"

namespace bvhkit {

/// A proxy is one user object in a DynamicTree. Its id is its slot in the tree's proxy table (the
/// index) and how many proxies that slot held before it (the generation). It stays valid (and the
/// same) until the proxy is destroyed, whatever happens to the tree: growth of the node pool,
/// rotations, rebuilds. A slot is reused after destroy() with the next generation, so an id kept
/// past its proxy's destroy() never names the new proxy: calls given it throw bvhkit::Error, and
/// contains() says false. Packed in 64 bits (generation << 32 | index, see bits()): passed in a
/// register, compared in one instruction; the tree finds the proxy by the index alone.
class ProxyId {
  public:
    /// Generations run from 0 to this; a slot whose proxy of this generation is destroyed is never
    /// reused (at one reuse per frame, 2^31 frames is over a year at 60 Hz). 31 bits keep bits()
    /// a non-negative int64 (the Python package hands ids out as int64).
    static constexpr std::uint32_t max_generation = 0x7fffffffu;

    /// The null id (kNullProxy): index() is -1.
    constexpr ProxyId() = default;
    constexpr ProxyId(std::int32_t index, std::uint32_t generation)
        : bits_(std::uint64_t(generation) << 32 | std::uint32_t(index)) {}
    /// The id whose bits() are `bits` (any value: one that no tree handed out is simply not live).
    static constexpr ProxyId from_bits(std::uint64_t bits) {
        ProxyId id;
        id.bits_ = bits;
        return id;
    }

    /// The slot in the tree's proxy table: 0 <= index() < id_bound() for ids the tree handed out.
    constexpr std::int32_t index() const { return std::int32_t(std::uint32_t(bits_)); }
    constexpr std::uint32_t generation() const { return std::uint32_t(bits_ >> 32); }
    constexpr std::uint64_t bits() const { return bits_; }
    constexpr bool is_null() const { return bits_ == kNull; }
    /// "index", or "index (generation g)" past the first, for messages.
    std::string text() const {
        if (is_null()) return "null";
        std::string s = std::to_string(index());
        if (generation() != 0) s += " (generation " + std::to_string(generation()) + ")";
        return s;
    }

    friend constexpr bool operator==(ProxyId, ProxyId) = default;
    friend constexpr auto operator<=>(ProxyId x, ProxyId y) { return x.bits_ <=> y.bits_; }
    template <class Os>
    friend auto operator<<(Os& os, ProxyId id) -> decltype(os << std::string()) {
        return os << id.text();
    }

  private:
    static constexpr std::uint64_t kNull = ~std::uint64_t(0);
    std::uint64_t bits_ = kNull;
};
inline constexpr ProxyId kNullProxy{};
inline std::string to_string(ProxyId id) {
    return id.text();
}

/// Options of a DynamicTree. The fat box of a leaf is its box grown on every side by
/// `margin_absolute + margin_relative * (largest extent of the box)`, then stretched along
/// `displacement_multiplier * displacement` when move() is given a displacement.
template <class T>
struct DynamicTreeOptions {
    T margin_absolute = T(0.1);
    T margin_relative = T(0);
    T displacement_multiplier = T(4);
    InsertionStrategy insertion = InsertionStrategy::Guided;
    /// Try the four rotations while walking up after an insert or a removal (Kopta et al.
    /// 2012).
    bool rotate = true;
};

/// Counters a query can fill in (pass a pointer; they are added to, never reset by the query).
struct QueryStats {
    std::uint64_t nodes_visited = 0;  // nodes whose box was tested
    std::uint64_t leaves_tested = 0;  // leaves whose proxy box was tested
};

/// The cast a ray_cast or box_cast callback may ask for (callback(const CastInput&, ProxyId) -> T,
/// as physics engines hand their ray input): the segment origin + s * translation, s in
/// [0, max_fraction], with max_fraction as clipped so far, and the cast box's half extents (zero
/// for a ray cast; origin is then the box's centre). Enough to clip the proxy's own shape exactly.
template <class T, std::size_t N>
struct CastInput {
    Vec<T, N> origin;
    Vec<T, N> translation;
    Vec<T, N> half_extent;
    T max_fraction = T(1);
};

/// A pair of overlapping proxies, a < b.
struct ProxyPair {
    ProxyId a = kNullProxy;
    ProxyId b = kNullProxy;
    friend constexpr bool operator==(const ProxyPair&, const ProxyPair&) = default;
    friend constexpr bool operator<(const ProxyPair& x, const ProxyPair& y) {
        return x.a != y.a ? x.a < y.a : x.b < y.b;
    }
};

/// Measures of a whole tree (DynamicTree::stats()).
struct TreeStats {
    std::size_t proxies = 0;
    std::size_t nodes = 0;          // leaves + internal nodes in use
    std::size_t node_capacity = 0;  // pool size
    int height = 0;                 // a single leaf has height 0; empty tree: 0
    double sah_cost = 0;            // sum of the areas of the internal nodes (perimeters in 2D)
    double area_ratio = 0;          // sah_cost / area of the root (0 for fewer than two leaves)
    std::size_t memory_bytes = 0;   // heap memory held by the tree
};

namespace dynamic_detail {

inline constexpr std::int32_t kNullNode = linked::null;
template <class T, std::size_t N>
using Node = linked::Node<T, N>;

/// What the tree keeps per proxy. A free slot has node == kNullNode and the next free slot in
/// next_free; its generation is the one its next proxy gets.
template <class T, std::size_t N, class UserData>
struct Proxy {
    Aabb<T, N> box;  // the tight box the user gave
    UserData user_data{};
    std::int32_t node = kNullNode;
    std::int32_t next_free = kNullNode;
    std::uint32_t generation = 0;  // beside the box's cache line: walks read it to name the proxy
    bool moved = false;            // live and created or moved since the last pair step
    bool buffered = false;         // its id is in the move buffer (once at most: bounds the buffer)
    bool ended = false;            // destroyed since the last pair step: its pairs have ended
};

/// How many walks (queries, find_pairs, for_each_node) are running over a tree right now. The
/// structural calls refuse to run while it is non-zero, so a callback cannot change the node pool
/// under the walk that called it. Atomic because const queries may run on many threads at once.
/// A copied or moved tree starts with no walk.
class WalkCounter {
  public:
    WalkCounter() = default;
    WalkCounter(const WalkCounter&) noexcept {}
    WalkCounter& operator=(const WalkCounter&) noexcept { return *this; }

    bool active() const { return count_.load(std::memory_order_relaxed) != 0; }

    /// Holds the counter up for its lifetime (also when a callback throws).
    class Guard {
      public:
        explicit Guard(const WalkCounter& c) : c_(c) {
            c_.count_.fetch_add(1, std::memory_order_relaxed);
        }
        ~Guard() { c_.count_.fetch_sub(1, std::memory_order_relaxed); }
        Guard(const Guard&) = delete;
        Guard& operator=(const Guard&) = delete;

      private:
        const WalkCounter& c_;
    };

  private:
    mutable std::atomic<std::uint32_t> count_{0};
};

}  // namespace dynamic_detail
}  // namespace bvhkit
