#pragma once
// Saving and loading a DynamicTree (format: docs/serialization.md, kind 5): a snapshot of its whole
// state, so that a game can keep a frame and roll back to it, or hand a world to another process.
// The file holds the options, the linked tree's node pool (free nodes included, so node indices
// stay), the proxy table (so proxy ids stay), the move buffer and both pair sets; scratch storage
// is not saved. A loaded tree answers every query, and goes on through the same moves and pair
// steps, exactly as the saved one.
//
// Loading trusts nothing: besides the envelope's checks (tree_file.hpp), every count is checked
// against the bytes before anything is allocated, every index against its table, every box for
// finite coordinates, the pair sets for order, and then DynamicTree::validate() runs, always (the
// structure is the state: a cycle would hang the first query). Any failure is a bvhkit::Error.
//
// UserData must be an integer type of at most 8 bytes (the default std::uint64_t is); it is
// stored as 8 little-endian bytes.
//
// Layout 2 holds the proxy ids' generations (each slot's, the floor for new slots, and whole ids in
// the pair sets); layout 1, written before ids had them, still loads: its ids are generation 0.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "bvhkit/dynamic/dynamic_tree.hpp"
#include "bvhkit/io/tree_file.hpp"

namespace bvhkit {

namespace serial_detail {

template <class T, std::size_t N>
inline constexpr std::uint64_t dynamic_node_bytes = 2 * N * sizeof(T) + 20;
// Layout 1 and 2 (which adds the slot's generation, u32).
template <class T, std::size_t N>
inline constexpr std::uint64_t dynamic_proxy_bytes(std::uint8_t layout) {
    return 2 * N * sizeof(T) + 8 + 9 + (layout >= 2 ? 4 : 0);
}
// Layout 1: two i32 slots; layout 2: two u64 ids (ProxyId::bits()).
inline constexpr std::uint64_t dynamic_pair_bytes(std::uint8_t layout) {
    return layout >= 2 ? 16 : 8;
}
inline constexpr std::uint8_t dynamic_layout = 2;
// Options and scalars: three T, three bytes, three int32, four uint64, padded.
template <class T>
inline constexpr std::uint64_t dynamic_state_bytes = (3 * sizeof(T) + 3 + 12 + 7) / 8 * 8 + 32;

struct DynamicTreeAccess {
    static constexpr const char* what = "DynamicTree file";

    template <class T, std::size_t N, class U>
    static std::vector<std::uint8_t> save(const DynamicTree<T, N, U>& t) {
        static_assert(std::is_integral_v<U> && sizeof(U) <= 8,
                      "a DynamicTree file stores integer user data of at most 8 bytes");
        const LinkedTree<T, N>& tree = t.tree_;
        ByteWriter w;
        const auto& o = t.options_;
        w.scalar(o.margin_absolute), w.scalar(o.margin_relative);
        w.scalar(o.displacement_multiplier);
        w.u8(std::uint8_t(o.insertion)), w.u8(o.rotate ? 1 : 0), w.u8(t.pairs_valid_ ? 1 : 0);
        w.u32(std::uint32_t(tree.root_)), w.u32(std::uint32_t(tree.free_));
        w.u32(std::uint32_t(t.free_proxy_));
        w.pad(8);
        w.u64(tree.node_count_), w.u64(t.proxy_count_), w.u64(t.pending_ends_.size());
        w.u64(t.generation_floor_);
        for (const auto& n : tree.nodes_) {
            put_box(w, n.box);
            w.u32(std::uint32_t(n.parent)), w.u32(std::uint32_t(n.child1));
            w.u32(std::uint32_t(n.child2)), w.u32(std::uint32_t(std::int32_t(n.height)));
            w.u32(n.enlarged);
        }
        w.pad(8);
        for (const auto& p : t.proxies_) {
            put_box(w, p.box);
            w.u64(std::uint64_t(p.user_data));
            w.u32(std::uint32_t(p.node)), w.u32(std::uint32_t(p.next_free));
            w.u8(std::uint8_t(p.moved | p.buffered << 1 | p.ended << 2));
            w.u32(p.generation);
        }
        w.pad(8);
        for (const std::int32_t slot : t.move_buffer_) w.u32(std::uint32_t(slot));
        w.pad(8);
        for (const auto* set : {&t.pairs_, &t.pending_ends_})
            for (const ProxyPair& p : *set) w.u64(p.a.bits()), w.u64(p.b.bits());
        TreeFileHeader h;
        h.kind = FileKind::DynamicTree;
        h.scalar = scalar_code<T>();
        h.volume = N == 2 ? VolumeCode::Aabb2 : VolumeCode::Aabb3;
        h.layout = dynamic_layout;
        h.counts = {tree.nodes_.size(), t.proxies_.size(), t.move_buffer_.size(), t.pairs_.size()};
        return seal_tree_file(h, w.bytes());
    }

    template <class T, std::size_t N, class U>
    static DynamicTree<T, N, U> load(std::span<const std::uint8_t> file) {
        static_assert(std::is_integral_v<U> && sizeof(U) <= 8,
                      "a DynamicTree file stores integer user data of at most 8 bytes");
        const OpenedTreeFile f = open_tree_file(file, FileKind::DynamicTree, what);
        const TreeFileHeader& h = f.header;
        check_kind(h, N == 2 ? VolumeCode::Aabb2 : VolumeCode::Aabb3, scalar_code<T>());
        const std::uint8_t layout = h.layout;
        const auto [node_count, proxy_count, buffer_count, pair_count] = h.counts;
        const std::uint64_t limit = f.payload.size();
        std::uint64_t need = dynamic_state_bytes<T>;
        need += section_bytes(node_count, dynamic_node_bytes<T, N>, limit, what, "node");
        need += section_bytes(proxy_count, dynamic_proxy_bytes<T, N>(layout), limit, what, "proxy");
        need += section_bytes(buffer_count, 4, limit, what, "move buffer");
        if (node_count > std::uint64_t(INT32_MAX) || proxy_count > std::uint64_t(INT32_MAX))
            throw Error(std::string(what) + ": more than 2^31 nodes or proxies");
        ByteReader r(f.payload, what);
        DynamicTree<T, N, U> t(read_options<T>(r));
        LinkedTree<T, N>& tree = t.tree_;
        t.pairs_valid_ = read_flag(r);
        tree.root_ = std::int32_t(r.u32()), tree.free_ = std::int32_t(r.u32());
        t.free_proxy_ = std::int32_t(r.u32());
        r.skip_padding(8);
        tree.node_count_ = r.u64(), t.proxy_count_ = r.u64();
        const std::uint64_t end_count = r.u64();
        const std::uint64_t floor = r.u64();
        if (layout < 2 && floor != 0) r.fail("reserved field is not zero");
        if (floor > ProxyId::max_generation) r.fail("a generation floor past the largest");
        t.generation_floor_ = std::uint32_t(floor);
        const std::uint64_t pair_bytes = dynamic_pair_bytes(layout);
        if (need > limit ||
            section_bytes(pair_count, pair_bytes, limit - need, what, "pair") +
                    section_bytes(end_count, pair_bytes, limit - need, what, "ended pair") >
                limit - need)
            r.fail("the counts claim more than the file's " + std::to_string(limit) + " bytes");
        tree.nodes_.resize(node_count);
        for (auto& n : tree.nodes_) read_node(r, n);
        r.skip_padding(8);
        t.proxies_.resize(proxy_count);
        for (auto& p : t.proxies_) read_proxy(r, p, layout);
        r.skip_padding(8);
        t.move_buffer_.resize(buffer_count);
        for (std::int32_t& slot : t.move_buffer_) slot = std::int32_t(r.u32());
        r.skip_padding(8);
        read_pairs(r, t.pairs_, pair_count, proxy_count, layout, true);
        read_pairs(r, t.pending_ends_, end_count, proxy_count, layout, false);
        if (r.remaining() != 0) r.fail("bytes left after the last section");
        try {
            t.validate();
        } catch (const Error& e) {
            throw Error(std::string(what) + ": " + e.what());
        }
        return t;
    }

  private:
    static void check_kind(const TreeFileHeader& h, VolumeCode volume, ScalarCode scalar) {
        if (h.volume != volume)
            throw Error(std::string(what) + ": the file holds a " +
                        (h.volume == VolumeCode::Aabb2 ? "2D" : "3D or unknown") +
                        " tree, another dimension was asked for");
        if (h.scalar != scalar)
            throw Error(std::string(what) + ": the file holds " +
                        scalar_name(std::uint8_t(h.scalar)) + " coordinates, " +
                        scalar_name(std::uint8_t(scalar)) + " were asked for");
        if (h.layout != 1 && h.layout != dynamic_layout)
            throw Error(std::string(what) + ": unknown layout " + std::to_string(int(h.layout)));
    }

    template <class T, std::size_t N>
    static void put_box(ByteWriter& w, const Aabb<T, N>& b) {
        for (std::size_t a = 0; a < N; ++a) w.scalar(b.min[a]), w.scalar(b.max[a]);
    }
    template <class T, std::size_t N>
    static Aabb<T, N> get_box(ByteReader& r) {
        Aabb<T, N> b;
        for (std::size_t a = 0; a < N; ++a) b.min[a] = r.scalar<T>(), b.max[a] = r.scalar<T>();
        return b;
    }
    /// The boxes in use must be ones this library could have made: finite, min <= max. (Free
    /// nodes and free proxy slots keep whatever they held; nothing reads them.)
    template <class T, std::size_t N>
    static void check_box(ByteReader& r, const Aabb<T, N>& b) {
        for (std::size_t a = 0; a < N; ++a)
            if (!(std::isfinite(b.min[a]) && std::isfinite(b.max[a]) && b.min[a] <= b.max[a]))
                r.fail("a box that is not finite or has min > max");
    }
    static bool read_flag(ByteReader& r) {
        const std::uint8_t v = r.u8();
        if (v > 1) r.fail("a flag byte that is neither 0 nor 1");
        return v == 1;
    }
    template <class T>
    static DynamicTreeOptions<T> read_options(ByteReader& r) {
        DynamicTreeOptions<T> o;
        o.margin_absolute = r.scalar<T>(), o.margin_relative = r.scalar<T>();
        o.displacement_multiplier = r.scalar<T>();
        const std::uint8_t insertion = r.u8();
        if (insertion > std::uint8_t(InsertionStrategy::Guided))
            r.fail("unknown insertion strategy " + std::to_string(int(insertion)));
        o.insertion = InsertionStrategy(insertion);
        o.rotate = read_flag(r);
        try {
            dynamic_detail::check_options(o);
        } catch (const Error& e) {
            r.fail(e.what());
        }
        return o;
    }
    template <class T, std::size_t N>
    static void read_node(ByteReader& r, linked::Node<T, N>& n) {
        n.box = get_box<T, N>(r);
        n.parent = std::int32_t(r.u32()), n.child1 = std::int32_t(r.u32());
        n.child2 = std::int32_t(r.u32());
        const auto height = std::int32_t(r.u32());
        if (height < -1 || height >= (1 << 30)) r.fail("a node height out of range");
        n.height = height;
        const std::uint32_t enlarged = r.u32();
        if (enlarged > 1) r.fail("an enlarged mark that is neither 0 nor 1");
        n.enlarged = enlarged;
        if (height >= 0) check_box(r, n.box);
    }
    template <class T, std::size_t N, class U>
    static void read_proxy(ByteReader& r, dynamic_detail::Proxy<T, N, U>& p, std::uint8_t layout) {
        p.box = get_box<T, N>(r);
        const std::uint64_t user = r.u64();
        if (std::uint64_t(U(user)) != user) r.fail("user data out of the UserData type's range");
        p.user_data = U(user);
        p.node = std::int32_t(r.u32()), p.next_free = std::int32_t(r.u32());
        const std::uint8_t flags = r.u8();
        if (flags > 7) r.fail("unknown proxy flags");
        p.moved = flags & 1, p.buffered = flags >> 1 & 1, p.ended = flags >> 2 & 1;
        // validate() checks the range. Layout 1 named a proxy by its slot alone: a live one keeps
        // that id (generation 0); a free slot's next proxy gets generation 1, so an id its old
        // proxy left behind (in the caller's hands, or in the pair sets) is stale.
        if (layout >= 2)
            p.generation = r.u32();
        else
            p.generation = p.node == dynamic_detail::kNullNode ? 1 : 0;
        if (p.node != dynamic_detail::kNullNode) check_box(r, p.box);
    }
    /// Pairs with ids in the table and a < b; the current set also strictly sorted (the pair step
    /// merges it as a sorted list).
    static void read_pairs(ByteReader& r, std::vector<ProxyPair>& out, std::uint64_t count,
                           std::uint64_t proxies, std::uint8_t layout, bool sorted) {
        out.resize(count);
        const auto id = [&] {
            if (layout < 2) return ProxyId(std::int32_t(r.u32()), 0);
            return ProxyId::from_bits(r.u64());
        };
        const auto in_table = [&](ProxyId x) {
            return x.index() >= 0 && std::uint64_t(x.index()) < proxies &&
                   x.generation() <= ProxyId::max_generation;
        };
        for (std::size_t i = 0; i < out.size(); ++i) {
            ProxyPair& p = out[i];
            p.a = id(), p.b = id();
            if (!in_table(p.a) || !in_table(p.b) || !(p.a < p.b))
                r.fail("a pair (" + to_string(p.a) + ", " + to_string(p.b) +
                       ") that is not two proxy ids in order");
            if (sorted && i > 0 && !(out[i - 1] < p)) r.fail("the pair set is not sorted");
        }
    }
};

}  // namespace serial_detail

/// The whole state of `tree` as bytes (format: docs/serialization.md).
template <class T, std::size_t N, class U>
std::vector<std::uint8_t> to_bytes(const DynamicTree<T, N, U>& tree) {
    return serial_detail::DynamicTreeAccess::save(tree);
}

template <class T, std::size_t N, class U>
void save(const DynamicTree<T, N, U>& tree, const std::filesystem::path& path) {
    serial_detail::write_file_bytes(path, to_bytes(tree));
}

/// A DynamicTree from bytes written by to_bytes / save; T, N and UserData must be the saved ones
/// (an integer UserData of at most 8 bytes).
template <class T, std::size_t N, class U = std::uint64_t>
DynamicTree<T, N, U> dynamic_tree_from_bytes(std::span<const std::uint8_t> bytes) {
    return serial_detail::DynamicTreeAccess::load<T, N, U>(bytes);
}

template <class T, std::size_t N, class U = std::uint64_t>
DynamicTree<T, N, U> load_dynamic_tree(const std::filesystem::path& path) {
    return serial_detail::load_file(path, [&](std::span<const std::uint8_t> bytes) {
        return dynamic_tree_from_bytes<T, N, U>(bytes);
    });
}

}  // namespace bvhkit
